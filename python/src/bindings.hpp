// The kelp Python extension module (kelp._kelp): what its translation units share.
//
// The module is split in several .cpp files (one per area of the library), each defining one
// bind_*() function that module.cpp calls in the order below; every python/src/*.cpp is compiled
// into the module (python/CMakeLists.txt globs them). To add bindings of a new area: declare its
// bind_*() here, define it in a new .cpp, call it from module.cpp. kelp.Batch and the learning
// environment have their hooks ready: bind_batch() (batch.cpp) and bind_learning()
// (learning.cpp), each defined there as an empty function until filled.
#pragma once

// The double-precision system, tether step and wave kernels the module binds are kelp::sim's,
// compiled once in the library (declared extern here), not again in each of the module's units.
#include "kelp/sim/instantiation.hpp"

#include <pybind11/pybind11.h>

namespace kelp_python {

namespace py = pybind11;

/// kelp.Error, kelp.InvalidArgument (a ValueError), kelp.NumericalError (a RuntimeError),
/// kelp.ScenarioError and kelp.StateError (InvalidArguments) and the translation of kelp's C++
/// exceptions to them (errors.cpp). Called first.
void bind_errors(py::module_& m);

/// kelp.VehicleState, kelp.Vehicle, kelp.t200_thrust/t200_current (vehicle.cpp).
void bind_vehicle(py::module_& m);

/// kelp.Environment (environment.cpp).
void bind_environment(py::module_& m);

/// kelp.catenary and kelp.Catenary (catenary.cpp).
void bind_catenary(py::module_& m);

/// kelp.System, kelp.SystemState, kelp.SystemInputs, kelp.SystemReport (system.cpp; after
/// bind_vehicle and bind_environment, whose types it returns).
void bind_system(py::module_& m);

/// kelp.Fleet, kelp.FleetState, kelp.FleetInputs, kelp.FleetReport (fleet.cpp; after
/// bind_vehicle and bind_environment, whose types it returns).
void bind_fleet(py::module_& m);

/// kelp.run_scenario's C++ part, kelp._kelp._run_scenario (scenario.cpp).
void bind_scenario(py::module_& m);

/// kelp.Batch: many worlds at once (batch.cpp). Called after everything else, so that it may use
/// every type bound before it.
void bind_batch(py::module_& m);

/// The learning environment's C++ part, if any (learning.cpp). Called last.
void bind_learning(py::module_& m);

}  // namespace kelp_python
