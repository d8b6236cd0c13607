// kelp::nav sensors: each one's noise statistics within 10 % of its parameters over a long run
// (white noise σ, bias random-walk growth, Gauss–Markov σ and correlation, USBL noise against
// range, dropout rate, latency), the DVL's bottom lock and water track by altitude, the same
// numbers for the same seed and others for another, and bad parameters refused.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "kelp/control/controllers.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/nav/random.hpp"
#include "kelp/nav/sensors.hpp"

namespace kn = kelp::nav;
using V3 = kelp::Vector3<double>;

namespace {

struct Stats {
  double n = 0, sum = 0, sum2 = 0;
  void add(double x) {
    n += 1;
    sum += x;
    sum2 += x * x;
  }
  double mean() const { return sum / n; }
  double sd() const { return std::sqrt(sum2 / n - mean() * mean()); }
};

kelp::vehicle::VehicleStated moving(double u, double v, double w, double z) {
  kelp::vehicle::VehicleStated x;
  x.position = V3(0, 0, z);
  x.attitude = kelp::quaternion_from_euler(0.1, -0.05, 0.7);
  x.nu << u, v, w, 0, 0, 0;
  return x;
}

}  // namespace

TEST_CASE("normal deviates: mean 0, variance 1, and the same for the same seed", "[nav][random]") {
  kn::RandomStream a(42, 3), b(42, 3), c(43, 3), d(42, 4);
  Stats s;
  bool differ_seed = false, differ_stream = false;
  for (int i = 0; i < 200000; ++i) {
    const double x = a.normal();
    REQUIRE(x == b.normal());
    differ_seed = differ_seed || x != c.normal();
    differ_stream = differ_stream || x != d.normal();
    s.add(x);
  }
  CHECK(std::abs(s.mean()) < 0.01);
  CHECK(s.sd() == Approx(1.0).epsilon(0.01));
  CHECK(differ_seed);
  CHECK(differ_stream);
  // std::mt19937_64 is fixed by the standard, so is the first uniform of a seed's stream.
  kn::RandomStream e(1, 0), f(1, 0);
  CHECK(e.uniform() == f.uniform());
}

TEST_CASE("IMU white noise: σ = density · √rate on every axis", "[nav][imu]") {
  kn::ImuParameters p;
  p.gyro_bias_walk = 0;
  p.accel_bias_walk = 0;
  kn::ImuSensor imu(p, 7, 0);
  Stats g[3], a[3];
  const V3 omega(0.1, -0.2, 0.3), force(0.5, 0.0, -9.8);
  for (int k = 0; k < 30000; ++k) {
    const kn::ImuSample s = imu.measure(omega, force, k * 0.01);
    for (int i = 0; i < 3; ++i) {
      g[i].add(s.gyro(i) - omega(i));
      a[i].add(s.accel(i) - force(i));
    }
  }
  for (int i = 0; i < 3; ++i) {
    CHECK(g[i].sd() == Approx(p.gyro_noise_density * std::sqrt(p.rate)).epsilon(0.1));
    CHECK(a[i].sd() == Approx(p.accel_noise_density * std::sqrt(p.rate)).epsilon(0.1));
    CHECK(std::abs(g[i].mean()) < 0.05 * g[i].sd());
  }
}

TEST_CASE("IMU bias random walk: the variance of its change grows as walk² · time", "[nav][imu]") {
  kn::ImuParameters p;
  p.gyro_noise_density = 0;
  p.accel_noise_density = 0;
  kn::ImuSensor imu(p, 11, 0);
  const int lag = 100;  // 1 s at 100 Hz
  Stats dg, da;
  V3 g0 = imu.gyro_bias(), a0 = imu.accel_bias();
  for (int k = 1; k <= 300000; ++k) {
    imu.measure(V3::Zero(), V3::Zero(), k * 0.01);
    if (k % lag == 0) {
      for (int i = 0; i < 3; ++i) {
        dg.add(imu.gyro_bias()(i) - g0(i));
        da.add(imu.accel_bias()(i) - a0(i));
      }
      g0 = imu.gyro_bias();
      a0 = imu.accel_bias();
    }
  }
  const double T = lag / p.rate;
  CHECK(dg.sd() == Approx(p.gyro_bias_walk * std::sqrt(T)).epsilon(0.1));
  CHECK(da.sd() == Approx(p.accel_bias_walk * std::sqrt(T)).epsilon(0.1));
}

