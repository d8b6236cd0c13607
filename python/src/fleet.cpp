// kelp.Fleet (any vehicles, point masses and tethers of a fleet scenario: kelp::system's fleet
// step), kelp.FleetState (which pickles through kelp::sim's state files), kelp.FleetInputs,
// kelp.FleetReport, and the fleet's overloads of kelp.save_state / kelp.load_state.
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "kelp/sim/fleet_run.hpp"
#include "kelp/sim/state_io.hpp"
#include "types.hpp"

namespace kelp_python {

namespace {

namespace kfs = kelp::system;
using FState = kfs::FleetStated;
using FInputs = kfs::FleetInputsd;
using FReport = kfs::FleetReportd;

/// kelp.Fleet: a fleet scenario's world, its model and workspace.
struct Fleet {
  kelp::sim::Scenario scenario;
  std::string file;
  kelp::sim::FleetWorld world;
  kfs::FleetModeld model;
  kfs::FleetWorkspaced workspace;
  std::mutex mutex;  // the workspace is shared: one step at a time (the GIL is released)

  Fleet(kelp::sim::Scenario sc, std::string f)
      : scenario(std::move(sc)),
        file(std::move(f)),
        world(kelp::sim::fleet_world(scenario, file)),
        model(world.parameters, world.environment),
        workspace(model) {}
};

// Index `i` of `what` checked against `n` (Python's negative indices allowed).
std::size_t index_of(int i, int n, const char* what) {
  if (i < 0) i += n;
  if (i < 0 || i >= n)
    kelp::detail::throw_invalid_argument(std::string(what) + " index " + std::to_string(i) +
                                         " out of range (" + std::to_string(n) + ")");
  return std::size_t(i);
}

// Part `key` (an index or a name) of a fleet's vehicles / point masses / tethers.
std::size_t part_of(py::handle key, int n, const std::vector<std::string>& names,
                    const char* what) {
  if (py::isinstance<py::str>(key)) {
    const std::string name = key.cast<std::string>();
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return i;
    kelp::detail::throw_invalid_argument(std::string("no ") + what + " named \"" + name + "\"");
  }
  return index_of(key.cast<int>(), n, what);
}

// The names of a fleet's vehicles, point masses or tethers (FleetParameters' lists), in order.
template <class Parts>
std::vector<std::string> names_of(const Parts& parts) {
  std::vector<std::string> r;
  for (const auto& x : parts) r.push_back(x.name);
  return r;
}

py::dict energy_dict(const kfs::FleetEnergy<double>& e) {
  py::dict d;
  d["vehicles"] = e.vehicles;
  d["point_masses"] = e.point_masses;
  d["tethers"] = e.tethers;
  d["total"] = e.total();
  return d;
}

// The end forces of every tether, (M, 3) NED [N].
py::array end_forces(const std::vector<Eigen::Vector3d>& f) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(f.size()));
  for (std::size_t k = 0; k < f.size(); ++k) m.col(static_cast<Eigen::Index>(k)) = f[k];
  return copy_matrix(m.transpose());
}

}  // namespace

