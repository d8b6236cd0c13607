// Bad input at the vehicle layer's public boundary: absurd but finite parameters whose derived
// quantities overflow, NaN / Inf currents and times and mis-sized wrenches given to the steps,
// thruster allocation with a NaN wrench or mismatched sizes, thruster models with non-finite or
// non-physical curves. Each bad input must throw kelp::invalid_argument; the valid inputs next to
// them must keep working, and a step that blows up from valid input must still end as
// kelp::numerical_error with the state unchanged.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/vehicle/added_mass.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/paper.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/restoring.hpp"
#include "kelp/vehicle/rigid_body.hpp"
#include "kelp/vehicle/thrusters.hpp"
#include "support/non_finite.hpp"

using kelp::Vector3;
using kelp::Vector6;
namespace kv = kelp::vehicle;
namespace ke = kelp::environment;

namespace {

using kelp_test::kInf;
using kelp_test::kNan;

bool same(const kv::VehicleState<double>& a, const kv::VehicleState<double>& b) {
  return a.position == b.position && a.attitude.coeffs() == b.attitude.coeffs() && a.nu == b.nu &&
         a.time == b.time;
}

}  // namespace

TEST_CASE("bad input: absurd vehicle parameters are refused where the model is built",
          "[vehicle][bad_input]") {
  const auto rov = kv::bluerov2_heavy<double>().parameters;
  auto p = rov;
  p.density = 1e300;  // buoyancy 1.3e299 N: the first step would overflow
  REQUIRE_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(kv::VehicleModel<double>(p),
                      Catch::Contains("density") && Catch::Contains("1e+300"));
  p = rov;
  p.gravity = 1e300;
  REQUIRE_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(kv::VehicleModel<double>(p), Catch::Contains("gravity"));
  p = rov;
  p.mass = 1e308;  // m g overflows
  p.inertia *= 1e300;
  REQUIRE_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(kv::VehicleModel<double>(p), Catch::Contains("weight"));
  p = rov;
  p.r_g = Vector3<double>(1e200, 0.0, 0.0);  // m S(r_g)² overflows in M_RB
  REQUIRE_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::rigid_body_mass_matrix(p.mass, p.inertia, p.r_g), kelp::invalid_argument);
  p = rov;
  p.displaced_volume = 1e306;  // ρ g ∇ overflows
  REQUIRE_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(kv::VehicleModel<double>(p), Catch::Contains("buoyancy"));
  auto boat = kv::blueboat<double>().parameters;
  boat.gm_transverse = 1e308;  // roll stiffness ρ g ∇ GM_T overflows
  REQUIRE_THROWS_AS(kv::VehicleModel<double>(boat), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(kv::VehicleModel<double>(boat), Catch::Contains("gm_transverse"));

  // Presets validate the water they are built for (the boat's volume is m/ρ).
  for (const double rho : {0.0, -1025.0, kNan, 1e300}) {
    INFO("density " << rho);
    REQUIRE_THROWS_AS(kv::blueboat<double>(rho), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(kv::blueboat<double>(rho), Catch::Contains("density"));
    REQUIRE_THROWS_AS(kv::bluerov2_heavy<double>(rho), kelp::invalid_argument);
  }
  REQUIRE_THROWS_AS(kv::bluerov2_heavy<double>(1025.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::blueboat<double>(1025.0, 1e300), kelp::invalid_argument);

  // Nearby valid water: fresh water, the Moon, a dense brine; a step stays finite.
  for (const auto& water :
       {std::pair<double, double>{1000.0, 9.82}, {1025.0, 1.62}, {1240.0, 9.81}}) {
    INFO("rho " << water.first << " g " << water.second);
    const kv::VehicleModel<double> model(
        kv::bluerov2_heavy<double>(water.first, water.second).parameters);
    CHECK(model.buoyancy() == Approx(water.first * water.second * 0.0134));
    kv::VehicleWorkspace<double> ws;
    kv::VehicleState<double> x;
    x.position.z() = 5.0;  // fully submerged
    kv::step_rk4(model, ws, x, {Vector6<double>::Zero(), Vector6<double>::Zero()}, 0.01);
    CHECK(x.nu.allFinite());
    CHECK((x.nu(2) < 0.0) == (model.buoyancy() > model.weight()));  // rises if buoyant
  }
  CHECK_NOTHROW(kv::VehicleModel<double>(kv::blueboat<double>(1000.0, 9.81).parameters));
}

TEST_CASE("bad input: steps refuse NaN currents and times and mis-sized wrenches",
          "[vehicle][bad_input]") {
  const kv::VehicleModel<double> model(kv::bluerov2_heavy<double>().parameters);
  kv::VehicleWorkspace<double> ws;
  kv::VehicleState<double> x;
  x.position << 1.0, 2.0, 5.0;
  x.nu << 0.2, 0.0, 0.1, 0.0, 0.0, 0.05;
  const kv::VehicleState<double> before = x;
  const Vector6<double> zero = Vector6<double>::Zero();
  Vector6<double> bad = zero;
  bad(3) = kNan;
  // A non-finite wrench is the documented numerical_error (tests/vehicle/test_dynamics.cpp), state
  // unchanged; a wrench of the wrong size is an invalid argument.
  REQUIRE_THROWS_AS(kv::step_rk4(model, ws, x, {bad, zero}, 0.01), kelp::numerical_error);
  REQUIRE_THROWS_AS(kv::step_rk4(model, ws, x, {zero, bad}, 0.01), kelp::numerical_error);
  CHECK(same(x, before));
  REQUIRE_THROWS_AS(kv::step_rk4(model, ws, x, {zero, zero}, 0.01, Vector3<double>(kInf, 0, 0)),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::step_symplectic_euler(model, ws, x, {bad, zero}, 0.01),
                    kelp::numerical_error);
  REQUIRE_THROWS_AS(
      kv::step_symplectic_euler(model, ws, x, {zero, zero}, 0.01, Vector3<double>(kNan, 0, 0)),
      kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::step_rk4_with(
                        model, ws, x, [&](const kv::VehicleState<double>&, double) { return zero; },
                        0.01, Vector3<double>(0, kNan, 0)),
                    kelp::invalid_argument);
  // The steps take their wrenches as VehicleInputs (two Vector6): a wrench of the wrong size
  // cannot reach them. forward_dynamics takes any Eigen expression and checks the size.
  const Eigen::VectorXd short_tau = Eigen::VectorXd::Zero(5);
  REQUIRE_THROWS_AS(kv::forward_dynamics(model, ws, x, short_tau, zero), kelp::invalid_argument);
  const Eigen::VectorXd long_current = Eigen::VectorXd::Zero(4);
  REQUIRE_THROWS_AS(kv::forward_dynamics(model, ws, x, zero, zero, long_current),
                    kelp::invalid_argument);
  const ke::Environment<double> env = ke::make_environment<double>(ke::presets::moderate());
  kv::VehicleState<double> xt = x;  // the clock is the state's
  xt.time = kNan;
  REQUIRE_THROWS_AS(kv::step_rk4(model, ws, env, xt, {zero, zero}, 0.01), kelp::invalid_argument);
  xt.time = kInf;
  REQUIRE_THROWS_WITH(kv::step_rk4(model, ws, env, xt, {zero, zero}, 0.01),
                      Catch::Contains("state.time must be finite"));
  CHECK(same(x, before));

  // The valid neighbours step, and give the same result as before any refused call.
  kv::VehicleState<double> y = before;
  kv::step_rk4(model, ws, x, {zero, zero}, 0.01);
  kv::step_rk4(model, ws, y, {zero, zero}, 0.01);
  CHECK(same(x, y));
  CHECK_FALSE(same(x, before));
  x.time = 1e5;
  kv::step_rk4(model, ws, env, x, {zero, zero}, 0.01);
  CHECK(x.nu.allFinite());

  // A huge but finite wrench is valid input: the step blows up and says so as a numerical error,
  // state unchanged (also for a surface vessel, whose wind load reads the blown-up stage states).
  const Vector6<double> huge = Vector6<double>::Constant(1e308);
  kv::VehicleState<double> z = before;
  REQUIRE_THROWS_AS(kv::step_rk4(model, ws, z, {huge, zero}, 0.01), kelp::numerical_error);
  CHECK(same(z, before));
  const kv::VehicleModel<double> boat(kv::blueboat<double>().parameters);
  kv::VehicleState<double> b;
  b.time = 10.0;
  const kv::VehicleState<double> b0 = b;
  REQUIRE_THROWS_AS(kv::step_rk4(boat, ws, env, b, {huge, zero}, 0.01), kelp::numerical_error);
  CHECK(same(b, b0));
}

TEST_CASE("bad input: thruster allocation with NaN wrenches and mismatched sizes",
          "[vehicle][bad_input]") {
  const auto rov = kv::bluerov2_heavy<double>();
  const kv::ThrusterAllocation<double> alloc(rov.thruster_positions, rov.thruster_directions);
  Eigen::VectorXd f = Eigen::VectorXd::Constant(8, 3.0);
  const Eigen::VectorXd f_before = f;
  Vector6<double> tau;
  tau << 10.0, -5.0, 3.0, 0.5, -0.2, 1.0;
  Vector6<double> bad = tau;
  bad(2) = kNan;
  REQUIRE_THROWS_AS(alloc.distribute(bad, f), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(alloc.distribute(bad, f), Catch::Contains("tau"));
  CHECK(f == f_before);  // left unchanged
  const Eigen::VectorXd tau5 = Eigen::VectorXd::Zero(5);
  REQUIRE_THROWS_AS(alloc.distribute(tau5, f), kelp::invalid_argument);
  Eigen::VectorXd f_bad = f;
  f_bad(7) = kInf;
  REQUIRE_THROWS_AS(alloc.wrench(f_bad), kelp::invalid_argument);
  REQUIRE_THROWS_AS(alloc.wrench(Eigen::VectorXd::Zero(7)), kelp::invalid_argument);
  // Valid: the BlueROV2 Heavy is fully actuated, so B B⁺ τ = τ.
  alloc.distribute(tau, f);
  CHECK((alloc.wrench(f) - tau).norm() < 1e-12 * tau.norm());

  // An allocation matrix whose moments overflow.
  kelp::Matrix3X<double> r(3, 1), d(3, 1);
  r << 1.7e308, -1.7e308, 0.0;
  d << 1.0, 1.0, 0.0;
  REQUIRE_THROWS_AS(kv::allocation_matrix(r, d), kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::ThrusterAllocation<double>(r, d), kelp::invalid_argument);
  r << 0.1, -0.1, 0.0;
  const auto B = kv::allocation_matrix(r, d);
  CHECK(B(5, 0) == Approx(0.2 / std::sqrt(2.0)));  // (r × d̂)_z = (r_x d_y − r_y d_x)/√2

  // T200 curve and PWM mapping.
  REQUIRE_THROWS_AS(kv::t200_thrust_slope(kNan), kelp::invalid_argument);
  CHECK(kv::thrust_slope(kv::von_benzon_t200_model, 0.0) == Approx(8.9));
  CHECK(kv::t200_thrust_slope(0.0) == 0.0);  // the datasheet's dead band
  kv::PwmMapping<double> m;
  m.min_us = 2000.0;  // above neutral: invalid
  REQUIRE_THROWS_AS(kv::command_from_pwm(1700.0, m), kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::pwm_from_command(0.5, m), kelp::invalid_argument);
  CHECK(kv::command_from_pwm(1900.0) == 1.0);
  CHECK(kv::pwm_from_command(-1.0) == 1100.0);
}

TEST_CASE("bad input: a thruster model is checked wherever it enters", "[vehicle][bad_input]") {
  const kv::ThrusterModel good = kv::von_benzon_t200_model;
  kv::ThrusterModel nan_coefficient = good, no_thrust = good, nan_thrust = good, no_peak = good,
                    past_full = good, no_curve = good;
  nan_coefficient.odd_coefficients[2] = kNan;
  no_thrust.max_thrust = 0.0;
  nan_thrust.max_thrust = kNan;
  no_peak.peak_command = 0.0;
  past_full.peak_command = 1.5;
  no_curve.curve = static_cast<kv::ThrusterCurve>(7);
  const kv::PwmMapping<double> pwm;
  for (const kv::ThrusterModel& m :
       {nan_coefficient, no_thrust, nan_thrust, no_peak, past_full, no_curve}) {
    REQUIRE_THROWS_AS(kv::validate(m), kelp::invalid_argument);
    REQUIRE_THROWS_AS(kv::thrust(m, 0.5), kelp::invalid_argument);
    REQUIRE_THROWS_AS(kv::thrust_slope(m, 0.5), kelp::invalid_argument);
    REQUIRE_THROWS_AS(kv::command_for_thrust(m, 5.0), kelp::invalid_argument);
    REQUIRE_THROWS_AS(kv::max_forward_thrust(m, 16.0), kelp::invalid_argument);
    REQUIRE_THROWS_AS(kv::max_reverse_thrust(m, 16.0), kelp::invalid_argument);
    REQUIRE_THROWS_AS(kv::thrust_from_pwm(m, 1700.0, pwm), kelp::invalid_argument);
  }
  REQUIRE_THROWS_WITH(kv::thrust(nan_coefficient, 0.5), Catch::Contains("odd_coefficients"));
  REQUIRE_THROWS_WITH(kv::thrust(no_thrust, 0.5), Catch::Contains("max_thrust"));
  REQUIRE_THROWS_WITH(kv::thrust(past_full, 0.5), Catch::Contains("peak_command"));
  REQUIRE_THROWS_WITH(kv::thrust(no_curve, 0.5), Catch::Contains("curve"));
  // The valid models pass; the datasheet curve ignores the polynomial's fields.
  kv::validate(good);
  kv::validate(kv::t200_model);
  kv::ThrusterModel datasheet = kv::t200_model;
  datasheet.odd_coefficients[0] = kNan;
  CHECK(kv::thrust(datasheet, 0.5) == kv::thrust(kv::t200_model, 0.5));
  CHECK(kv::thrust(good, 1.0) == Approx(30.4).epsilon(1e-6));
}

TEST_CASE("bad input: added mass, restoring and hull parameters", "[vehicle][bad_input]") {
  REQUIRE_THROWS_AS(kv::diagonal_added_mass(Eigen::VectorXd::Ones(5)), kelp::invalid_argument);
  Eigen::VectorXd a(6);
  a << 6.36, 7.12, 18.68, 0.189, 0.135, 0.222;
  CHECK(kv::diagonal_added_mass(a)(2, 2) == 18.68);
  a(4) = kNan;
  REQUIRE_THROWS_AS(kv::diagonal_added_mass(a), kelp::invalid_argument);

  REQUIRE_THROWS_AS(kv::submerged_fraction(0.0, 0.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::submerged_fraction(0.0, 0.0, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(kv::submerged_fraction(0.0, 0.0, -0.25), kelp::invalid_argument);
  CHECK(kv::submerged_fraction(0.0, 0.0, 0.25) == 0.5);
  CHECK(kv::submerged_fraction(1.0, 0.0, 0.25) == 1.0);

  // The surface vessel's hydrostatics handed to the environment layer stay valid.
  const auto boat = kv::blueboat<double>().parameters;
  CHECK_NOTHROW(ke::validate(kv::surface_hydrostatics(boat)));
}

// Fuzz finding (fuzz/regressions/fuzz_vehicle_step/vehicle_step_non_unit_attitude.bin): a step
// whose yaw rate grew to ~1e240 rad/s within one step committed the zero quaternion. RK4's stage
// quaternion q + h q̇ had coefficients ~1e238, whose squared norm overflows to +Inf, so the
// renormalisation q / √(q·q) divided by +Inf and gave (0, 0, 0, 0): finite, so the step's
// finiteness check let it through, and Eigen reads a zero quaternion as a zero "rotation" matrix.
// The norm of a quaternion is now taken on a rescaled copy when its square leaves the normal
// range, and a step that ends with a non-unit attitude anyway is a numerical_error.
TEST_CASE("a step keeps the attitude a unit quaternion however fast the vehicle turns",
          "[vehicle][bad_input][fuzz]") {
  SECTION("renormalize: squared norms that overflow or underflow") {
    for (const double scale : {1e200, 1e-200, 1e160, 1e-170, 1e300, 4.9e-324}) {
      INFO("scale " << scale);
      kelp::Quaternion<double> q(scale, scale, -scale, 0.0);
      kv::renormalize(q);
      CHECK(q.squaredNorm() == Approx(1.0).epsilon(1e-15));
      CHECK(q.w() == Approx(1.0 / std::sqrt(3.0)));
      CHECK(q.y() == Approx(-1.0 / std::sqrt(3.0)));
    }
    for (const float scale : {1e30f, 1e-30f, 1e-40f}) {
      INFO("float scale " << scale);
      kelp::Quaternion<float> q(scale, 0.0f, 0.0f, scale);
      kv::renormalize(q);
      CHECK(q.squaredNorm() == Approx(1.0f).epsilon(1e-6));
      CHECK(q.z() == Approx(1.0 / std::sqrt(2.0)).epsilon(1e-6));
    }
    // A unit quaternion in the normal range is divided by its norm as before (bit for bit).
    kelp::Quaternion<double> q(0.5, 0.5, 0.5, 0.5), r = q;
    q.coeffs() *= 1.1;
    r.coeffs() *= 1.1;
    kv::renormalize(q);
    r.coeffs() /= std::sqrt(r.coeffs().squaredNorm());
    CHECK(q.coeffs() == r.coeffs());
  }

  SECTION("a yaw wrench that spins the vehicle up to ~1e240 rad/s within one step") {
    // No quadratic damping, so that ν̇ stays finite at these rates: the yaw rate grows by
    // τ_N dt / (I_zz + N_ṙ) per step and the attitude turns through ~r dt rad, far beyond
    // anything physical, but every number stays finite.
    auto p = kv::bluerov2_heavy<double>().parameters;
    p.damping.quadratic.setZero();
    const kv::VehicleModel<double> model(p);
    const ke::Environment<double> env;
    kv::VehicleWorkspace<double> ws;
    const Vector6<double> zero = Vector6<double>::Zero();
    for (const double n : {1e200, 1e245, 1e280}) {
      INFO("yaw moment " << n << " N m");
      Vector6<double> tau = zero;
      tau(5) = n;
      for (int integrator = 0; integrator < 3; ++integrator) {
        INFO("integrator " << integrator);
        kv::VehicleState<double> x;
        x.position.z() = 5.0;
        const kv::VehicleState<double> before = x;
        try {
          if (integrator == 0)
            kv::step_rk4(model, ws, x, {tau, zero}, 1e-3);
          else if (integrator == 1)
            kv::step_symplectic_euler(model, ws, x, {tau, zero}, 1e-3);
          else
            kv::step_rk4(model, ws, env, x, {tau, zero}, 1e-3);
        } catch (const kelp::numerical_error&) {
          CHECK(same(x, before));  // refused: the state as it was
          continue;
        }
        REQUIRE(x.attitude.coeffs().allFinite());
        CHECK(x.attitude.squaredNorm() == Approx(1.0).epsilon(1e-12));
        CHECK(x.nu(5) > 0.0);  // it did spin up, about +z
      }
    }
  }
}

// The probe: forward_dynamics took a NaN τ and answered a NaN ν̇. As a public entry point it
// now refuses every non-finite value it reads (τ, τ_ext, the state, the surroundings) before
// touching the workspace; the steps evaluate their stages without these checks, so a NaN that
// appears inside a step (a NaN wrench, a stage state that blows up) still ends the step as
// numerical_error with the state unchanged, never as an invalid_argument from a stage.
TEST_CASE("bad input: forward_dynamics refuses non-finite input; the steps keep numerical_error",
          "[vehicle][bad_input]") {
  const kv::VehicleModel<double> model(kv::bluerov2_heavy<double>().parameters);
  kv::VehicleWorkspace<double> ws;
  kv::VehicleState<double> x;
  x.position.z() = 5.0;
  const Vector6<double> zero = Vector6<double>::Zero();
  REQUIRE_THROWS_AS(kv::forward_dynamics(model, ws, x, Eigen::VectorXd::Zero(7), zero),
                    kelp::invalid_argument);
  const Vector6<double> good = kv::forward_dynamics(model, ws, x, zero, zero);
  CHECK(good.allFinite());
  for (const double bad_value : {kNan, kInf, -kInf}) {
    INFO("value " << bad_value);
    for (int i = 0; i < 6; ++i) {
      Vector6<double> bad = zero;
      bad(i) = bad_value;
      REQUIRE_THROWS_WITH(kv::forward_dynamics(model, ws, x, bad, zero),
                          Catch::StartsWith("forward_dynamics: tau must be finite"));
      REQUIRE_THROWS_WITH(kv::forward_dynamics(model, ws, x, zero, bad),
                          Catch::Contains("tau_ext must be finite"));
    }
    REQUIRE_THROWS_AS(
        kv::forward_dynamics(model, ws, x, zero, zero, Vector3<double>(0.0, bad_value, 0.0)),
        kelp::invalid_argument);
    kv::Surroundings<double> s;
    s.surface_elevation = bad_value;
    REQUIRE_THROWS_WITH(kv::forward_dynamics(model, ws, x, zero, zero, s),
                        Catch::Contains("surroundings"));
    kv::VehicleState<double> y = x;
    y.nu(4) = bad_value;
    REQUIRE_THROWS_WITH(kv::forward_dynamics(model, ws, y, zero, zero),
                        Catch::Contains("state.nu"));
    y = x;
    y.position(0) = bad_value;
    REQUIRE_THROWS_AS(kv::forward_dynamics(model, ws, y, zero, zero), kelp::invalid_argument);
  }
  // Refused before the workspace is touched: it still holds the last good evaluation.
  CHECK(ws.nu_dot == good);

  // Every step still reports a NaN wrench as numerical_error, state unchanged: held over the
  // step (τ or τ_ext), in still water, in a current and in an environment, and from a wrench
  // callable that turns NaN only at a later RK4 stage.
  Vector6<double> nan_wrench = zero;
  nan_wrench(1) = kNan;
  const ke::Environment<double> env = ke::make_environment<double>(ke::presets::moderate());
  const Vector3<double> current(0.3, 0.0, 0.0);
  x.time = 20.0;
  const kv::VehicleState<double> before = x;
  for (const kv::VehicleInputs<double>& in :
       {kv::VehicleInputs<double>{nan_wrench, zero}, kv::VehicleInputs<double>{zero, nan_wrench}}) {
    REQUIRE_THROWS_AS(kv::step_rk4(model, ws, x, in, 0.01), kelp::numerical_error);
    REQUIRE_THROWS_AS(kv::step_rk4(model, ws, x, in, 0.01, current), kelp::numerical_error);
    REQUIRE_THROWS_AS(kv::step_rk4(model, ws, env, x, in, 0.01), kelp::numerical_error);
    REQUIRE_THROWS_AS(kv::step_symplectic_euler(model, ws, x, in, 0.01), kelp::numerical_error);
    REQUIRE_THROWS_AS(kv::step_symplectic_euler(model, ws, x, in, 0.01, current),
                      kelp::numerical_error);
    REQUIRE_THROWS_AS(kv::step_symplectic_euler(model, ws, env, x, in, 0.01),
                      kelp::numerical_error);
    CHECK(same(x, before));
  }
  const auto late_nan = [&](const kv::VehicleState<double>&, double offset) {
    return offset > 0.0 ? nan_wrench : zero;
  };
  REQUIRE_THROWS_AS(kv::step_rk4_with(model, ws, x, late_nan, 0.01), kelp::numerical_error);
  CHECK(same(x, before));
  // The step that takes a NaN state refuses it up front, as before.
  kv::VehicleState<double> nan_state = x;
  nan_state.nu(0) = kNan;
  REQUIRE_THROWS_AS(kv::step_rk4(model, ws, nan_state, {zero, zero}, 0.01), kelp::invalid_argument);
}
