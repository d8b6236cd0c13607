// kelp.Tether (the lumped-mass tether on its own: model, state, step between prescribed ends)
// and kelp.TetherState.
#include <mutex>
#include <optional>
#include <string>

#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/driver.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/presets.hpp"

namespace kelp_python {

namespace kt = kelp::tether;
using Env = kelp::environment::Environmentd;

namespace {

/// kelp.Tether: the model (parameters and derived constants) and its step buffers.
struct Tether {
  kt::TetherModeld model;
  kt::TetherWorkspaced workspace;
  std::mutex mutex;  // the workspace is shared: one step at a time (the GIL is released)
  explicit Tether(const kt::TetherParametersd& p) : model(p), workspace(model) {}
};

const Env& still_water() {
  static const Env env;
  return env;
}

}  // namespace

void bind_tether(py::module_& m) {
  py::class_<kt::TetherStated>(
      m, "TetherState",
      "A tether's state: node positions and velocities (NED, shape (nodes, 3): zero-copy "
      "writable views, kept alive with the state, valid while it keeps its node count), the "
      "clock and the implicit integrator's history. Writing positions or velocities through "
      "the properties clears the history (the next step starts with backward Euler).")
      .def_property(
          "position",
          [](py::object self) {
            auto& x = self.cast<kt::TetherStated&>().position;
            return points_view(x.data(), x.cols(), self);
          },
          [](kt::TetherStated& s, py::handle v) {
            set_points(s.position, v, "position");
            s.clear_history();
          },
          "Node positions, NED [m], (nodes, 3): a view.")
      .def_property(
          "velocity",
          [](py::object self) {
            auto& x = self.cast<kt::TetherStated&>().velocity;
            return points_view(x.data(), x.cols(), self);
          },
          [](kt::TetherStated& s, py::handle v) {
            set_points(s.velocity, v, "velocity");
            s.clear_history();
          },
          "Node velocities, NED [m/s], (nodes, 3): a view.")
      .def_readonly("time", &kt::TetherStated::time, "The tether's clock [s].")
      .def("clear_history", &kt::TetherStated::clear_history,
           "Forgets the integrator history (after editing the nodes by hand).")
      .def(
          "copy", [](const kt::TetherStated& s) { return s; }, "An independent copy.")
      .def("__copy__", [](const kt::TetherStated& s) { return s; })
      .def(
          "__deepcopy__", [](const kt::TetherStated& s, py::dict) { return s; }, py::arg("memo"));

  py::class_<Tether>(
      m, "Tether",
      "A lumped-mass tether (N segments, N + 1 nodes: axial tension EA strain when stretched, "
      "internal damping, weight and buoyancy, Morison drag on the velocity relative to the "
      "water, added mass, seabed contact) on its own, its ends moved by the caller:\n\n"
      "    t = kelp.Tether.rov_tether(10.0)\n"
      "    x = t.initial_state([0, 0, 0], [8, 0, 5])   # the static catenary between the ends\n"
      "    f = t.step(x, [0, 0, 0], [8, 0, 5], 0.01)   # end forces, NED [N]\n\n"
      "kelp.System couples it to the vehicles.")
      .def_static(
          "rov_tether",
          [](double length, double max_segment_length, std::optional<double> ratio) {
            kt::TetherParametersd p = kt::presets::rov_tether(length, max_segment_length);
            if (ratio) {
              p.internal_damping = 0.0;
              p.internal_damping_ratio = *ratio;
            }
            return std::make_unique<Tether>(p);
          },
          py::arg("length"), py::arg("max_segment_length") = 0.25,
          py::arg("internal_damping_ratio") = py::none(),
          "Fathom-class ROV tether (kelp/tether/presets.hpp: 7.6 mm, nearly neutrally buoyant "
          "in seawater, EA 2.92 kN, von Benzon et al. 2022) of `length` m in segments of at most "
          "`max_segment_length` m. `internal_damping_ratio`: the internal damping as a ratio of "
          "critical (MoorDyn's BA/-zeta) instead of the preset's BA of 100 N s.")
      .def_static(
          "bead_chain",
          [](double length) { return std::make_unique<Tether>(kt::presets::bead_chain(length)); },
          py::arg("length"), "The paper's bead-chain tether of `length` m.")
      .def_property_readonly(
          "nodes", [](const Tether& t) { return t.model.nodes(); },
          "Number of nodes (segments + 1).")
      .def_property_readonly(
          "length", [](const Tether& t) { return t.model.parameters().length; },
          "Unstretched length [m].")
      .def_property_readonly(
          "segment_length", [](const Tether& t) { return t.model.segment_length(); },
          "Unstretched segment length [m].")
      .def_property_readonly(
          "internal_damping", [](const Tether& t) { return t.model.parameters().internal_damping; },
          "Internal damping BA [N s] (from internal_damping_ratio when one was given: ratio * "
          "segment_length * sqrt(EA * mass per length)).")
      .def(
          "weight_per_length",
          [](const Tether& t, const Env* env) {
            const Env& e = env ? *env : still_water();
            return t.model.submerged_weight_per_length(e.water_density(), e.gravity());
          },
          py::arg("environment") = py::none(),
          "Submerged weight per length w = (m' - rho A) g [N/m] in the environment's water "
          "(default seawater), as kelp.catenary takes it.")
      .def(
          "initial_state",
          [](const Tether& t, py::handle start, py::handle end, const Env* env) {
            return kt::catenary_initial_state(t.model, env ? *env : still_water(),
                                              Eigen::Vector3d(vector_arg<3>(start, "start")),
                                              Eigen::Vector3d(vector_arg<3>(end, "end")));
          },
          py::arg("start"), py::arg("end"), py::arg("environment") = py::none(),
          "A state at rest on the static catenary between the NED points `start` and `end` [m] "
          "(straight when taut), t = 0.")
      .def(
          "step",
          [](Tether& t, kt::TetherStated& state, py::handle start, py::handle end, double dt,
             const Env* env, py::handle start_velocity, py::handle end_velocity, double max_dt) {
            kt::TetherBoundary<double> b = kt::TetherBoundary<double>::fixed(
                vector_arg<3>(start, "start"), vector_arg<3>(end, "end"));
            if (!start_velocity.is_none())
              b.start.velocity = vector_arg<3>(start_velocity, "start_velocity");
            if (!end_velocity.is_none())
              b.end.velocity = vector_arg<3>(end_velocity, "end_velocity");
            kt::AdvanceOptions<double> o;
            o.max_dt = max_dt;
            kt::StepReport<double> r;
            kt::EndForces<double> f;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(t.mutex);
              r = kt::advance(t.model, t.workspace, env ? *env : still_water(), state, b, dt, o);
              f = t.workspace.end_forces;
            }
            py::dict d;
            d["force_on_start"] = copy_vector(f.on_start);
            d["force_on_end"] = copy_vector(f.on_end);
            d["substeps"] = r.substeps;
            d["newton_iterations"] = r.newton_iterations;
            d["residual"] = r.residual;
            d["retries"] = r.retries;
            return d;
          },
          py::arg("state"), py::arg("start"), py::arg("end"), py::arg("dt"),
          py::arg("environment") = py::none(), py::arg("start_velocity") = py::none(),
          py::arg("end_velocity") = py::none(), py::arg("max_dt") = 0.01,
          "Advances `state` in place by `dt` [s] (BDF2 sub-steps of at most `max_dt`) with its "
          "ends at the NED points `start` and `end` [m] moving at `start_velocity`, "
          "`end_velocity` [m/s] (default at rest) in `environment` (default still water). "
          "Returns a dict: force_on_start, force_on_end (the line's pull on each end, NED [N], "
          "after the last sub-step), substeps, newton_iterations, residual, retries. Raises "
          "kelp.InvalidArgument or kelp.NumericalError with the state unchanged.");
}

}  // namespace kelp_python
