// Hull contact (kelp/system/hull_contact.hpp): a vehicle resting on the seabed (flat, a flat
// height field, a sloped height field) carries its weight in water W − B on the contact; sliding
// on the seabed it decelerates at μ (W − B) / (m + X_u̇); driven into a pile it stops at its
// surface with the contact force equal to the thrust; and system::step applies the hull's contact
// (the ROV rests on the seabed only with SystemParameters::auv_hull).
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/system/hull_contact.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/system.hpp"
#include "kelp/vehicle/presets.hpp"

namespace ke = kelp::environment;
namespace ks = kelp::system;
namespace kv = kelp::vehicle;
using V3 = kelp::Vector3<double>;

namespace {

constexpr double kDt = 0.01;

// The BlueROV2 Heavy ballasted to 15 kg (the preset is 2.3 N buoyant in seawater and would not
// rest on the seabed): W − B = (15 − ρ∇) g ≈ 12.4 N.
kv::VehicleParametersd ballasted_rov(double mass = 15.0) {
  kv::VehicleParametersd p = kv::bluerov2_heavy<double>().parameters;
  p.mass = mass;
  return p;
}

double weight_in_water(const kv::VehicleParametersd& p) {
  return (p.mass - p.density * p.displaced_volume) * p.gravity;
}

// Steps one vehicle alone by the system's own stage function (detail::step_vehicle) with its
// hull, no tether force, for `seconds`.
void run(const kv::VehicleModeld& model, kv::VehicleWorkspaced& ws, kv::VehicleStated& x,
         const ke::Environmentd& env, const ks::HullContactd& hull, double seconds,
         const kelp::Vector6<double>& tau = kelp::Vector6<double>::Zero()) {
  kv::VehicleInputs<double> in;
  in.tau = tau;
  const long n = std::lround(seconds / kDt);
  for (long k = 0; k < n; ++k) {
    ks::detail::step_vehicle(model, ws, x, env, x.time, kDt, in, V3(V3::Zero()), V3(V3::Zero()),
                             &hull);
    x.time += kDt;
  }
}

// A height field of 3 × 3 nodes 20 m apart around the origin with depth h0 + s·north.
ke::HeightField sloped_field(double h0, double slope) {
  ke::HeightField f;
  f.origin = Eigen::Vector2d(-20, -20);
  f.spacing = Eigen::Vector2d(20, 20);
  f.rows = 3;
  f.cols = 3;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f.depth.push_back(h0 + slope * (-20.0 + 20.0 * i));
  return f;
}

}  // namespace

TEST_CASE("hull contact: a vehicle resting on the seabed carries its weight in water",
          "[system][contact]") {
  const kv::VehicleParametersd p = ballasted_rov();
  const kv::VehicleModeld model(p);
  kv::VehicleWorkspaced ws;
  const ks::HullContactd hull = ks::bluerov2_heavy_hull<double>();
  const double wb = weight_in_water(p);
  REQUIRE(wb > 10.0);
  ke::Environmentd env;
  double slope = 0;
  SECTION("flat seabed") { env.set_seabed_depth(10.0); }
  SECTION("flat height field") {
    ke::ObstacleSet set;
    set.set_seabed(sloped_field(10.0, 0.0));
    env.set_obstacles(set);
  }
  SECTION("height field sloping 10 degrees, held by friction") {
    slope = std::tan(10.0 * kelp::pi / 180.0);
    ke::ObstacleSet set;
    set.set_seabed(sloped_field(10.0, slope));
    env.set_obstacles(set);
  }
  kv::VehicleStated x;
  // The hull's bottom 2 cm above the seabed under the CO.
  x.position = V3(0, 0, 10.0 - hull.half_extents.z() - 0.02 - 0.3 * slope);
  run(model, ws, x, env, hull, 20.0);
  const ks::HullContactLoad<double> load = ks::hull_contact(hull, env, x);
  INFO("contact force " << load.force.transpose() << " N, W - B " << wb << " N, points "
                        << load.points << ", speed " << x.nu.head<3>().norm());
  CHECK(load.points >= 3);
  // Vertical: the contact carries W − B (within 1 %); horizontal: nothing else pushes it.
  CHECK(std::abs(-load.force.z() - wb) < 0.01 * wb);
  // On the slope too: friction holds the ROV (μ = 0.5 > tan 10°), creeping below the friction
  // velocity.
  CHECK(load.force.head<2>().norm() < 0.01 * wb);
  CHECK(x.nu.head<3>().norm() < hull.friction_velocity);
}

TEST_CASE("hull contact: without the hull the ballasted ROV sinks through the seabed",
          "[system][contact]") {
  const kv::VehicleModeld model(ballasted_rov());
  kv::VehicleWorkspaced ws;
  ke::Environmentd env;
  env.set_seabed_depth(10.0);
  kv::VehicleStated x;
  x.position = V3(0, 0, 9.85);
  kv::VehicleInputs<double> in;
  for (int k = 0; k < 500; ++k) {
    ks::detail::step_vehicle(model, ws, x, env, x.time, kDt, in, V3(V3::Zero()), V3(V3::Zero()));
    x.time += kDt;
  }
  CHECK(x.position.z() > 10.2);
}

