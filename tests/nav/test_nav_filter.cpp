// kelp::nav's filter on a known trajectory (a level circle at constant speed and depth): from
// wrong initial position, velocity and heading it converges with the aiding sensors, late
// position fixes included, and stays bounded; its settings are checked; updates before
// initialize() are ignored and a non-finite measurement or IMU sample is refused, the filter
// unchanged.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "kelp/nav/filter.hpp"
#include "kelp/nav/sensors.hpp"

namespace kn = kelp::nav;
using V3 = kelp::Vector3<double>;

namespace {

// A level circle of radius u / r at depth 5 m, starting at the origin heading north.
struct Circle {
  double u = 1.0, r = 0.1, z = 5.0;
  kelp::vehicle::VehicleStated at(double t) const {
    kelp::vehicle::VehicleStated x;
    const double psi = r * t, R = u / r;
    x.position = V3(R * std::sin(psi), R * (1 - std::cos(psi)), z);
    x.attitude = kelp::quaternion_from_euler(0.0, 0.0, psi);
    x.nu << u, 0, 0, 0, 0, r;
    x.time = t;
    return x;
  }
};

struct Run {
  double rms_late = 0, max_late = 0, velocity_late = 0, heading_late = 0;
};

// 120 s at 100 Hz: IMU, depth, bottom-lock DVL, compass and USBL-like fixes 0.5 s late at 1 Hz
// (σ 0.3 m); the filter starts 3 m and 0.5 m/s off with a 10° heading error.
Run fly(bool with_dvl) {
  const Circle c;
  kn::ImuParameters ip;
  kn::ImuSensor imu(ip, 3, 0);
  kn::DepthSensor depth(kn::DepthParameters{}, 3, 2);
  kn::Dvl dvl(kn::DvlParameters{}, 3, 3);
  kn::Compass compass(kn::CompassParameters{}, 3, 4);
  kelp::nav::RandomStream fixes(3, 9);
  kn::FilterSettings fs;
  fs.initial_position_sigma = 3.0;
  fs.initial_velocity_sigma = 0.5;
  kn::NavigationFilter f(ip, fs);
  const kelp::Vector6<double> nu_dot = kelp::Vector6<double>::Zero();
  const double g = kelp::standard_gravity;
  {
    const auto x = c.at(0);
    kn::ImuSample s = imu.measure(x.nu.tail<3>(), kn::specific_force(x, nu_dot, g), 0.0);
    f.initialize(x.position + V3(2.0, -2.0, 1.0), V3(0.5, 0.0, 0.0), 10 * kn::degree, s);
  }
  Run out;
  long n = 0;
  for (int k = 1; k <= 12000; ++k) {
    const double t = k * 0.01;
    const auto x = c.at(t);
    kn::ImuSample s;
    REQUIRE(imu.sample(x, nu_dot, g, t, s));
    f.predict(s);
    double z, psi;
    if (depth.sample(x.position.z(), t, z)) f.update_depth(z, 0.002);
    if (compass.sample(x.attitude, t, psi)) f.update_heading(psi, 0.02);
    kelp::environment::Environmentd env;
    env.set_seabed_depth(20.0);
    kn::DvlSample d;
    if (with_dvl && dvl.sample(x, env, t, d) && d.mode == kn::DvlMode::bottom)
      f.update_body_velocity(d.velocity, d.sigma);
    if (k % 100 == 50 && t > 1.0) {  // measured 0.5 s ago
      const auto then = c.at(t - 0.5);
      V3 p = then.position;
      for (int i = 0; i < 3; ++i) p(i) += 0.3 * fixes.normal();
      f.update_position(p, V3::Constant(0.3), t - 0.5);
    }
    if (t > 60.0) {
      const auto& nav = f.navigation();
      const double e = (nav.position - x.position).norm();
      out.rms_late += e * e;
      out.max_late = std::max(out.max_late, e);
      out.velocity_late = std::max(out.velocity_late, (nav.nu.head<3>() - x.nu.head<3>()).norm());
      out.heading_late =
          std::max(out.heading_late, std::abs(kelp::wrap_angle(kelp::heading_of(nav.attitude) -
                                                               kelp::heading_of(x.attitude))));
      ++n;
    }
  }
  out.rms_late = std::sqrt(out.rms_late / n);
  return out;
}

}  // namespace