void bind_fleet(py::module_& m) {
  py::class_<FInputs>(
      m, "FleetInputs",
      "The inputs of one Fleet.step, per vehicle and per tether (from Fleet.inputs(), sized for "
      "its fleet): tau(i) and tau_ext(i), a vehicle's control and other external wrench (body "
      "axes [N, N m], (6,)); commands(i), its thrusters' normalised commands in [-1, 1] (empty "
      "without thrusters); winch_payout_rates, each tether's commanded winch payout rate [m/s] "
      "(0 without a winch). Every array is a writable zero-copy view: fill it in place "
      "(u.commands(0)[:] = 0.2).")
      .def(
          "tau",
          [](py::object self, int i) {
            auto& in = self.cast<FInputs&>();
            return vector_view(
                in.vehicles[index_of(i, int(in.vehicles.size()), "vehicle")].tau.data(), 6, self);
          },
          py::arg("i"), "Vehicle i's control wrench [N, N m], (6,): a view.")
      .def(
          "tau_ext",
          [](py::object self, int i) {
            auto& in = self.cast<FInputs&>();
            return vector_view(
                in.vehicles[index_of(i, int(in.vehicles.size()), "vehicle")].tau_ext.data(), 6,
                self);
          },
          py::arg("i"), "Vehicle i's other external wrench [N, N m], (6,): a view.")
      .def(
          "commands",
          [](py::object self, int i) {
            auto& u = self.cast<FInputs&>().commands;
            auto& c = u[index_of(i, int(u.size()), "vehicle")];
            return vector_view(c.data(), c.size(), self);
          },
          py::arg("i"),
          "Vehicle i's thruster commands in its thrusters' order, (n,): a view (empty without "
          "thrusters).")
      .def_property_readonly(
          "winch_payout_rates",
          [](py::object self) {
            auto& r = self.cast<FInputs&>().winch_payout_rates;
            return vector_view(r.data(), py::ssize_t(r.size()), self);
          },
          "Each tether's winch payout rate [m/s], (M,): a view.");

  py::class_<FState>(
      m, "FleetState",
      "Everything that determines a fleet's next step: the clock, each vehicle "
      "(kelp.VehicleState views), each point mass and each tether's nodes (NED, zero-copy "
      "writable views), the integrators' history and the propulsion. copy() saves it; stepping "
      "a copy again reproduces a run bit for bit.")
      .def_readonly("time", &FState::time, "The fleet's clock [s] (set it with set_time()).")
      .def(
          "vehicle",
          [](FState& s, int i) -> kelp::vehicle::VehicleStated& {
            return s.vehicles[index_of(i, int(s.vehicles.size()), "vehicle")];
          },
          py::arg("i"), py::return_value_policy::reference_internal,
          "Vehicle i's state: a view (kelp.VehicleState) kept alive with this state.")
      .def(
          "point_mass_position",
          [](py::object self, int j) {
            auto& p = self.cast<FState&>().point_masses;
            return vector_view(p[index_of(j, int(p.size()), "point mass")].position.data(), 3,
                               self);
          },
          py::arg("j"), "Point mass j's position, NED [m], (3,): a view.")
      .def(
          "point_mass_velocity",
          [](py::object self, int j) {
            auto& p = self.cast<FState&>().point_masses;
            return vector_view(p[index_of(j, int(p.size()), "point mass")].velocity.data(), 3,
                               self);
          },
          py::arg("j"), "Point mass j's velocity, NED [m/s], (3,): a view.")
      .def(
          "tether_position",
          [](py::object self, int k) {
            auto& t = self.cast<FState&>().tethers;
            const auto& x = t[index_of(k, int(t.size()), "tether")].position;
            return points_view(x.data(), x.cols(), self);
          },
          py::arg("k"),
          "Tether k's node positions, NED [m], (nodes, 3): a view, valid while the tether keeps "
          "its node count (a winch re-meshes it). Set with set_tether_position().")
      .def(
          "tether_velocity",
          [](py::object self, int k) {
            auto& t = self.cast<FState&>().tethers;
            const auto& x = t[index_of(k, int(t.size()), "tether")].velocity;
            return points_view(x.data(), x.cols(), self);
          },
          py::arg("k"), "Tether k's node velocities, NED [m/s], (nodes, 3): a view.")
      .def(
          "set_tether_position",
          [](FState& s, int k, py::handle v) {
            auto& t = s.tethers[index_of(k, int(s.tethers.size()), "tether")];
            set_points(t.position, v, "tether_position");
            t.clear_history();
          },
          py::arg("k"), py::arg("positions"),
          "Sets tether k's node positions (nodes, 3) and clears its integrator history.")
      .def(
          "thrust",
          [](py::object self, int i) {
            auto& p = self.cast<FState&>().propulsion;
            const auto& u = p[index_of(i, int(p.size()), "vehicle")].thrust;
            return vector_view(u.data(), u.size(), self, false);
          },
          py::arg("i"),
          "Vehicle i's thrusters' (lagged) thrust [N], (n,): a read-only view (empty without "
          "thrusters).")
      .def("set_time", &FState::set_time, py::arg("t"),
           "Sets the clock of the fleet and its parts to `t` [s].")
      .def(
          "copy", [](const FState& s) { return s; }, "An independent copy (for saving).")
      .def("__copy__", [](const FState& s) { return s; })
      .def(
          "__deepcopy__", [](const FState& s, py::dict) { return s; }, py::arg("memo"))
      // Pickling: the state file's bytes, checked on their own when unpickled (as
      // kelp.SystemState's; the fleet it is stepped with checks the counts).
      .def(py::pickle([](const FState& s) { return py::bytes(kelp::sim::save_state(s)); },
                      [](const py::bytes& b) {
                        const std::string data = b;
                        return kelp::sim::load_fleet_state(data, "pickled kelp.FleetState");
                      }));

  m.def(
      "save_state", [](const FState& s) { return py::bytes(kelp::sim::save_state(s)); },
      py::arg("state"), "A kelp.FleetState as a state file's bytes (see the pair's overload).");
  m.def(
      "save_state_file",
      [](const std::string& path, const FState& s) { kelp::sim::save_state_file(path, s); },
      py::arg("path"), py::arg("state"),
      "Writes a kelp.FleetState to `path` atomically (see the pair's overload).");

  py::class_<FReport>(m, "FleetReport", "What one Fleet.step did (a copy).")
      .def_property_readonly(
          "force_at_start", [](const FReport& r) { return end_forces(r.force_at_start); },
          "Per tether: the force its start end delivered to what holds it over the step (a "
          "vehicle, a point mass, an anchor's load), NED [N], (M, 3).")
      .def_property_readonly(
          "force_at_end", [](const FReport& r) { return end_forces(r.force_at_end); },
          "Per tether: the force at its far end, NED [N], (M, 3) (zero at a free end).")
      .def_property_readonly(
          "substeps", [](const FReport& r) { return r.tether.substeps; },
          "Tether sub-steps, all tethers.")
      .def_property_readonly(
          "newton_iterations", [](const FReport& r) { return r.tether.newton_iterations; },
          "Newton iterations of the tethers' implicit solves, all tethers.")
      .def_property_readonly(
          "retries", [](const FReport& r) { return r.tether.retries; },
          "Retried tether sub-steps, all tethers.")
      .def_property_readonly(
          "tether_fallbacks", [](const FReport& r) { return r.tether_fallbacks; },
          "Tether steps redone explicitly.")
      .def_property_readonly(
          "energy", [](const FReport& r) { return energy_dict(r.energy); },
          "Energy after the step [J] (vehicles, point_masses, tethers: lists; total) when "
          "step(..., with_energy=True), else zeros.");

  py::class_<Fleet>(
      m, "Fleet",
      "Any fleet: N vehicles, P point masses and M tethers between them, anchors and free ends "
      "(kelp::system's fleet step: each tether by its implicit integrator, each body by RK4 under "
      "every tether end on it), built from a fleet scenario (one with \"fleet\"; the shipped "
      "ship_tms_rov.json, boat_two_rovs.json, rov_docking.json).\n\n"
      "    fleet = kelp.Fleet.from_scenario('ship_tms_rov.json')\n"
      "    state = fleet.initial_state()\n"
      "    u = fleet.inputs()\n"
      "    u.commands(fleet.vehicle_index('rov'))[:] = 0.1\n"
      "    for _ in range(100):\n"
      "        report = fleet.step(state, u, 0.01)\n\n"
      "Parts are found by index or name (vehicle_index, point_mass_index, tether_index). A step "
      "that fails raises kelp.InvalidArgument or kelp.NumericalError and leaves the state as it "
      "was. kelp.run_scenario runs a fleet scenario closed loop with its controllers.")
      .def_static(
          "from_scenario",
          [](py::object scenario) {
            std::string file;
            kelp::sim::Scenario sc = scenario_from_python(scenario, file);
            if (!sc.fleet)
              throw kelp::sim::scenario_error(file +
                                              ": /fleet: not a fleet scenario (kelp.System "
                                              "runs the pair's)");
            return std::make_unique<Fleet>(std::move(sc), file);
          },
          py::arg("scenario"),
          "The fleet of a scenario (a file path or a dict with \"fleet\"): its vehicles (presets, "
          "vehicle files, Gazebo models), point masses, anchors, tethers and sea. Raises "
          "kelp.ScenarioError naming the bad field.")
      .def(
          "initial_state",
          [](Fleet& f) {
            std::lock_guard<std::mutex> lock(f.mutex);
            return kelp::sim::fleet_start_state(f.model, f.workspace, f.world, f.scenario, f.file);
          },
          "The state a run of the scenario starts from (kelp::sim::fleet_start_state): every "
          "tether at its static shape between its ends, t = 0.")
      .def(
          "inputs",
          [](const Fleet& f) {
            FInputs in(f.model);
            for (int i = 0; i < f.model.vehicle_count(); ++i)
              if (const auto* p = f.model.propulsion(i))
                in.commands[std::size_t(i)].setZero(p->size());
            return in;
          },
          "Zero inputs sized for this fleet (commands for each vehicle with thrusters).")
      .def(
          "step",
          [](Fleet& f, FState& state, const FInputs* inputs, double dt, bool with_energy) {
            kfs::SystemStepOptions o;
            o.with_energy = with_energy;
            const FInputs none(f.model);
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(f.mutex);
            // A state whose winch lines have other node counts than the last one stepped (a
            // copy restored, a state loaded or unpickled) gets those counts' buffers.
            kfs::fit_workspace(f.model, f.workspace, state);
            return FReport(kfs::step(f.model, f.workspace, state, inputs ? *inputs : none, dt, o));
          },
          py::arg("state"), py::arg("inputs") = py::none(), py::arg("dt") = 0.01,
          py::arg("with_energy") = false,
          "Advances `state` in place by `dt` [s] under `inputs` (a kelp.FleetInputs; None: zero) "
          "and returns a kelp.FleetReport. The GIL is released during the step. Raises "
          "kelp.InvalidArgument (bad dt, inputs of another fleet, non-finite values) or "
          "kelp.NumericalError; the state is then unchanged. Any state of this fleet may be "
          "stepped: a copy, one restored from kelp.load_state or a pickle.")
      .def(
          "energy",
          [](const Fleet& f, const FState& state) {
            kfs::FleetEnergy<double> e;
            e.vehicles.assign(std::size_t(f.model.vehicle_count()), 0.0);
            e.point_masses.assign(std::size_t(f.model.point_mass_count()), 0.0);
            e.tethers.assign(std::size_t(f.model.tether_count()), 0.0);
            kfs::energy(f.model, state, e);
            return energy_dict(e);
          },
          py::arg("state"),
          "The mechanical energy of `state` [J]: vehicles, point_masses, tethers (lists), total.")
      .def_property_readonly(
          "vehicle_names", [](const Fleet& f) { return names_of(f.model.parameters().vehicles); },
          "The vehicles' names, in index order.")
      .def_property_readonly(
          "point_mass_names",
          [](const Fleet& f) { return names_of(f.model.parameters().point_masses); },
          "The point masses' names, in index order.")
      .def_property_readonly(
          "tether_names", [](const Fleet& f) { return names_of(f.model.parameters().tethers); },
          "The tethers' names, in index order.")
      .def(
          "vehicle_index",
          [](const Fleet& f, py::handle key) {
            return int(part_of(key, f.model.vehicle_count(),
                               names_of(f.model.parameters().vehicles), "vehicle"));
          },
          py::arg("name"), "A vehicle's index by name (or index, checked).")
      .def(
          "point_mass_index",
          [](const Fleet& f, py::handle key) {
            return int(part_of(key, f.model.point_mass_count(),
                               names_of(f.model.parameters().point_masses), "point mass"));
          },
          py::arg("name"), "A point mass's index by name (or index, checked).")
      .def(
          "tether_index",
          [](const Fleet& f, py::handle key) {
            return int(part_of(key, f.model.tether_count(), names_of(f.model.parameters().tethers),
                               "tether"));
          },
          py::arg("name"), "A tether's index by name (or index, checked).")
      .def(
          "tether_nodes",
          [](const Fleet&, const FState& s, int k) {
            return int(s.tethers[index_of(k, int(s.tethers.size()), "tether")].position.cols());
          },
          py::arg("state"), py::arg("k"), "Tether k's node count in `state` (a winch re-meshes).")
      .def_property_readonly(
          "environment", [](const Fleet& f) { return f.model.environment(); },
          "The fleet's environment (a copy: kelp.Environment).")
      .def_property_readonly(
          "notes", [](const Fleet& f) { return f.world.notes; },
          "What building the fleet changed in what it loaded (e.g. a Gazebo model's water).");

  m.def(
      "load_state",
      [](const py::bytes& b, const Fleet& f) {
        const std::string data = b;
        return kelp::sim::load_state(data, f.model);
      },
      py::arg("data"), py::arg("fleet"),
      "The kelp.FleetState saved in `data`, checked against `fleet` (its vehicle, point mass and "
      "tether counts, each tether's node count, each vehicle's thrusters). Raises "
      "kelp.StateError naming what is wrong.");
  m.def(
      "load_state_file",
      [](const std::string& path, const Fleet& f) {
        return kelp::sim::load_state_file(path, f.model);
      },
      py::arg("path"), py::arg("fleet"),
      "kelp.load_state of a fleet's file `path` (errors name it).");
}

}  // namespace kelp_python