TEST_CASE("IMU: an ideal accelerometer reads the specific force", "[nav][imu]") {
  kelp::vehicle::VehicleStated x;
  kelp::Vector6<double> nu_dot = kelp::Vector6<double>::Zero();
  // At rest and level: −g along body z (the accelerometer feels the support, upwards).
  CHECK(kn::specific_force(x, nu_dot, 9.81).isApprox(V3(0, 0, -9.81)));
  // Turning at r with surge u: the centripetal acceleration u r to starboard.
  x.nu << 2.0, 0, 0, 0, 0, 0.1;
  CHECK(kn::specific_force(x, nu_dot, 9.81).isApprox(V3(0, 0.2, -9.81)));
  // Pitched nose up by 90°: the support pushes along body +x.
  x.nu.setZero();
  x.attitude = kelp::quaternion_from_euler(0.0, kelp::pi / 2, 0.0);
  CHECK(kn::specific_force(x, nu_dot, 9.81).x() == Approx(9.81));
}

TEST_CASE("depth and compass: σ and bias as given", "[nav][depth][compass]") {
  kn::DepthParameters dp;
  dp.bias = 0.3;
  kn::DepthSensor depth(dp, 3, 2);
  kn::CompassParameters cp;
  kn::Compass compass(cp, 3, 4);
  Stats d, c;
  for (int k = 0; k < 20000; ++k) {
    d.add(depth.measure(5.0) - 5.0);
    c.add(kelp::control::wrap_angle(compass.measure(3.1) - 3.1));
  }
  CHECK(d.sd() == Approx(dp.noise).epsilon(0.1));
  CHECK(d.mean() == Approx(0.3).margin(0.001));
  CHECK(c.sd() == Approx(cp.noise).epsilon(0.1));
}

TEST_CASE("DVL: bottom lock within its altitude range, else water track or no fix", "[nav][dvl]") {
  kn::DvlParameters p;
  kn::Dvl dvl(p, 5, 3);
  CHECK(dvl.mode_at(0.01) == kn::DvlMode::water);
  CHECK(dvl.mode_at(0.05) == kn::DvlMode::bottom);
  CHECK(dvl.mode_at(20.0) == kn::DvlMode::bottom);
  CHECK(dvl.mode_at(50.0) == kn::DvlMode::bottom);
  CHECK(dvl.mode_at(50.5) == kn::DvlMode::water);
  CHECK(dvl.mode_at(std::numeric_limits<double>::infinity()) == kn::DvlMode::water);
  kn::DvlParameters off = p;
  off.water_track = false;
  CHECK(kn::Dvl(off, 5, 3).mode_at(80.0) == kn::DvlMode::none);

  // Through the environment: a seabed at 30 m and a current of 0.5 m/s east.
  kelp::environment::Environmentd env;
  env.set_current(V3(0.0, 0.5, 0.0));
  const auto x = moving(1.0, 0.2, 0.0, 5.0);
  kn::DvlParameters quiet = p;
  quiet.noise_floor = quiet.noise_fraction = quiet.water_noise = 0;
  env.set_seabed_depth(30.0);
  kn::Dvl a(quiet, 1, 3);
  kn::DvlSample s;
  REQUIRE(a.sample(x, env, 0.0, s));
  CHECK(s.mode == kn::DvlMode::bottom);
  CHECK(s.altitude == Approx(25.0));
  CHECK(s.velocity.isApprox(V3(1.0, 0.2, 0.0)));  // over ground
  // The next bottom-lock ping is due one bottom-lock period later.
  CHECK_FALSE(a.sample(x, env, 0.1, s));
  CHECK(a.sample(x, env, 1.0 / p.bottom_rate, s));
  env.set_seabed_depth(100.0);  // 95 m below: out of range, water track
  kn::Dvl b(quiet, 1, 3);
  REQUIRE(b.sample(x, env, 0.0, s));
  CHECK(s.mode == kn::DvlMode::water);
  const V3 expected = V3(1.0, 0.2, 0.0) - x.attitude.conjugate() * V3(0.0, 0.5, 0.0);
  CHECK(s.velocity.isApprox(expected));                   // relative to the water
  CHECK_FALSE(b.sample(x, env, 1.0 / p.bottom_rate, s));  // water track pings at 2 Hz
  CHECK(b.sample(x, env, 1.0 / p.water_rate, s));
}

