/// \file
/// \brief Lumped-mass tether model: parameters, workspace, state, end conditions and the force
/// evaluation (axial tension, internal damping, optional bending stiffness, weight and buoyancy,
/// Morison drag, added mass, fluid-inertia forcing, seabed contact with friction).
///
/// The line of unstretched length L is cut into N segments of length l = L/N joined at N+1 nodes
/// (node 0 = start end, e.g. the ASV; node N = far end, e.g. the AUV). The model follows the
/// lumped-mass formulation of Hall & Goupee (2015, "Validation of a lumped-mass mooring line
/// model with DeepCwind semisubmersible model test data", Ocean Engineering 104) as implemented
/// in MoorDyn v2 (source/Line.cpp); the code is kelp's own. Two deliberate differences from
/// MoorDyn: the added mass enters through the kinetic energy (its rate of change included, so the
/// line is passive), and the axial force never pushes (see TetherParameters::compressive_damping).
/// `TetherParameters::line_model = LineModel::moordyn` selects MoorDyn's line model instead.
///
/// Frames and units: world NED (z down, mean sea surface at z = 0, free surface at z = −ζ), SI.
/// Environments are duck-typed (`Env`): anything with `water_density()`, `gravity()`,
/// `seabed_depth()`, `surface_elevation(x, y, t)` and `sample_water(points, t, vel, acc)` as
/// `kelp::environment::Environment` has (its `sample_water(points, t, vel, acc, elevation)`, when
/// present, saves the per-node elevation queries; a five-argument one of another signature is a
/// compile error). docs/custom-environment.md gives the exact signatures and an example.
///
/// This header gathers the parts: kelp/tether/model.hpp (parameters and model),
/// kelp/tether/state.hpp (state, boundary, workspace), kelp/tether/forces.hpp (force evaluation,
/// energy) and kelp/tether/force_kernels.hpp (its SIMD kernels).
#pragma once

#include "kelp/tether/forces.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