TEST_CASE("the filter converges from a wrong start and stays bounded on a circle",
          "[nav][filter]") {
  const Run with = fly(true);
  INFO("with DVL: rms " << with.rms_late << " m, max " << with.max_late << " m, velocity "
                        << with.velocity_late << " m/s, heading " << with.heading_late << " rad");
  // Fixes of σ 0.3 m once a second, a DVL at 5 Hz: the estimate settles well inside the fixes'
  // own scatter.
  CHECK(with.rms_late < 0.2);
  CHECK(with.max_late < 0.5);
  CHECK(with.velocity_late < 0.1);
  CHECK(with.heading_late < 1.0 * kn::degree);
  // Without the DVL (IMU and fixes only) it still converges, less tightly.
  const Run without = fly(false);
  INFO("without: rms " << without.rms_late << " m, velocity " << without.velocity_late << " m/s");
  CHECK(without.rms_late < 0.5);
  CHECK(without.velocity_late < 0.3);
}

TEST_CASE("a late fix is compared with the estimate of its time", "[nav][filter]") {
  kn::ImuParameters ip;
  kn::NavigationFilter f(ip);
  kn::ImuSample s;
  s.accel = V3(0, 0, -kelp::standard_gravity);
  f.initialize(V3::Zero(), V3(1.0, 0.0, 0.0), 0.0, s);
  for (int k = 1; k <= 200; ++k) {  // 2 s north at 1 m/s, no noise
    s.t = k * 0.01;
    f.predict(s);
  }
  CHECK(f.navigation().position.x() == Approx(2.0));
  CHECK(f.position_at(0.5).x() == Approx(0.5));
  // A fix that agrees with where the vehicle was 1.5 s ago changes nothing.
  f.update_position(V3(0.5, 0.0, 0.0), V3::Constant(0.1), 0.5);
  CHECK(f.navigation().position.x() == Approx(2.0).margin(1e-9));
  // One 1 m east of it moves the estimate (now and then) east.
  f.update_position(V3(0.5, 1.0, 0.0), V3::Constant(0.1), 0.5);
  CHECK(f.navigation().position.y() > 0.3);
  CHECK(f.position_at(0.5).y() == Approx(f.navigation().position.y()));
}

TEST_CASE("filter settings are checked", "[nav][filter][errors]") {
  kn::FilterSettings s;
  s.history = 0;
  CHECK_THROWS_WITH(kn::NavigationFilter(kn::ImuParameters{}, s), Catch::Contains("history"));
  s = {};
  s.initial_position_sigma = -1;
  CHECK_THROWS_WITH(kn::validate(s), Catch::Contains("initial_position_sigma"));
  kn::NavigationFilter f(kn::ImuParameters{});
  CHECK_THROWS_AS(f.predict(kn::ImuSample{}), kelp::invalid_argument);  // not initialised
}

TEST_CASE("Navigation filter in float follows the double one on the same samples",
          "[nav][filter][float]") {
  const Circle c;
  kn::ImuParameters ip;
  kn::ImuSensor imu(ip, 5, 0);
  kn::DepthSensor depth(kn::DepthParameters{}, 5, 2);
  kn::Compass compass(kn::CompassParameters{}, 5, 4);
  kn::NavigationFilter f(ip);
  kn::NavigationFilterT<float> ff(ip);
  const kelp::Vector6<double> nu_dot = kelp::Vector6<double>::Zero();
  const double g = kelp::standard_gravity;
  {
    const auto x = c.at(0);
    const kn::ImuSample s = imu.measure(x.nu.tail<3>(), kn::specific_force(x, nu_dot, g), 0.0);
    f.initialize(x.position + V3(1.0, -1.0, 0.5), V3(0.8, 0.0, 0.0), 0.0, s);
    ff.initialize((x.position + V3(1.0, -1.0, 0.5)).cast<float>(), kelp::Vector3<float>(0.8f, 0, 0),
                  0.0, s);
  }
  double worst = 0;
  for (int k = 1; k <= 3000; ++k) {
    const double t = k * 0.01;
    const auto x = c.at(t);
    kn::ImuSample s;
    REQUIRE(imu.sample(x, nu_dot, g, t, s));
    f.predict(s);
    ff.predict(s);
    double z, psi;
    if (depth.sample(x.position.z(), t, z)) {
      f.update_depth(z, 0.002);
      ff.update_depth(z, 0.002);
    }
    if (compass.sample(x.attitude, t, psi)) {
      f.update_heading(psi, 0.02);
      ff.update_heading(psi, 0.02);
    }
    if (k % 100 == 0) {
      f.update_position(x.position, V3::Constant(0.3), t);
      ff.update_position(x.position.cast<float>(), kelp::Vector3<float>::Constant(0.3f), t);
      f.update_horizontal_position(x.position.head<2>(), 0.5, t);
      ff.update_horizontal_position(x.position.head<2>().cast<float>(), 0.5, t);
    }
    worst = std::max(
        worst,
        (ff.navigation().position.cast<double>() - f.navigation().position).cwiseAbs().maxCoeff());
  }
  CHECK(worst < 0.01);  // [m]: float rounding over 30 s, not a different filter
  CHECK((f.navigation().position - c.at(30.0).position).norm() < 1.0);  // both converged
  CHECK((ff.navigation().position.cast<double>() - c.at(30.0).position).norm() < 1.0);
  CHECK(ff.covariance().diagonal().minCoeff() >= 0.0f);
  CHECK(std::abs(kelp::wrap_angle(kelp::heading_of(ff.navigation().attitude) - 3.0)) < 0.05);
}