TEST_CASE("DVL noise: σ = floor + fraction · speed in bottom lock, water_noise in water track",
          "[nav][dvl]") {
  kn::DvlParameters p;
  kn::Dvl dvl(p, 9, 3);
  const auto x = moving(1.0, 0.0, 0.0, 5.0);
  Stats b, w;
  for (int k = 0; k < 20000; ++k) {
    const kn::DvlSample s = dvl.measure(x, kn::DvlMode::bottom, V3::Zero(), 0.0);
    const kn::DvlSample t = dvl.measure(x, kn::DvlMode::water, V3::Zero(), 0.0);
    for (int i = 0; i < 3; ++i) {
      b.add(s.velocity(i) - x.nu(i));
      w.add(t.velocity(i) - x.nu(i));
    }
  }
  CHECK(b.sd() == Approx(p.noise_floor + p.noise_fraction * 1.0).epsilon(0.1));
  CHECK(w.sd() == Approx(p.water_noise).epsilon(0.1));
  CHECK(dvl.measure(x, kn::DvlMode::none, V3::Zero(), 0.0).mode == kn::DvlMode::none);
}

TEST_CASE("GPS: white noise σ, Gauss–Markov σ and correlation time, vertical factor",
          "[nav][gps]") {
  kn::GpsParameters w;
  w.bias_sigma = 0;
  kn::Gps white(w, 2, 6);
  Stats h, v;
  for (int k = 0; k < 20000; ++k) {
    const V3 f = white.measure(V3(1, 2, 0));
    h.add(f.x() - 1);
    h.add(f.y() - 2);
    v.add(f.z());
  }
  CHECK(h.sd() == Approx(w.noise).epsilon(0.1));
  CHECK(v.sd() == Approx(w.noise * w.vertical_factor).epsilon(0.1));

  kn::GpsParameters m;
  m.noise = 0;
  m.rate = 10;
  m.bias_time = 1.0;
  kn::Gps slow(m, 2, 6);
  Stats b;
  std::vector<double> x;
  for (int k = 0; k < 200000; ++k) {
    x.push_back(slow.measure(V3::Zero()).x());
    b.add(x.back());
  }
  CHECK(b.sd() == Approx(m.bias_sigma).epsilon(0.1));
  // Autocorrelation at one correlation time (10 samples): e^−1.
  double c = 0;
  for (std::size_t k = 10; k < x.size(); ++k) c += x[k] * x[k - 10];
  c /= static_cast<double>(x.size() - 10) * b.sd() * b.sd();
  CHECK(c == Approx(std::exp(-1.0)).epsilon(0.1));
}

