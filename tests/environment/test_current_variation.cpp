// The Gauss–Markov current keeps varying for any run length, is deterministic for a seed, and has
// the process's mean, variance and autocorrelation e^{-tau/T}.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "kelp/environment/current.hpp"
#include "kelp/environment/environment.hpp"

using namespace kelp::environment;
using kelp::Vector3;

namespace {

CurrentParameters varying(std::uint64_t seed) {
  CurrentParameters p;
  p.speed = 0.5;
  p.direction = 1.0;
  p.speed_variation.time_constant = 600.0;  // T = 10 min
  p.speed_variation.sigma = 0.004;          // stationary std σ√(T/2) = 0.0693 m/s
  p.direction_variation.time_constant = 1200.0;
  p.direction_variation.sigma = 0.002;  // 0.049 rad
  p.seed = seed;
  return p;
}

struct Stats {
  double mean = 0, var = 0;
};

Stats stats(const CurrentModel<double>& c, double t0, double t1, double dt) {
  double s = 0, s2 = 0;
  long n = 0;
  for (double t = t0; t < t1; t += dt, ++n) {
    const double v = c.speed_at(t);
    s += v;
    s2 += v * v;
  }
  Stats r;
  r.mean = s / static_cast<double>(n);
  r.var = s2 / static_cast<double>(n) - r.mean * r.mean;
  return r;
}

}  // namespace

TEST_CASE("current variation: bitwise deterministic for a seed, different across seeds",
          "[environment][current]") {
  const CurrentModel<double> a(varying(3)), b(varying(3)), c(varying(4));
  double diff_ac = 0.0;
  for (double t : {0.0, 1.5, 3599.0, 3600.5, 7200.0, 36000.0, 360000.0, 1e7}) {
    const double va = a.speed_at(t), vb = b.speed_at(t);
    CHECK(std::memcmp(&va, &vb, sizeof va) == 0);
    CHECK(a.direction_at(t) == b.direction_at(t));
    diff_ac = std::max(diff_ac, std::abs(va - c.speed_at(t)));
  }
  CHECK(diff_ac > 0.01);
  // Random access: evaluating in any order gives the same values (no hidden state).
  const double late = a.speed_at(1e6);
  a.speed_at(3.0);
  CHECK(a.speed_at(1e6) == late);
}

TEST_CASE("current variation: still varies after 1 h and after 100 h", "[environment][current]") {
  const CurrentModel<double> c(varying(11));
  const double sd = 0.004 * std::sqrt(600.0 / 2.0);
  // Before, the record was precomputed for 3600 s and then held: zero variance after 1 h.
  for (const double t0 : {0.0, 3600.0, 36000.0, 360000.0, 3.6e6}) {
    const Stats s = stats(c, t0, t0 + 36000.0, 5.0);  // 10 h windows
    CAPTURE(t0, s.mean, std::sqrt(s.var));
    CHECK(std::sqrt(s.var) > 0.4 * sd);
    CHECK(std::sqrt(s.var) < 2.0 * sd);
  }
  // A short window late in the run moves as much as one at the start (several T long).
  const double early = std::sqrt(stats(c, 0.0, 3600.0, 2.0).var);
  const double late = std::sqrt(stats(c, 36000.0, 39600.0, 2.0).var);
  CHECK(late > 0.25 * early);
  CHECK(late < 4.0 * early);
  // Direction too.
  double dmin = 1e9, dmax = -1e9;
  for (double t = 360000.0; t < 367200.0; t += 10.0) {
    dmin = std::min(dmin, c.direction_at(t));
    dmax = std::max(dmax, c.direction_at(t));
  }
  CHECK(dmax - dmin > 0.02);
}

TEST_CASE("current variation: mean, variance and autocorrelation of the Gauss-Markov process",
          "[environment][current]") {
  const double T = 600.0, sigma = 0.004, var = sigma * sigma * T / 2.0;
  // Long record, 500 h = 3000 T, averaged over 4 seeds: the time averages' sampling errors are
  // ~ sqrt(2T/L) ≈ 2.6 % per seed.
  double mean = 0, variance = 0, rho_T = 0, rho_3T = 0;
  const int n_seeds = 4;
  for (int seed = 1; seed <= n_seeds; ++seed) {
    const CurrentModel<double> c(varying(static_cast<std::uint64_t>(seed)));
    const double dt = 20.0, L = 500.0 * 3600.0;
    const int lag1 = static_cast<int>(T / dt), lag3 = 3 * lag1;
    std::vector<double> x;
    x.reserve(static_cast<std::size_t>(L / dt) + 1);
    for (double t = 0.0; t < L; t += dt) x.push_back(c.speed_at(t) - 0.5);
    double m = 0, v = 0, c1 = 0, c3 = 0;
    for (double xi : x) m += xi;
    m /= static_cast<double>(x.size());
    for (double xi : x) v += (xi - m) * (xi - m);
    v /= static_cast<double>(x.size());
    for (std::size_t i = 0; i + lag3 < x.size(); ++i) {
      c1 += (x[i] - m) * (x[i + lag1] - m);
      c3 += (x[i] - m) * (x[i + lag3] - m);
    }
    const double np = static_cast<double>(x.size() - lag3);
    mean += m / n_seeds;
    variance += v / n_seeds;
    rho_T += c1 / np / v / n_seeds;
    rho_3T += c3 / np / v / n_seeds;
  }
  CAPTURE(mean, variance, var, rho_T, rho_3T);
  CHECK(std::abs(mean) < 0.05 * std::sqrt(var));
  CHECK(variance == Approx(var).epsilon(0.06));
  CHECK(rho_T == Approx(std::exp(-1.0)).margin(0.03));
  CHECK(rho_3T == Approx(std::exp(-3.0)).margin(0.03));
}

TEST_CASE("current variation: bounded, allocation-free, float reads the same current",
          "[environment][current]") {
  CurrentParameters p = varying(5);
  p.speed_variation.sigma = 0.02;  // std 0.35 m/s: the bounds are hit often
  p.speed_variation.lower = 0.3;
  p.speed_variation.upper = 0.7;
  p.direction_variation.lower = 0.9;
  p.direction_variation.upper = 1.1;
  const CurrentModel<double> c(p);
  const CurrentModel<float> cf(p);
  Environment<double> env;
  env.set_current(c);
  kelp::Matrix3X<double> pts(3, 4), vel(3, 4), acc(3, 4);
  pts.setZero();
  double vmin = 1e9, vmax = -1e9;
  Eigen::internal::set_is_malloc_allowed(false);
  for (double t = 1e6; t < 1e6 + 20000.0; t += 3.0) {
    const double v = c.speed_at(t), d = c.direction_at(t);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
    CHECK((v >= 0.3 && v <= 0.7 && d >= 0.9 && d <= 1.1));
    env.sample_water(pts, t, vel, acc);
    const Vector3<float> uf = cf.surface_velocity(t);
    CHECK(std::abs(static_cast<double>(uf(0)) - vel(0, 0)) < 1e-6);
  }
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(vmin == 0.3);
  CHECK(vmax == 0.7);
}
