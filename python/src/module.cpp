// kelp._kelp: the extension module under the `kelp` package (python/kelp/__init__.py imports it).
#include "bindings.hpp"

PYBIND11_MODULE(_kelp, m) {
  m.doc() =
      "kelp's C++ library (header-only, Eigen) bound with pybind11: vehicles, environment, "
      "catenary, tether, the coupled system and kelp::sim's scenarios. Import the `kelp` "
      "package, not this module.";
  m.attr("__version__") = KELP_VERSION_STRING;
  kelp_python::bind_errors(m);
  kelp_python::bind_scenario(m);
  kelp_python::bind_batch(m);
  kelp_python::bind_learning(m);
}