TEST_CASE("hull contact: sliding friction decelerates at mu (W - B) / (m + X_udot)",
          "[system][contact]") {
  // Hydrodynamic damping off, so that friction alone decelerates the vehicle.
  kv::VehicleParametersd p = ballasted_rov();
  p.damping.linear.setZero();
  p.damping.quadratic.setZero();
  const kv::VehicleModeld model(p);
  kv::VehicleWorkspaced ws;
  ks::HullContactd hull = ks::bluerov2_heavy_hull<double>();
  const double mu = GENERATE(0.2, 0.5);
  hull.seabed_friction = mu;
  ke::Environmentd env;
  env.set_seabed_depth(10.0);
  kv::VehicleStated x;
  x.position = V3(0, 0, 10.0 - hull.half_extents.z() - 0.001);
  run(model, ws, x, env, hull, 3.0);  // settle
  // Expected: (m + X_u̇) u̇ = −μ (W − B): the surge added mass moves with the hull; the normal
  // force is W − B (vertical balance), so g' = (W − B) / (m + X_u̇).
  const double g_prime = weight_in_water(p) / (p.mass + p.added_mass(0, 0));
  const double expected = mu * g_prime;
  x.nu(0) = 0.6;
  run(model, ws, x, env, hull, 0.5);  // the sliding contact settles
  const double u0 = x.nu(0);
  const double t = 0.4 * (u0 - 0.05) / expected;  // stay above the friction velocity
  run(model, ws, x, env, hull, t);
  const double measured = (u0 - x.nu(0)) / t;
  INFO("mu " << mu << ": deceleration " << measured << " m/s^2, expected " << expected);
  CHECK(std::abs(measured - expected) < 0.01 * expected);
  CHECK(std::abs(x.nu(1)) < 1e-6);
}

TEST_CASE("hull contact: a ROV pushed into a pile stops at its surface", "[system][contact]") {
  const kv::VehicleParametersd p0 = kv::bluerov2_heavy<double>().parameters;
  kv::VehicleParametersd p = p0;
  p.mass = p.density * p.displaced_volume;  // neutral
  const kv::VehicleModeld model(p);
  kv::VehicleWorkspaced ws;
  const ks::HullContactd hull = ks::bluerov2_heavy_hull<double>();
  ke::Cylinder pile;
  pile.name = "pile";
  pile.from = V3(2.0, 0.05, 20.0);
  pile.to = V3(2.0, 0.05, -1.0);
  pile.radius = 0.3;
  ke::ObstacleSet set;
  set.add(pile);
  ke::Environmentd env;
  env.set_obstacles(set);
  kv::VehicleStated x;
  x.position = V3(0, 0, 5);
  kelp::Vector6<double> tau = kelp::Vector6<double>::Zero();
  tau(0) = 20.0;
  run(model, ws, x, env, hull, 15.0, tau);
  const ks::HullContactLoad<double> load = ks::hull_contact(hull, env, x);
  INFO("front at " << x.position.x() + hull.half_extents.x() << " m, contact "
                   << load.force.transpose());
  // Its front face rests on the pile's surface (penetration 20 N / 2e4 N/m = 1 mm) and the
  // contact pushes back with the thrust.
  CHECK(std::abs(x.position.x() + hull.half_extents.x() - (2.0 - 0.3)) < 0.005);
  CHECK(std::abs(load.force.x() + 20.0) < 0.2);
  CHECK(std::abs(x.nu(0)) < 1e-3);
}

TEST_CASE("hull contact in system::step: the ROV rests on the seabed only with its hull",
          "[system][contact]") {
  namespace sp = ks::presets;
  ks::SystemParametersd params = sp::paper_system(10.0);
  params.auv.mass = 15.0;
  const bool with_hull = GENERATE(true, false);
  if (with_hull) params.auv_hull = ks::bluerov2_heavy_hull<double>();
  const sp::StartPoses<double> start = sp::paper_start(10.0);
  const double bed = start.auv.position.z() + 0.127 + 0.005;
  ke::Environmentd env;
  env.set_seabed_depth(bed);
  const ks::SystemModeld model(params, env);
  ks::SystemWorkspaced ws(model);
  ks::SystemStated state = ks::initial_state(model, ws, start.asv, start.auv);
  ks::SystemInputsd in;
  ks::SystemReportd r;
  for (int k = 0; k < 800; ++k) r = ks::step(model, ws, state, in, kDt);
  const double wb = weight_in_water(params.auv);
  if (with_hull) {
    // Vertical balance of the resting ROV: contact + tether + (W − B) = 0, within 1 % of W − B.
    INFO("contact " << r.auv_contact.force.transpose() << " tether " << r.force_on_auv.transpose());
    CHECK(std::abs(r.auv_contact.force.z() + r.force_on_auv.z() + wb) < 0.01 * wb);
    CHECK(state.auv.position.z() + 0.127 < bed + 0.002);
    CHECK(r.asv_contact.points == 0);
  } else {
    CHECK(state.auv.position.z() + 0.127 > bed + 0.1);
    CHECK(r.auv_contact.points == 0);
  }
}

TEST_CASE("hull contact: float gives the double's resting force", "[system][contact]") {
  ke::Environmentf envf;
  envf.set_seabed_depth(10.0f);
  ke::Environmentd envd;
  envd.set_seabed_depth(10.0);
  kv::VehicleStatef xf;
  xf.position = kelp::Vector3<float>(0, 0, 10.0f - 0.127f + 0.005f);
  kv::VehicleStated xd;
  xd.position = V3(0, 0, 10.0 - 0.127 + 0.005);
  const auto lf = ks::hull_contact(ks::bluerov2_heavy_hull<float>(), envf, xf);
  const auto ld = ks::hull_contact(ks::bluerov2_heavy_hull<double>(), envd, xd);
  CHECK(lf.points == 4);
  CHECK(ld.points == 4);
  // 4 corners 5 mm deep: 4 k p = 400 N up.
  CHECK(ld.force.z() == Approx(-400.0).epsilon(1e-4));
  CHECK(double(lf.force.z()) == Approx(ld.force.z()).epsilon(1e-3));
}
