// The C++ objects behind kelp.Vehicle and kelp.System (vehicle.cpp, system.cpp), shared with
// other translation units of the module (e.g. kelp.Batch's) that take or return them.
#pragma once

#include <pybind11/pybind11.h>

#include <mutex>
#include <optional>
#include <string>

#include "kelp/sim/scenario.hpp"
#include "kelp/sim/world.hpp"
#include "kelp/system/system.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp_python {

namespace py = pybind11;

/// kelp.Vehicle: a preset's parameters and thrusters, its model (M and its factorisation, built
/// once) and its step buffers.
struct Vehicle {
  kelp::vehicle::VehiclePreset<double> preset;
  kelp::vehicle::VehicleModeld model;
  kelp::vehicle::ThrusterAllocationd thrusters;
  kelp::vehicle::VehicleWorkspaced workspace;
  std::mutex mutex;  // the workspace is shared: one step at a time (the GIL is released)

  explicit Vehicle(const kelp::vehicle::VehiclePreset<double>& p)
      : preset(p), model(p.parameters), thrusters(p.thruster_positions, p.thruster_directions) {}
};

/// kelp.System: the coupled ASV + tether + AUV in its environment, its workspace and what its
/// start state is built from (a scenario's world, or the paper's start poses).
struct System {
  kelp::sim::WorldSetup world;
  kelp::system::SystemModeld model;
  kelp::system::SystemWorkspaced workspace;
  /// Set when built from a scenario: the start state is then kelp::sim::start_state's (the
  /// state kelp-tethered-pair starts from).
  std::optional<kelp::sim::Scenario> scenario;
  std::mutex mutex;  // the workspace is shared: one step at a time (the GIL is released)

  System(const kelp::sim::WorldSetup& w, std::optional<kelp::sim::Scenario> sc)
      : world(w), model(w.parameters, w.environment), workspace(model), scenario(std::move(sc)) {}
};

/// A scenario from Python: None (the embedded default), a path (str or os.PathLike) or a dict
/// (as JSON; errors name "(dict)"). `file` is what errors and summaries call it.
/// \throws kelp::sim::scenario_error
inline kelp::sim::Scenario scenario_from_python(py::handle obj, std::string& file) {
  if (obj.is_none()) {
    file = "(embedded default)";
    return {};
  }
  if (py::isinstance<py::dict>(obj)) {
    file = "(dict)";
    const std::string text =
        py::str(py::module_::import("json").attr("dumps")(obj, py::arg("allow_nan") = false));
    return kelp::sim::parse_scenario(text, file);
  }
  file = py::str(py::module_::import("os").attr("fspath")(obj));
  return kelp::sim::load_scenario(file);
}

}  // namespace kelp_python
