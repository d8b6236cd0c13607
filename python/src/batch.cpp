// kelp.Batch (kelp::sim::Batch): n worlds of a scenario stepped together on a thread pool with
// the GIL released; its per-world arrays are read-only numpy views of the batch's own memory.
#include <pybind11/numpy.h>

#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "kelp/sim/batch.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp_python {

namespace {

namespace ks = kelp::sim;

// A read-only view of `count` rows of `cols` items of T at `data` (row stride `row_bytes`), kept
// alive by `owner`; cols == 0: a 1-D array of `count` items.
template <typename T>
py::array view(const T* data, py::ssize_t count, py::ssize_t cols, py::ssize_t row_bytes,
               py::handle owner, py::dtype dtype = py::dtype::of<T>()) {
  py::array a = cols == 0
                    ? py::array(dtype, {count}, {row_bytes}, data, owner)
                    : py::array(dtype, {count, cols},
                                {row_bytes, static_cast<py::ssize_t>(sizeof(T))}, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array rows(const ks::Batch::Rows& m, py::handle owner) {
  return view(m.data(), m.rows(), m.cols(), m.cols() * static_cast<py::ssize_t>(sizeof(double)),
              owner);
}

py::array column(const ks::Batch::Rows& m, py::handle owner) {
  return view(m.data(), m.rows(), 0, m.cols() * static_cast<py::ssize_t>(sizeof(double)), owner);
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

}  // namespace

/// kelp._kelp.Batch; kelp.Batch (python/kelp/batch.py) builds it from a scenario.
void bind_batch(py::module_& m) {
  py::class_<ks::Batch>(m, "Batch", R"(n independent worlds of one scenario, stepped together.

World i is the scenario with sea seed ``seed + i`` (waves, gusts), a ``TetheredPairEnv`` whose
ROV (and optionally boat) is flown either by the scenario's controllers (``step()`` without
actions, as kelp-tethered-pair runs it) or by actions (``step(n, actions)``: one row per world,
the same action and reward as ``TetheredPairEnv.step``). The worlds are split into one block per
thread; a world is stepped by one thread with nothing shared, so every number is the same bit for
bit whatever ``threads`` is. ``step`` releases the GIL. Not to be stepped from two Python threads
at once.

The per-world properties (``auv_position`` (n, 3), ``auv_attitude`` (n, 4), ``auv_velocity``
(n, 6), the same for ``asv_``, ``tension`` (n, 2), ``observation`` (n, 20), ``reward``,
``time``, ``terminated``, ``truncated`` (n,)) are read-only numpy views of the batch's own memory
(no copy; ``np.shares_memory`` holds between two reads): they change in place at every step and
keep the batch alive. Copy them (``np.array(b.auv_position)``) to keep a value.

Build it through ``kelp.Batch(scenario, n, seed, ...)``.)")
      .def(py::init([](const std::string& text, const std::string& name, std::size_t n,
                       std::uint64_t seed, unsigned threads, double control_period, bool asv_action,
                       double max_path_error, double path_weight, double energy_weight) {
             const ks::Scenario sc = ks::parse_scenario(text, name);
             ks::BatchOptions o;
             o.threads = threads;
             o.env.control_period = control_period;
             o.env.asv_action = asv_action;
             o.env.max_path_error = max_path_error;
             o.env.path_weight = path_weight;
             o.env.energy_weight = energy_weight;
             py::gil_scoped_release release;
             return std::make_unique<ks::Batch>(sc, n, seed, o);
           }),
           py::arg("scenario_json"), py::arg("scenario_name"), py::arg("n"), py::arg("seed"),
           py::arg("threads") = 0, py::arg("control_period") = 0.1, py::arg("asv_action") = false,
           py::arg("max_path_error") = 20.0, py::arg("path_weight") = 1.0,
           py::arg("energy_weight") = 0.01,
           "Builds n worlds from scenario JSON text (its name is used in errors), seeds seed … "
           "seed + n − 1, on `threads` threads (0: one per CPU, at most n).")
      .def(
          "step",
          [](ks::Batch& b, long n_steps, py::object actions) {
            if (actions.is_none()) {
              py::gil_scoped_release release;
              b.step(n_steps);
              return;
            }
            using In = py::array_t<double, py::array::c_style | py::array::forcecast>;
            In a = In::ensure(actions);
            if (!a) throw kelp::invalid_argument("Batch.step: actions must be an array of numbers");
            const auto n = static_cast<py::ssize_t>(b.size());
            if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != b.action_size()) {
              std::string got;
              for (py::ssize_t k = 0; k < a.ndim(); ++k)
                got += (k ? ", " : "") + std::to_string(a.shape(k));
              throw kelp::invalid_argument(
                  "Batch.step: actions must have shape (" + std::to_string(n) + ", " +
                  std::to_string(b.action_size()) + "), got (" + got + ")");
            }
            py::gil_scoped_release release;
            b.step(n_steps, a.data());
          },
          py::arg("n_steps") = 1, py::arg("actions") = py::none(),
          "Advances every world by n_steps control periods: without actions the scenario's "
          "controllers fly; with actions (shape (n, action_size), each entry clipped to [-1, 1], "
          "applied at every step) they fly the ROVs (and boats). `reward` then holds each "
          "world's reward summed over the steps. A world whose episode ended stays as it is. "
          "Releases the GIL. Raises kelp.InvalidArgument for a negative n_steps or a bad or "
          "non-finite action (nothing is stepped).")
      .def(
          "reset",
          [](ks::Batch& b, std::uint64_t seed) {
            py::gil_scoped_release release;
            b.reset(seed);
          },
          py::arg("seed"), "New episodes: world i rebuilt with seed `seed + i`.")
      .def_property_readonly("n", &ks::Batch::size, "Number of worlds.")
      .def("__len__", &ks::Batch::size, "Number of worlds.")
      .def_property_readonly("threads", &ks::Batch::threads,
                             "Threads stepping the worlds (the caller's included).")
      .def_property_readonly("seed", &ks::Batch::seed, "Seed of world 0.")
      .def_property_readonly("action_size", &ks::Batch::action_size,
                             "Entries of one world's action (6, or 8 with the boat's).")
      .def_property_readonly(
          "auv_position",
          [](py::object self) { return rows(self.cast<ks::Batch&>().auv_position(), self); },
          "The ROVs' positions, NED [m], shape (n, 3) (a read-only view).")
      .def_property_readonly(
          "auv_attitude",
          [](py::object self) { return rows(self.cast<ks::Batch&>().auv_attitude(), self); },
          "The ROVs' attitudes, unit quaternions body -> NED (w, x, y, z), shape (n, 4) (a view).")
      .def_property_readonly(
          "auv_velocity",
          [](py::object self) { return rows(self.cast<ks::Batch&>().auv_velocity(), self); },
          "The ROVs' body velocities (u, v, w [m/s], p, q, r [rad/s]), shape (n, 6) (a view).")
      .def_property_readonly(
          "asv_position",
          [](py::object self) { return rows(self.cast<ks::Batch&>().asv_position(), self); },
          "The boats' positions, NED [m], shape (n, 3) (a read-only view).")
      .def_property_readonly(
          "asv_attitude",
          [](py::object self) { return rows(self.cast<ks::Batch&>().asv_attitude(), self); },
          "The boats' attitudes (w, x, y, z), shape (n, 4) (a read-only view).")
      .def_property_readonly(
          "asv_velocity",
          [](py::object self) { return rows(self.cast<ks::Batch&>().asv_velocity(), self); },
          "The boats' body velocities, shape (n, 6) (a read-only view).")
      .def_property_readonly(
          "tension", [](py::object self) { return rows(self.cast<ks::Batch&>().tension(), self); },
          "The tether's end forces' magnitudes [N], column 0 on the boat, 1 on the ROV, shape "
          "(n, 2) (a read-only view).")
      .def_property_readonly(
          "observation",
          [](py::object self) { return rows(self.cast<ks::Batch&>().observation(), self); },
          "The worlds' observations (TetheredPairEnv's), shape (n, 20) (a read-only view).")
      .def_property_readonly(
          "reward", [](py::object self) { return column(self.cast<ks::Batch&>().reward(), self); },
          "Each world's reward summed over the last step() call, shape (n,) (a read-only view).")
      .def_property_readonly(
          "time", [](py::object self) { return column(self.cast<ks::Batch&>().time(), self); },
          "Each world's simulation time [s], shape (n,) (a read-only view).")
      .def_property_readonly(
          "terminated",
          [](py::object self) {
            const auto& e = self.cast<ks::Batch&>().ended();
            return view(e.data(), e.rows(), 0, 2, self, py::dtype("bool"));
          },
          "True where the episode terminated (a failed step, see error(i), or the ROV beyond "
          "max_path_error), shape (n,) (a read-only view).")
      .def_property_readonly(
          "truncated",
          [](py::object self) {
            const auto& e = self.cast<ks::Batch&>().ended();
            return view(e.data() + 1, e.rows(), 0, 2, self, py::dtype("bool"));
          },
          "True where the scenario's duration has been simulated, shape (n,) (a read-only view).")
      .def(
          "error", [](const ks::Batch& b, std::size_t i) { return b.error(i); }, py::arg("i"),
          "Why world i terminated on a failed step ('' otherwise).")
      .def(
          "summary",
          [](const ks::Batch& b, std::size_t i) {
            return json_to_python(
                nlohmann::json::parse(kelp::sim::summary_json(b.world(i).loop().summary())));
          },
          py::arg("i"),
          "World i's summary so far, as kelp-tethered-pair's summary.json (without the wall "
          "time): path errors, tensions, energy, the scenario with its seed.");
}

}  // namespace kelp_python
