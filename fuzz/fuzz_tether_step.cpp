// libFuzzer target: lumped-mass tether parameter validation followed by one step of every
// integrator (include/kelp/tether/lumped_mass.hpp, initial_state.hpp, integrators.hpp).
//
// Input (read in run() below; raw little-endian doubles, missing bytes take the defaults of
// the benchmark line): segments (1..64), flags (end modes, compressive damping, initial state),
// the 17 TetherParameters numbers, the environment (water density, gravity, seabed depth,
// current), the two ends (positions, velocities, accelerations), dt and the Newton settings.
// Oracle: TetherModel, the environment setters, the initial state and each step either throw a
// kelp::error or succeed; a step that succeeds leaves a finite state and, on the physical scale
// (fuzz_common.hpp: no number off [1e-12, 1e12]), the time advanced by dt and finite end forces;
// a step that throws kelp::numerical_error leaves the state unchanged (as documented). Any
// other exception, crash or sanitizer report is a finding.
#include <cstring>
#include <limits>
#include <optional>

#include "fuzz_common.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"

namespace kt = kelp::tether;

namespace {

bool same_state(const kt::TetherStated& a, const kt::TetherStated& b) {
  // Bitwise (NaN-safe) comparison of what a failed step must not touch.
  const auto eq = [](const kelp::Matrix3X<double>& x, const kelp::Matrix3X<double>& y) {
    return x.cols() == y.cols() &&
           std::memcmp(x.data(), y.data(), sizeof(double) * static_cast<std::size_t>(x.size())) ==
               0;
  };
  return eq(a.position, b.position) && eq(a.velocity, b.velocity) &&
         std::memcmp(&a.time, &b.time, sizeof a.time) == 0 &&
         std::memcmp(&a.previous_dt, &b.previous_dt, sizeof a.previous_dt) == 0 &&
         (a.previous_dt <= 0.0 || (eq(a.previous_position, b.previous_position) &&
                                   eq(a.previous_velocity, b.previous_velocity)));
}

void run(const std::uint8_t* data, std::size_t size) {
  kelp_fuzz::Reader in(data, size);
  kt::TetherParametersd p;
  p.segments = 1 + in.u8(19) % 64;  // bounded: the cost of one input, not a validity limit
  const std::uint8_t flags = in.u8(0);
  p.start_mode = (flags & 1) ? kt::EndMode::free : kt::EndMode::kinematic;
  p.end_mode = (flags & 2) ? kt::EndMode::free : kt::EndMode::kinematic;
  p.compressive_damping = (flags & 4) != 0;
  const bool catenary_start = (flags & 8) == 0;
  if (flags & 16) p.line_model = kt::LineModel::moordyn;
  for (double* v :
       {&p.length, &p.diameter, &p.mass_per_length, &p.axial_stiffness, &p.internal_damping,
        &p.bending_stiffness, &p.normal_drag, &p.tangential_drag, &p.normal_added_mass,
        &p.tangential_added_mass, &p.seabed_stiffness, &p.seabed_damping, &p.seabed_damping_depth,
        &p.seabed_friction, &p.friction_velocity, &p.start_point_mass, &p.end_point_mass})
    *v = in.f64(*v);
  const double rho = in.f64(1025.0), g = in.f64(9.81), seabed = in.f64(INFINITY);
  kelp::Vector3<double> current(0, 0, 0);
  for (int i = 0; i < 3; ++i) current(i) = in.f64(0.0);
  kelp::Vector3<double> a(0, 0, 0), b(8, 0, 5);
  for (int i = 0; i < 3; ++i) a(i) = in.f64(a(i));
  for (int i = 0; i < 3; ++i) b(i) = in.f64(b(i));
  kt::TetherBoundaryd ends = kt::TetherBoundaryd::fixed(a, b);
  for (int i = 0; i < 3; ++i) ends.start.velocity(i) = in.f64(0.0);
  for (int i = 0; i < 3; ++i) ends.end.velocity(i) = in.f64(0.0);
  for (int i = 0; i < 3; ++i) ends.start.acceleration(i) = in.f64(0.0);
  for (int i = 0; i < 3; ++i) ends.end.acceleration(i) = in.f64(0.0);
  const double dt = in.f64(1e-3);
  kt::ImplicitOptionsd opt;
  opt.acceleration_tolerance = in.f64(opt.acceleration_tolerance);
  opt.slack_band = in.f64(opt.slack_band);
  opt.max_iterations = in.u8(8) % 17;
  opt.max_active_set_passes = in.u8(32) % 65;
  opt.max_backtracks = in.u8(6) % 9;
  opt.max_step_halvings = in.u8(6) % 8;
  const std::uint8_t opt_flags = in.u8(1);
  opt.check_convergence = (opt_flags & 1) != 0;
  opt.resample_water = (opt_flags & 2) != 0;

  bool off_scale = kelp_fuzz::any_off_scale(
      p.length, p.diameter, p.mass_per_length, p.axial_stiffness, p.internal_damping,
      p.bending_stiffness, p.normal_drag, p.tangential_drag, p.normal_added_mass,
      p.tangential_added_mass, p.seabed_stiffness, p.seabed_damping, p.seabed_damping_depth,
      p.seabed_friction, p.friction_velocity, p.start_point_mass, p.end_point_mass, rho, g, seabed,
      dt, opt.acceleration_tolerance, opt.slack_band);
  for (const kelp::Vector3<double>* v : {&current, &a, &b, &ends.start.velocity, &ends.end.velocity,
                                         &ends.start.acceleration, &ends.end.acceleration})
    off_scale = off_scale || kelp_fuzz::any_off_scale(v->x(), v->y(), v->z());

  kelp::environment::Environmentd env;
  std::optional<kt::TetherModeld> model;
  try {
    env.set_water_density(rho).set_gravity(g).set_seabed_depth(seabed).set_current(current);
    model.emplace(p);
  } catch (const kelp::error&) {
    return;  // refused parameters: fine
  }
  kt::TetherWorkspaced ws(*model);
  kt::TetherStated s0;
  try {
    s0 = catenary_start ? kt::catenary_initial_state(*model, env, a, b)
                        : kt::straight_line_state(*model, a, b);
  } catch (const kelp::error&) {
    return;
  }
  for (const kt::Integrator integrator :
       {kt::Integrator::symplectic_euler, kt::Integrator::rk2, kt::Integrator::rk4,
        kt::Integrator::implicit_euler, kt::Integrator::bdf2}) {
    kt::TetherStated s = s0;
    const std::string what = std::string("tether step ") + kt::integrator_name(integrator);
    try {
      kt::step(*model, ws, env, s, ends, dt, {integrator, opt});
    } catch (const kelp::numerical_error&) {
      KELP_FUZZ_REQUIRE(same_state(s, s0), what + ": numerical_error changed the state");
      continue;
    } catch (const kelp::error&) {
      continue;
    }
    KELP_FUZZ_REQUIRE(s.position.allFinite() && s.velocity.allFinite(),
                      what + ": non-finite state after a successful step");
    if (off_scale) continue;
    // A step retried in halves adds dt/2 + dt/4 + ...: exact up to the rounding of those sums
    // (not for a subnormal dt, whose halves round: hence after the scale check).
    KELP_FUZZ_REQUIRE(std::abs(s.time - (s0.time + dt)) <=
                          16 * std::numeric_limits<double>::epsilon() * (std::abs(s0.time) + dt),
                      what + ": time did not advance by dt");
    KELP_FUZZ_REQUIRE(ws.end_forces.on_start.allFinite() && ws.end_forces.on_end.allFinite(),
                      what + ": non-finite end forces after a successful step");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return kelp_fuzz::run_catching_stray_errors(run, data, size);
}
