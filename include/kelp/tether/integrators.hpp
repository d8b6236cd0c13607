/// \file
/// \brief Time integration of the lumped-mass tether: semi-implicit (symplectic) Euler, RK2
/// (midpoint), RK4, and implicit backward Euler / BDF2 solved by Newton's method with the
/// analytic block-tridiagonal Jacobian (O(N) block-Thomas solve) or the whole Jacobian
/// (ImplicitOptions::jacobian, O(N) block LU); an explicit stable-dt estimate,
/// a sub-stepping driver and a static-equilibrium solve.
///
/// Kinematic ends follow the prescribed EndMotion within a step (p + vτ + ½aτ²). Every scheme
/// reports the end forces at the end of the step, with the end nodes' inertia taken off
/// (TetherWorkspace::end_forces) and without it (TetherWorkspace::end_node_forces).
///
/// Every step works in preallocated workspace buffers (no heap allocation) and commits the new
/// state only when it is finite and, for the implicit schemes, when Newton's method met its
/// tolerance: an implicit step that does not converge is retried in sub-steps (halving up to
/// `ImplicitOptions::max_step_halvings` times), and a step that cannot be completed throws
/// `kelp::numerical_error` and leaves the state as it was. Time steps and the clock are doubles
/// for every Scalar; the integrator history (BDF2) lives in the TetherState.
///
/// This header gathers the parts: kelp/tether/stepping.hpp (schemes, options, reports),
/// kelp/tether/explicit.hpp, kelp/tether/implicit.hpp (with kelp/tether/block_solve.hpp),
/// kelp/tether/stable_dt.hpp, kelp/tether/driver.hpp (`step`, `advance`) and
/// kelp/tether/statics.hpp.
#pragma once

#include "kelp/environment/limits.hpp"
#include "kelp/tether/block_solve.hpp"
#include "kelp/tether/driver.hpp"
#include "kelp/tether/explicit.hpp"
#include "kelp/tether/implicit.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/stable_dt.hpp"
#include "kelp/tether/statics.hpp"
#include "kelp/tether/stepping.hpp"
