// kelp.System (the coupled ASV + tether + AUV), kelp.SystemState (which pickles through
// kelp::sim's state files), kelp.SystemInputs, kelp.SystemReport, and kelp.save_state /
// kelp.load_state for the pair (fleet.cpp adds the fleet's overloads).
#include <pybind11/stl.h>

#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/sim/state_io.hpp"
#include "kelp/sim/world.hpp"
#include "kelp/system/presets.hpp"
#include "types.hpp"

namespace kelp_python {

namespace ks = kelp::system;
using State = ks::SystemStated;
using Inputs = ks::SystemInputsd;
using Report = ks::SystemReportd;

namespace {

// A 3×n matrix of the tether as (n, 3) points: a view owned by `self`.
py::array tether_view(const Eigen::Matrix3Xd& x, py::handle self) {
  return points_view(x.data(), x.cols(), self);
}

// The paper's system (kelp::system::presets::paper_system) as a scenario-less world.
kelp::sim::WorldSetup paper_world(double tether_length, const std::string& sea, std::uint64_t seed,
                                  int wave_components, double ramp, bool propulsion) {
  namespace sp = kelp::system::presets;
  namespace ke = kelp::environment;
  kelp::sim::WorldSetup w{sp::paper_system(tether_length), ke::Environmentd{},
                          sp::paper_start(tether_length)};
  if (!propulsion) {
    w.parameters.asv_propulsion.reset();
    w.parameters.auv_propulsion.reset();
  }
  ke::SeaState s;
  if (sea == "calm")
    s = ke::presets::calm();
  else if (sea == "moderate")
    s = ke::presets::moderate();
  else if (sea == "rough")
    s = ke::presets::rough();
  else
    kelp::detail::throw_invalid_argument(
        "sea: expected \"calm\", \"moderate\" or \"rough\", got \"" + sea + "\"");
  ke::SeaStateOptions o;
  o.seed = seed;
  o.wave_components = wave_components;
  o.ramp = ramp;
  w.environment = ke::make_environment<double>(s, o);
  return w;
}

void set_commands(kelp::vehicle::ThrusterVector<double>& u, Eigen::Index n, py::handle v,
                  const char* name) {
  KELP_CHECK(n > 0, std::string(name) + ": this vehicle has no propulsion");
  u = vector_arg(v, n, name);
}

}  // namespace

void bind_system(py::module_& m) {
  py::class_<Inputs>(
      m, "SystemInputs",
      "The inputs of one System.step: each vehicle's control wrench tau and other external "
      "wrench tau_ext (body axes [N, N m], shape (6,)), for a vehicle with propulsion its "
      "thrusters' normalised commands in [-1, 1] (held over the step), and with a winch its "
      "commanded payout rate. Get one sized for a "
      "system from System.inputs(); every array is a writable zero-copy view, so filling it in "
      "place (inputs.auv_commands[:] = u) costs no allocation.")
      .def(py::init<>(), "Zero wrenches, no commands (all thrusters at 0).")
      .def_property(
          "asv_tau",
          [](py::object self) { return vector_view(self.cast<Inputs&>().asv.tau.data(), 6, self); },
          [](Inputs& i, py::handle v) { i.asv.tau = vector_arg<6>(v, "asv_tau"); },
          "The ASV's control wrench [N, N m], (6,): a view.")
      .def_property(
          "asv_tau_ext",
          [](py::object self) {
            return vector_view(self.cast<Inputs&>().asv.tau_ext.data(), 6, self);
          },
          [](Inputs& i, py::handle v) { i.asv.tau_ext = vector_arg<6>(v, "asv_tau_ext"); },
          "The ASV's other external wrench [N, N m], (6,): a view.")
      .def_property(
          "auv_tau",
          [](py::object self) { return vector_view(self.cast<Inputs&>().auv.tau.data(), 6, self); },
          [](Inputs& i, py::handle v) { i.auv.tau = vector_arg<6>(v, "auv_tau"); },
          "The AUV's control wrench [N, N m], (6,): a view.")
      .def_property(
          "auv_tau_ext",
          [](py::object self) {
            return vector_view(self.cast<Inputs&>().auv.tau_ext.data(), 6, self);
          },
          [](Inputs& i, py::handle v) { i.auv.tau_ext = vector_arg<6>(v, "auv_tau_ext"); },
          "The AUV's other external wrench [N, N m], (6,): a view.")
      .def_property(
          "asv_commands",
          [](py::object self) {
            auto& u = self.cast<Inputs&>().asv_commands;
            return vector_view(u.data(), u.size(), self);
          },
          [](Inputs& i, py::handle v) {
            set_commands(i.asv_commands, i.asv_commands.size(), v, "asv_commands");
          },
          "The ASV's thruster commands (port, starboard), (n,): a view (empty: all 0).")
      .def_property(
          "auv_commands",
          [](py::object self) {
            auto& u = self.cast<Inputs&>().auv_commands;
            return vector_view(u.data(), u.size(), self);
          },
          [](Inputs& i, py::handle v) {
            set_commands(i.auv_commands, i.auv_commands.size(), v, "auv_commands");
          },
          "The AUV's thruster commands in ArduSub's motor order, (n,): a view (empty: all 0).")
      .def_readwrite("winch_payout_rate", &Inputs::winch_payout_rate,
                     "The winch's commanded payout rate [m/s] (positive: paying out), followed "
                     "within its limits; must be 0 for a system without a winch.");

  py::class_<State>(
      m, "SystemState",
      "Everything that determines the system's next step: the clock, both vehicles "
      "(kelp.VehicleState: views into this state), the tether's nodes (positions and "
      "velocities, NED, shape (nodes, 3): zero-copy writable views, valid while the tether "
      "keeps its node count), the integrators' history and the propulsion's state. Saving a "
      "copy (copy()) and stepping it again reproduces a run bit for bit.")
      .def_readonly("time", &State::time, "The system's clock [s] (set it with set_time()).")
      .def_property_readonly(
          "asv", [](State& s) -> kelp::vehicle::VehicleStated& { return s.asv; },
          py::return_value_policy::reference_internal,
          "The ASV's state: a view (kelp.VehicleState) kept alive with this state.")
      .def_property_readonly(
          "auv", [](State& s) -> kelp::vehicle::VehicleStated& { return s.auv; },
          py::return_value_policy::reference_internal,
          "The AUV's state: a view (kelp.VehicleState) kept alive with this state.")
      .def_property(
          "tether_position",
          [](py::object self) { return tether_view(self.cast<State&>().tether.position, self); },
          [](State& s, py::handle v) {
            set_points(s.tether.position, v, "tether_position");
            s.tether.clear_history();
          },
          "Tether node positions, NED [m], (nodes, 3): a view. Setting it clears the integrator "
          "history.")
      .def_property(
          "tether_velocity",
          [](py::object self) { return tether_view(self.cast<State&>().tether.velocity, self); },
          [](State& s, py::handle v) {
            set_points(s.tether.velocity, v, "tether_velocity");
            s.tether.clear_history();
          },
          "Tether node velocities, NED [m/s], (nodes, 3): a view. Setting it clears the integrator "
          "history.")
      .def_property_readonly(
          "asv_thrust",
          [](py::object self) {
            auto& u = self.cast<State&>().asv_propulsion.thrust;
            return vector_view(u.data(), u.size(), self, false);
          },
          "The ASV's thrusters' (lagged) thrust [N], (n,): a read-only view (empty without "
          "propulsion).")
      .def_property_readonly(
          "auv_thrust",
          [](py::object self) {
            auto& u = self.cast<State&>().auv_propulsion.thrust;
            return vector_view(u.data(), u.size(), self, false);
          },
          "The AUV's thrusters' (lagged) thrust [N], (n,): a read-only view (empty without "
          "propulsion).")
      .def("set_time", &State::set_time, py::arg("t"),
           "Sets the clock of the system and its parts to `t` [s].")
      .def("reset_coupling", &State::reset_coupling,
           "Forgets the coupling's memory (the vehicles' last accelerations): call it after "
           "editing the vehicle states by hand.")
      .def(
          "copy", [](const State& s) { return s; },
          "An independent copy (for saving and restoring).")
      .def("__copy__", [](const State& s) { return s; })
      .def(
          "__deepcopy__", [](const State& s, py::dict) { return s; }, py::arg("memo"))
      // Pickling: the state file's bytes (kelp.save_state). A kelp.SystemState is a plain C++
      // state with no reference to its system, so unpickling checks the state on its own (sizes
      // that fit together, finite values, equal clocks); System.step then refuses a node or
      // thruster count that is not its system's, and kelp.load_state(data, system) checks all
      // of it (a winch length without a winch too) at once.
      .def(py::pickle([](const State& s) { return py::bytes(kelp::sim::save_state(s)); },
                      [](const py::bytes& b) {
                        const std::string data = b;
                        return kelp::sim::load_system_state(data, "pickled kelp.SystemState");
                      }));

  m.def(
      "save_state", [](const State& s) { return py::bytes(kelp::sim::save_state(s)); },
      py::arg("state"),
      "The state as a state file's bytes (kelp::sim::save_state; docs/state-files.md): "
      "everything that influences its next steps, bit for bit. Raises kelp.StateError for a "
      "state that could not be loaded back (NaN where a step refuses it, sizes that do not fit "
      "together).");
  m.def(
      "save_state_file",
      [](const std::string& path, const State& s) { kelp::sim::save_state_file(path, s); },
      py::arg("path"), py::arg("state"),
      "Writes kelp.save_state(state) to `path` atomically (a new file beside it, flushed, then "
      "renamed over it). Raises kelp.StateError, or kelp.Error when the file cannot be written.");

  py::class_<Report>(m, "SystemReport", "What one System.step did.")
      .def_property_readonly(
          "force_on_asv", [](const Report& r) { return copy_vector(r.force_on_asv); },
          "Tether force on the ASV over the step, NED [N], (3,).")
      .def_property_readonly(
          "force_on_auv", [](const Report& r) { return copy_vector(r.force_on_auv); },
          "Tether force on the AUV over the step, NED [N], (3,).")
      .def_property_readonly(
          "substeps", [](const Report& r) { return r.tether.substeps; }, "Tether sub-steps.")
      .def_property_readonly(
          "newton_iterations", [](const Report& r) { return r.tether.newton_iterations; },
          "Newton iterations of the tether's implicit solve.")
      .def_property_readonly(
          "residual", [](const Report& r) { return r.tether.residual; },
          "Worst accepted Newton residual of the step.")
      .def_property_readonly(
          "retries", [](const Report& r) { return r.tether.retries; }, "Retried tether sub-steps.")
      .def_property_readonly(
          "tether_fallbacks", [](const Report& r) { return r.tether_fallbacks; },
          "Tether steps redone explicitly.")
      .def_property_readonly(
          "energy",
          [](const Report& r) {
            py::dict d;
            d["asv"] = r.energy.asv;
            d["auv"] = r.energy.auv;
            d["tether"] = r.energy.tether;
            d["total"] = r.energy.total();
            return d;
          },
          "Energy after the step [J] (asv, auv, tether, total) when step(..., with_energy=True), "
          "else zeros.");

  py::class_<System>(
      m, "System",
      "The coupled system: a BlueBoat ASV and a BlueROV2 Heavy AUV joined by a lumped-mass "
      "tether in one environment, advanced together by step() (kelp::system::step: the "
      "vehicles by RK4, the tether by its implicit integrator, the end forces applied back).\n\n"
      "    sys = kelp.System(tether_length=10, sea='moderate', seed=1)\n"
      "    state = sys.initial_state()\n"
      "    u = sys.inputs()\n"
      "    u.auv_commands[:] = 0.1\n"
      "    for _ in range(100):\n"
      "        report = sys.step(state, u, 0.01)\n\n"
      "kelp.System.from_scenario(path_or_dict) builds the world of a scenario file (the one "
      "kelp-tethered-pair and kelp.run_scenario fly). A step that fails raises "
      "kelp.InvalidArgument or kelp.NumericalError and leaves the state as it was.")
      .def(py::init([](double tether_length, const std::string& sea, std::uint64_t seed,
                       int wave_components, double ramp, bool propulsion) {
             return std::make_unique<System>(
                 paper_world(tether_length, sea, seed, wave_components, ramp, propulsion),
                 std::nullopt);
           }),
           py::kw_only(), py::arg("tether_length") = 10.0, py::arg("sea") = "moderate",
           py::arg("seed") = 1, py::arg("wave_components") = 64, py::arg("ramp") = 0.0,
           py::arg("propulsion") = true,
           "The paper's system (kelp::system::presets::paper_system: the ROV tether of "
           "`tether_length` m, the vehicles' T200 thrusters and batteries unless "
           "propulsion=False) in the paper's 'calm', 'moderate' or 'rough' sea drawn from "
           "`seed`, ramped in over `ramp` s.")
      .def_static(
          "from_scenario",
          [](py::object scenario) {
            std::string file;
            kelp::sim::Scenario sc = scenario_from_python(scenario, file);
            return std::make_unique<System>(kelp::sim::world_setup(sc, file), sc);
          },
          py::arg("scenario") = py::none(),
          "The world of a scenario (a file path, a dict, or None for the embedded default): "
          "its system, sea and start. Raises kelp.ScenarioError naming the bad field.")
      .def(
          "initial_state",
          [](System& s) {
            std::lock_guard<std::mutex> lock(s.mutex);
            if (s.scenario)
              return kelp::sim::start_state(s.model, s.workspace, s.world, *s.scenario);
            return ks::initial_state(s.model, s.workspace, s.world.start.asv, s.world.start.auv);
          },
          "The start state: the vehicles at their start poses, the tether at its static shape "
          "between them, t = 0 (from a scenario: kelp::sim::start_state, as a run starts).")
      .def(
          "inputs",
          [](const System& s) {
            Inputs i;
            if (const auto* p = s.model.asv_propulsion()) i.asv_commands.setZero(p->size());
            if (const auto* p = s.model.auv_propulsion()) i.auv_commands.setZero(p->size());
            return i;
          },
          "Zero inputs sized for this system (commands for each vehicle with propulsion).")
      .def(
          "step",
          [](System& s, State& state, const Inputs* inputs, double dt, bool with_energy) {
            static const Inputs none;
            ks::SystemStepOptions o;
            o.with_energy = with_energy;
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(s.mutex);
            // A state of another tether node count than the last one stepped (a copy restored,
            // a state loaded or unpickled, with a winch) gets that count's buffers.
            ks::fit_workspace(s.model, s.workspace, state);
            return ks::step(s.model, s.workspace, state, inputs ? *inputs : none, dt, o);
          },
          py::arg("state"), py::arg("inputs") = py::none(), py::arg("dt") = 0.01,
          py::arg("with_energy") = false,
          "Advances `state` in place by `dt` [s] under `inputs` (a kelp.SystemInputs; None: "
          "zero) and returns a kelp.SystemReport. The GIL is released during the step. Raises "
          "kelp.InvalidArgument (bad dt, non-finite inputs or state, wrong command count) or "
          "kelp.NumericalError; the state is then unchanged. Any state of this system may be "
          "stepped: a copy, one restored from kelp.load_state or a pickle.")
      .def(
          "energy",
          [](const System& s, const State& state) {
            const auto e = ks::energy(s.model, state);
            py::dict d;
            d["asv"] = e.asv;
            d["auv"] = e.auv;
            d["tether"] = e.tether;
            d["total"] = e.total();
            return d;
          },
          py::arg("state"), "The mechanical energy of `state` [J]: asv, auv, tether, total.")
      .def_property_readonly(
          "environment", [](const System& s) { return s.model.environment(); },
          "The system's environment (a copy: kelp.Environment).")
      .def_property_readonly(
          "tether_nodes", [](const System& s) { return s.model.tether().nodes(); },
          "Number of tether nodes (segments + 1).")
      .def_property_readonly(
          "tether_parameters",
          [](const System& s) {
            const auto& p = s.model.tether().parameters();
            py::dict d;
            d["length"] = p.length;
            d["segments"] = p.segments;
            d["diameter"] = p.diameter;
            d["mass_per_length"] = p.mass_per_length;
            d["axial_stiffness"] = p.axial_stiffness;
            d["internal_damping"] = p.internal_damping;
            d["normal_drag"] = p.normal_drag;
            d["tangential_drag"] = p.tangential_drag;
            return d;
          },
          "The tether's main parameters (length [m], segments, diameter [m], mass_per_length "
          "[kg/m], axial_stiffness EA [N], internal_damping, drag coefficients).")
      .def_property_readonly(
          "asv_attachment",
          [](const System& s) { return copy_vector(s.model.parameters().asv_attachment); },
          "The tether's point on the ASV, body axes [m].")
      .def_property_readonly(
          "auv_attachment",
          [](const System& s) { return copy_vector(s.model.parameters().auv_attachment); },
          "The tether's point on the AUV, body axes [m].");

  m.def(
      "load_state",
      [](const py::bytes& b, const System& sys) {
        const std::string data = b;
        return kelp::sim::load_state(data, sys.model);
      },
      py::arg("data"), py::arg("system"),
      "The kelp.SystemState saved in `data` (bytes from kelp.save_state), checked against "
      "`system` (its tether's node count, within its winch's range; its thruster counts). Raises "
      "kelp.StateError naming what is wrong (truncated or corrupted bytes, a fleet's state, "
      "another system's, NaN).");
  m.def(
      "load_state_file",
      [](const std::string& path, const System& sys) {
        return kelp::sim::load_state_file(path, sys.model);
      },
      py::arg("path"), py::arg("system"),
      "kelp.load_state of the file `path` (errors name it). Raises kelp.StateError, or "
      "kelp.Error when it cannot be read.");
}

}  // namespace kelp_python