TEST_CASE(
    "USBL: noise grows with slant range, fixes are lost at the dropout rate and arrive "
    "after the latency",
    "[nav][usbl]") {
  kn::UsblParameters p;
  p.dropout = 0;
  p.latency = 0;
  for (double range : {10.0, 60.0}) {
    kn::Usbl usbl(p, 4, 7);
    Stats e;
    const V3 boat(0, 0, 0), rov(0.6 * range, 0.0, 0.8 * range);
    kn::UsblFix f;
    for (int k = 0; k < 10000; ++k) {
      REQUIRE(usbl.sample(rov, boat, boat, 0.0, k));
      REQUIRE(usbl.poll(k, f));
      CHECK(f.range == Approx(range));
      for (int i = 0; i < 3; ++i) e.add(f.position(i) - rov(i));
    }
    CHECK(e.sd() == Approx(p.noise_floor + p.noise_fraction * range).epsilon(0.1));
  }
  // Beyond the maximum range: lost.
  {
    kn::Usbl usbl(p, 4, 7);
    usbl.sample(V3(0, 0, 150), V3::Zero(), V3::Zero(), 0.0, 0.0);
    kn::UsblFix f;
    CHECK_FALSE(usbl.poll(10.0, f));
    CHECK(usbl.dropouts() == 1);
  }
  // Dropout rate.
  kn::UsblParameters d = p;
  d.dropout = 0.3;
  kn::Usbl lossy(d, 8, 7);
  kn::UsblFix f;
  long got = 0;
  for (int k = 0; k < 20000; ++k) {
    lossy.sample(V3(0, 0, 10), V3::Zero(), V3::Zero(), 0.0, k);
    while (lossy.poll(k, f)) ++got;
  }
  CHECK(lossy.pings() == 20000);
  CHECK(static_cast<double>(lossy.dropouts()) / lossy.pings() == Approx(0.3).epsilon(0.1));
  CHECK(got + lossy.dropouts() == 20000);
  // Latency: measured at t, available at t + latency, not before; in order.
  kn::UsblParameters l = p;
  l.latency = 1.5;
  l.rate = 2.0;
  kn::Usbl late(l, 8, 7);
  REQUIRE(late.sample(V3(0, 0, 10), V3::Zero(), V3::Zero(), 0.0, 0.0));
  REQUIRE(late.sample(V3(0, 0, 10), V3::Zero(), V3::Zero(), 0.0, 0.5));
  CHECK_FALSE(late.poll(1.49, f));
  REQUIRE(late.poll(1.5, f));
  CHECK(f.measured_at == 0.0);
  CHECK(f.delivered_at == 1.5);
  CHECK_FALSE(late.poll(1.9, f));
  REQUIRE(late.poll(2.0, f));
  CHECK(f.measured_at == 0.5);
  // The boat's heading error turns the relative position: 90° puts a fix due north to the east.
  kn::UsblParameters exact = p;
  exact.noise_floor = exact.noise_fraction = 0;
  kn::Usbl turned(exact, 8, 7);
  turned.sample(V3(10, 0, 5), V3::Zero(), V3(1, 1, 0), kelp::pi / 2, 0.0);
  REQUIRE(turned.poll(0.0, f));
  CHECK(f.position.isApprox(V3(1, 11, 5)));
  // Never polled: the queue keeps its newest usbl_queue_capacity fixes, in order.
  kn::Usbl unread(p, 8, 7);
  const int n = kn::usbl_queue_capacity + 10;
  for (int k = 0; k < n; ++k) REQUIRE(unread.sample(V3(0, 0, 10), V3::Zero(), V3::Zero(), 0.0, k));
  int kept = 0;
  double first = -1, last = -1;
  while (unread.poll(1e9, f)) {
    if (kept++ == 0) first = f.measured_at;
    CHECK(f.measured_at > last);
    last = f.measured_at;
  }
  CHECK(kept == kn::usbl_queue_capacity);
  CHECK(first == n - kn::usbl_queue_capacity);
  CHECK(last == n - 1);
}

TEST_CASE("sensors: the same seed gives the same numbers, another seed others", "[nav]") {
  const auto run = [](std::uint64_t seed) {
    kn::ImuSensor imu(kn::ImuParameters{}, seed, 0);
    kn::Gps gps(kn::GpsParameters{}, seed, 6);
    std::vector<double> out;
    for (int k = 0; k < 100; ++k) {
      out.push_back(imu.measure(V3::Zero(), V3::Zero(), k * 0.01).accel.x());
      out.push_back(gps.measure(V3::Zero()).y());
    }
    return out;
  };
  CHECK(run(5) == run(5));
  CHECK(run(5) != run(6));
}

TEST_CASE("sensors refuse bad parameters, naming the field", "[nav][errors]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  kn::ImuParameters imu;
  imu.rate = 0;
  CHECK_THROWS_WITH(kn::ImuSensor(imu, 1, 0), Catch::Contains("imu.rate"));
  imu = {};
  imu.gyro_noise_density = -1;
  CHECK_THROWS_AS(kn::validate(imu), kelp::invalid_argument);
  kn::DepthParameters depth;
  depth.noise = nan;
  CHECK_THROWS_WITH(kn::validate(depth), Catch::Contains("depth.noise"));
  kn::DvlParameters dvl;
  dvl.max_altitude = 0.01;
  CHECK_THROWS_WITH(kn::validate(dvl), Catch::Contains("dvl.max_altitude"));
  kn::CompassParameters compass;
  compass.bias = nan;
  CHECK_THROWS_WITH(kn::validate(compass), Catch::Contains("compass.bias"));
  kn::GpsParameters gps;
  gps.bias_time = 0;
  CHECK_THROWS_WITH(kn::validate(gps), Catch::Contains("gps.bias_time"));
  kn::UsblParameters usbl;
  usbl.dropout = 1.0;
  CHECK_THROWS_WITH(kn::validate(usbl), Catch::Contains("usbl.dropout"));
  usbl = {};
  usbl.latency = 100;
  CHECK_THROWS_WITH(kn::validate(usbl), Catch::Contains("usbl.latency"));
}