TEST_CASE("before initialize() every update is ignored, the heading's too", "[nav][filter]") {
  kn::NavigationFilter f(kn::ImuParameters{});
  f.update_heading(1.0, 1.0);
  f.update_depth(3.0, 0.1);
  f.update_position(V3(1.0, 2.0, 3.0), V3::Constant(0.1), 0.0);
  CHECK_FALSE(f.initialized());
  CHECK(f.gyro_bias() == V3::Zero());
  CHECK(f.navigation().attitude.coeffs() == kelp::Quaternion<double>::Identity().coeffs());
  CHECK(f.state() == kn::NavigationFilter::StateVector::Zero());
}

TEST_CASE("every update refuses a non-finite measurement, σ or time and changes nothing",
          "[nav][filter][errors]") {
  kn::FilterSettings fs;
  fs.estimate_current = true;  // so that update_water_velocity acts
  kn::NavigationFilter f(kn::ImuParameters{}, fs);
  kn::ImuSample s;
  s.accel = V3(0, 0, -kelp::standard_gravity);
  f.initialize(V3(1.0, 2.0, 3.0), V3(0.5, 0.0, 0.0), 0.3, s);
  s.t = 0.01;
  f.predict(s);
  const kn::NavigationFilter::StateVector x = f.state();
  const kn::NavigationFilter::Covariance P = f.covariance();
  const kelp::Quaternion<double> q = f.navigation().attitude;
  const V3 bias = f.gyro_bias();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d ne(1.0, 2.0);
  CHECK_THROWS_AS(f.update_depth(nan, 0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_depth(3.0, nan), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_depth(3.0, -0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_body_velocity(V3(nan, 0, 0), 0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_body_velocity(V3::Zero(), inf), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_water_velocity(V3(0, inf, 0), 0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_water_velocity(V3::Zero(), nan), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_heading(nan, 0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_heading(0.1, nan), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_heading(0.1, inf), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_heading(0.1, -0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_horizontal_position(Eigen::Vector2d(nan, 2.0), 0.1, 0.0),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_horizontal_position(ne, nan, 0.0), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_horizontal_position(ne, 0.1, nan), kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_position(V3(1.0, nan, 3.0), V3::Constant(0.1), 0.0),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_position(V3(1.0, 2.0, 3.0), V3(0.1, 0.1, nan), 0.0),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(f.update_position(V3(1.0, 2.0, 3.0), V3::Constant(0.1), nan),
                  kelp::invalid_argument);
  CHECK_THROWS_WITH(f.update_heading(nan, 0.1), Catch::Contains("update_heading: psi"));
  // Nothing moved: bit for bit.
  CHECK(f.state() == x);
  CHECK(f.covariance() == P);
  CHECK(f.navigation().attitude.coeffs() == q.coeffs());
  CHECK(f.gyro_bias() == bias);
  // The same updates with finite values act.
  f.update_depth(3.5, 0.1);
  CHECK(f.state() != x);
}

TEST_CASE(
    "predict and initialize refuse a non-finite IMU sample or time, predict one earlier "
    "than the last, and change nothing",
    "[nav][filter][errors]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  kn::ImuSample s;
  s.accel = V3(0.3, -0.2, -kelp::standard_gravity);
  s.gyro = V3(0.01, -0.02, 0.05);
  // `f` is offered the bad samples; `twin` gets only the good ones.
  kn::NavigationFilter f(kn::ImuParameters{}), twin(kn::ImuParameters{});
  f.initialize(V3(1.0, 2.0, 3.0), V3(0.5, 0.0, 0.0), 0.3, s);
  twin.initialize(V3(1.0, 2.0, 3.0), V3(0.5, 0.0, 0.0), 0.3, s);
  s.t = 0.01;
  f.predict(s);
  twin.predict(s);
  const kn::NavigationFilter::StateVector x = f.state();
  const kn::NavigationFilter::Covariance P = f.covariance();
  const kelp::Quaternion<double> q = f.navigation().attitude;
  const kelp::Vector6<double> nu = f.navigation().nu;
  const V3 bias = f.gyro_bias();
  // A bad time, later than the last sample or not, and bad components with a good time, a
  // time of the last sample's (dt = 0: it would only set the body rate) included.
  for (const double t : {nan, inf, -inf}) {
    kn::ImuSample m = s;
    m.t = t;
    INFO("t " << t);
    CHECK_THROWS_AS(f.predict(m), kelp::invalid_argument);
  }
  for (const double t : {0.01, 0.02}) {
    for (int i = 0; i < 3; ++i) {
      INFO("t " << t << ", component " << i);
      kn::ImuSample m = s;
      m.t = t;
      m.gyro(i) = nan;
      CHECK_THROWS_AS(f.predict(m), kelp::invalid_argument);
      m = s;
      m.t = t;
      m.accel(i) = i == 1 ? -inf : nan;
      CHECK_THROWS_AS(f.predict(m), kelp::invalid_argument);
    }
  }
  // A sample earlier than the last (good in every component): it would set the clock back and
  // the next sample would integrate the span between them twice.
  for (const double t : {0.0099, 0.0, -1.0}) {
    kn::ImuSample m = s;
    m.t = t;
    INFO("t " << t);
    CHECK_THROWS_AS(f.predict(m), kelp::invalid_argument);
  }
  kn::ImuSample bad = s;
  bad.t = 0.005;
  CHECK_THROWS_WITH(f.predict(bad), Catch::Contains("earlier than the last sample"));
  bad.t = nan;
  CHECK_THROWS_WITH(f.predict(bad), Catch::Contains("predict: m.t"));
  bad = s;
  bad.gyro.x() = nan;
  CHECK_THROWS_WITH(f.predict(bad), Catch::Contains("predict: m.gyro"));
  // initialize() takes its clock and attitude from an IMU sample too: a bad one is refused the
  // same way, the running filter kept.
  bad = s;
  bad.t = nan;
  CHECK_THROWS_AS(f.initialize(V3::Zero(), V3::Zero(), 0.0, bad), kelp::invalid_argument);
  bad = s;
  bad.accel.z() = inf;
  CHECK_THROWS_AS(f.initialize(V3::Zero(), V3::Zero(), 0.0, bad), kelp::invalid_argument);
  bad = s;
  bad.gyro.y() = nan;
  CHECK_THROWS_AS(f.initialize(V3::Zero(), V3::Zero(), 0.0, bad), kelp::invalid_argument);
  // Nothing moved: bit for bit.
  CHECK(f.state() == x);
  CHECK(f.covariance() == P);
  CHECK(f.navigation().attitude.coeffs() == q.coeffs());
  CHECK(f.navigation().nu == nu);
  CHECK(f.gyro_bias() == bias);
  // The clock and body rate too: the next good sample gives what it gives the twin.
  s.t = 0.02;
  f.predict(s);
  twin.predict(s);
  CHECK(f.state() != x);
  CHECK(f.state() == twin.state());
  CHECK(f.covariance() == twin.covariance());
  CHECK(f.navigation().attitude.coeffs() == twin.navigation().attitude.coeffs());
  CHECK(f.navigation().nu == twin.navigation().nu);
  CHECK(f.position_at(0.015) == twin.position_at(0.015));
}
