# Runs one of the replay page's browser tests (SCRIPT, a Node.js script) on HTML, failing with a
# message saying what to install when Node.js or the npm packages are missing.
if(NOT NODE)
  message(FATAL_ERROR "Node.js not found: scripts/install-deps test installs it (Debian: nodejs)")
endif()
get_filename_component(replay_dir "${SCRIPT}" DIRECTORY)
if(NOT EXISTS "${replay_dir}/../node_modules/puppeteer-core/package.json")
  message(FATAL_ERROR "puppeteer-core is not installed in ${replay_dir}/../node_modules: "
                      "run scripts/install-deps test (or npm ci in apps/replay/page/)")
endif()
# ARGS: the script's further arguments (a ;-list), after the HTML file.
execute_process(COMMAND "${NODE}" "${SCRIPT}" "${HTML}" ${ARGS} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${SCRIPT} failed (${rc})")
endif()
