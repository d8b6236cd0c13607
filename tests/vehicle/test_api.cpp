// API consistency of the vehicle layer: step_<scheme> names, dt as a non-deduced parameter (a
// double literal with a float model), free validate() functions, and what the workspace holds
// after a step.
#include <catch2/catch.hpp>

#include <type_traits>
#include <utility>

#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"

using kelp::Vector3;
using kelp::Vector6;
namespace kv = kelp::vehicle;

namespace {

// True when T has a member validate() (the old style); every parameter set now has a free
// validate(const T&) instead.
template <typename T, typename = void>
struct has_member_validate : std::false_type {};
template <typename T>
struct has_member_validate<T, std::void_t<decltype(std::declval<const T&>().validate())>>
    : std::true_type {};

}  // namespace

TEST_CASE("vehicle steps take a double literal dt with a float model", "[vehicle][api]") {
  const kv::VehicleModel<float> model(kv::bluerov2_heavy<float>().parameters);
  kv::VehicleWorkspace<float> ws;
  kv::VehicleState<float> x, y, z;
  x.nu(0) = 0.5F;
  y = z = x;
  const Vector6<float> zero = Vector6<float>::Zero();
  // `0.01` is a double: with `const Scalar& dt` this did not compile (Scalar deduced as both
  // float and double).
  kv::step_rk4(model, ws, x, {zero, zero}, 0.01);
  kv::step_rk4(model, ws, y, {zero, zero}, 0.01F, Vector3<float>::Zero());
  kv::step_symplectic_euler(model, ws, z, {zero, zero}, 0.01);
  kv::step_rk4_with(
      model, ws, z, [&](const kv::VehicleState<float>&, float) { return zero; }, 1e-2,
      Vector3<float>::Zero());
  STATIC_REQUIRE(std::is_same_v<decltype(x.nu), Vector6<float>>);
  CHECK(x.nu(0) == y.nu(0));  // the literal became the same float step
  CHECK(x.nu(0) < 0.5F);      // and damping slowed the surge down
  CHECK(x.position(0) > 0.0F);
}

TEST_CASE("parameter sets are checked by free validate() functions", "[vehicle][api]") {
  STATIC_REQUIRE_FALSE(has_member_validate<kv::VehicleParameters<double>>::value);
  STATIC_REQUIRE_FALSE(has_member_validate<kv::DampingParameters<double>>::value);
  STATIC_REQUIRE_FALSE(has_member_validate<kv::PwmMapping<double>>::value);
  auto p = kv::bluerov2_heavy<double>().parameters;
  CHECK_NOTHROW(kv::validate(p));
  p.damping.quadratic(2) = -1.0;
  CHECK_THROWS_WITH(kv::validate(p.damping), Catch::Contains("quadratic_damping"));
  CHECK_THROWS_WITH(kv::validate(p), Catch::Contains("quadratic_damping"));
  CHECK_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  p = kv::bluerov2_heavy<double>().parameters;
  p.mass = 0.0;
  CHECK_THROWS_WITH(kv::VehicleModel<double>(p), Catch::Contains("mass"));
  kv::PwmMapping<double> pwm;
  pwm.min_us = 1600.0;
  CHECK_THROWS_WITH(kv::validate(pwm), Catch::Contains("min_us"));
}

TEST_CASE("after a step the workspace holds the last evaluation's terms (documented)",
          "[vehicle][api]") {
  const kv::VehicleModel<double> model(kv::bluerov2_heavy<double>().parameters);
  kv::VehicleState<double> x0;
  x0.position << 1.0, 2.0, 10.0;
  x0.attitude =
      kelp::Quaternion<double>(Eigen::AngleAxisd(0.3, Vector3<double>(1, 1, 0).normalized()));
  x0.nu << 0.6, -0.2, 0.1, 0.3, -0.2, 0.4;
  Vector6<double> tau;
  tau << 20, -5, 10, 1, -2, 3;
  const Vector6<double> zero = Vector6<double>::Zero();
  const Vector3<double> current(0.3, -0.1, 0.0);
  const double dt = 0.05;

  // RK4: the fourth stage, at the predictor x4 = x0 + dt k3, rebuilt here stage by stage.
  kv::VehicleWorkspace<double> ws, ref;
  kv::VehicleState<double> x = x0;
  kv::step_rk4(model, ws, x, {tau, zero}, dt, current);
  const auto k1 = kv::state_derivative(model, ref, x0, tau, current);
  const auto k2 =
      kv::state_derivative(model, ref, kv::detail::advance(x0, k1, 0.5 * dt), tau, current);
  const auto k3 =
      kv::state_derivative(model, ref, kv::detail::advance(x0, k2, 0.5 * dt), tau, current);
  const auto x4 = kv::detail::advance(x0, k3, dt);
  kv::state_derivative(model, ref, x4, tau, current);
  CHECK((ws.nu_dot - ref.nu_dot).norm() == 0.0);
  CHECK((ws.restoring - ref.restoring).norm() == 0.0);
  CHECK((ws.rotation - x4.rotation()).norm() < 1e-15);
  // ... which is not the committed state's: a caller who wants those calls forward_dynamics.
  kv::VehicleWorkspace<double> committed;
  kv::forward_dynamics(model, committed, x, tau, zero, current);
  CHECK((committed.nu_dot - ws.nu_dot).norm() > 1e-6);
  CHECK((committed.rotation - x.rotation()).norm() < 1e-15);

  // Semi-implicit Euler: the state at the start of the step.
  kv::VehicleState<double> y = x0;
  kv::step_symplectic_euler(model, ws, y, {tau, zero}, dt, current);
  kv::forward_dynamics(model, ref, x0, tau, zero, current);
  CHECK((ws.nu_dot - ref.nu_dot).norm() == 0.0);
  CHECK((ws.damping - ref.damping).norm() == 0.0);
}
