# docs/custom-environment.md quotes wave_tank.hpp whole: fail when they differ.
file(READ "${PAGE}" page)
file(READ "${HEADER}" header)
string(FIND "${page}" "${header}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${PAGE} does not quote ${HEADER} as it is: copy the header into the page")
endif()
