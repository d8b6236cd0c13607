// kelp._kelp._step_loop: System.step's C++ loop without Python, the baseline that
// benchmarks/python_step_overhead.py subtracts to measure the Python overhead per step.
#include <chrono>

#include "bindings.hpp"
#include "types.hpp"

namespace kelp_python {

void bind_timing(py::module_& m) {
  m.def(
      "_step_loop",
      [](System& s, kelp::system::SystemStated& state, const kelp::system::SystemInputsd& inputs,
         double dt, long n) {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(s.mutex);
        const auto t0 = std::chrono::steady_clock::now();
        for (long i = 0; i < n; ++i) kelp::system::step(s.model, s.workspace, state, inputs, dt);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      },
      py::arg("system"), py::arg("state"), py::arg("inputs"), py::arg("dt"), py::arg("n"),
      "Steps `state` n times in C++ (what System.step calls, without Python) and returns the "
      "wall time [s] (benchmarks only).");
}

}  // namespace kelp_python
