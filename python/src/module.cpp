// kelp._kelp: the extension module under the `kelp` package (python/kelp/__init__.py imports it).
#include "bindings.hpp"
#include "kelp/version.hpp"

namespace kelp_python {
/// kelp.Tether and kelp.TetherState (tether.cpp).
void bind_tether(py::module_& m);
/// kelp._kelp._step_loop, the C++ baseline of benchmarks/python_step_overhead.py (timing.cpp).
void bind_timing(py::module_& m);
}  // namespace kelp_python

PYBIND11_MODULE(_kelp, m) {
  m.doc() =
      "kelp's C++ library (header-only, Eigen) bound with pybind11: vehicles, environment, "
      "catenary, tether, the coupled system and kelp::sim's scenarios. Import the `kelp` "
      "package, not this module.";
  m.attr("__version__") = KELP_VERSION_STRING;
  kelp_python::bind_errors(m);
  kelp_python::bind_vehicle(m);
  kelp_python::bind_environment(m);
  kelp_python::bind_catenary(m);
  kelp_python::bind_tether(m);
  kelp_python::bind_system(m);
  kelp_python::bind_fleet(m);
  kelp_python::bind_timing(m);
  kelp_python::bind_scenario(m);
  kelp_python::bind_batch(m);
  kelp_python::bind_learning(m);
}
