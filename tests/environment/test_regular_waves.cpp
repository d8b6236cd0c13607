// Regular (Airy) waves and the near-surface kinematics (issue 40, item 2): a regular wave's
// elevation, orbital velocity and acceleration equal linear theory's closed form, in deep and
// finite depth, written out here from the formulas (DNV-RP-C205 (2010) Table 3-1, in NED) with
// a dispersion root found by bisection here (not kelp's wave_number); its elevation at a probe
// is A cos(k x − ω t); Wheeler stretching puts linear theory's mean-level kinematics at the
// instantaneous surface; a spectral sea's kinematics above the mean level stay bounded.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/environment/waves.hpp"

using kelp::Matrix3X;
using kelp::Vector3;
using namespace kelp::environment;

// A named namespace: the directory's tests compile as one unity unit.
namespace regular_waves_test {

constexpr double kDeep = std::numeric_limits<double>::infinity();
constexpr double kG = kelp::standard_gravity;

/// The root k of ω² = g k tanh(k h) by bisection (deep water: ω²/g).
double bisect_wave_number(double omega, double depth) {
  const double k_deep = omega * omega / kG;
  if (std::isinf(depth)) return k_deep;
  double lo = 0.0, hi = 10.0 * k_deep + 10.0 / depth;  // f(lo) < 0 < f(hi)
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (kG * mid * std::tanh(mid * depth) < omega * omega ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Linear theory at depth z ≥ 0 (NED), written with cosh and sinh.
struct Airy {
  double a, omega, k, beta, phase, depth;
  double theta(double x, double y, double t) const {
    return k * (x * std::cos(beta) + y * std::sin(beta)) - omega * t + phase;
  }
  double fh(double z) const {
    return std::isinf(depth) ? std::exp(-k * z) : std::cosh(k * (depth - z)) / std::sinh(k * depth);
  }
  double fv(double z) const {
    return std::isinf(depth) ? std::exp(-k * z) : std::sinh(k * (depth - z)) / std::sinh(k * depth);
  }
  double elevation(double x, double y, double t) const { return a * std::cos(theta(x, y, t)); }
  Vector3<double> velocity(const Vector3<double>& p, double t, double z_profile) const {
    const double th = theta(p(0), p(1), t);
    const double u = a * omega * fh(z_profile) * std::cos(th);
    return {u * std::cos(beta), u * std::sin(beta), -a * omega * fv(z_profile) * std::sin(th)};
  }
  Vector3<double> acceleration(const Vector3<double>& p, double t, double z_profile) const {
    const double th = theta(p(0), p(1), t);
    const double u = a * omega * omega * fh(z_profile) * std::sin(th);
    return {u * std::cos(beta), u * std::sin(beta),
            a * omega * omega * fv(z_profile) * std::cos(th)};
  }
};

WaveFieldParameters regular_only(const RegularWave& w, double depth,
                                 WaveStretching stretching = WaveStretching::vertical) {
  WaveFieldParameters p;
  p.spectrum.significant_height = 0.0;
  p.depth = depth;
  p.regular = {w};
  p.stretching = stretching;
  return p;
}

void check_close(const Vector3<double>& got, const Vector3<double>& want, double scale) {
  for (int r = 0; r < 3; ++r) CHECK(got(r) == Approx(want(r)).margin(1e-10 * scale));
}

}  // namespace regular_waves_test

using namespace regular_waves_test;

TEST_CASE("regular wave: kinematics equal the closed form in deep and finite depth",
          "[environment][waves][regular]") {
  RegularWave w;
  w.height = 1.6;
  w.period = 7.0;
  w.direction = 0.7;
  w.phase = 0.3;
  for (const double depth : {kDeep, 400.0, 40.0, 12.0, 4.0}) {
    CAPTURE(depth);
    const double omega = 2.0 * kelp::pi / w.period;
    const Airy airy{0.5 * w.height, omega,   bisect_wave_number(omega, depth),
                    w.direction,    w.phase, depth};
    const WaveField<double> field(regular_only(w, depth));
    REQUIRE(field.size() == 1);
    CHECK(field.amplitude(0) == 0.5 * w.height);
    CHECK(field.omega(0) == Approx(omega).epsilon(1e-14));
    CHECK(field.wave_number_of(0) == Approx(airy.k).epsilon(1e-12));
    CHECK(field.direction(0) == w.direction);
    const double scale = airy.a * omega * omega * airy.fh(0.0);
    Matrix3X<double> pts(3, 40), vel(3, 40), acc(3, 40);
    Eigen::VectorXd zeta(40);
    for (int i = 0; i < 40; ++i) {
      const double z = std::isinf(depth) ? 0.6 * i : depth * i / 39.0;  // mean level to seabed
      pts.col(i) << -30.0 + 3.1 * i, 17.0 - 2.3 * i, z;
    }
    for (const double t : {0.0, 1.3, 4.9, 250.0}) {
      // Batch query with the elevation, and the single-point query.
      field.kinematics(pts, t, vel, acc, zeta);
      for (int i = 0; i < pts.cols(); ++i) {
        const Vector3<double> p = pts.col(i);
        const double eta = airy.elevation(p(0), p(1), t);
        CHECK(zeta(i) == Approx(eta).margin(1e-12));
        if (p(2) < -eta) continue;  // (not with these points: all at or below the mean level)
        check_close(vel.col(i), airy.velocity(p, t, p(2)), scale);
        check_close(acc.col(i), airy.acceleration(p, t, p(2)), scale);
        const WaveKinematics<double> k = field.kinematics(p, t);
        CHECK(k.elevation == Approx(eta).margin(1e-12));
        check_close(k.velocity, airy.velocity(p, t, p(2)), scale);
        check_close(k.acceleration, airy.acceleration(p, t, p(2)), scale);
      }
    }
  }
}

TEST_CASE("regular wave: given by its wavelength, and the dispersion relation holds",
          "[environment][waves][regular]") {
  for (const double depth : {kDeep, 60.0, 10.0, 2.0}) {
    CAPTURE(depth);
    RegularWave w;
    w.height = 0.8;
    w.wavelength = 45.0;
    const WaveField<double> field(regular_only(w, depth));
    const double k = field.wave_number_of(0), omega = field.omega(0);
    CHECK(k == Approx(2.0 * kelp::pi / 45.0).epsilon(1e-15));
    const double rhs = std::isinf(depth) ? kG * k : kG * k * std::tanh(k * depth);
    CHECK(omega * omega == Approx(rhs).epsilon(1e-13));
    // The same wave given by its period has the same wave number.
    RegularWave by_period = w;
    by_period.wavelength = 0.0;
    by_period.period = 2.0 * kelp::pi / omega;
    const WaveField<double> same(regular_only(by_period, depth));
    CHECK(same.wave_number_of(0) == Approx(k).epsilon(1e-12));
    // Shallower water: shorter waves for the same period.
    if (!std::isinf(depth)) CHECK(k > omega * omega / kG);
  }
}

TEST_CASE("regular wave: the elevation at a probe is A cos(k x - omega t)",
          "[environment][waves][regular]") {
  for (const double depth : {kDeep, 15.0}) {
    CAPTURE(depth);
    RegularWave w;
    w.height = 2.0;
    w.period = 5.5;
    SeaState sea;  // calm but for the regular wave
    sea.regular_waves = {w};
    SeaStateOptions o;
    o.seabed_depth = depth;
    const Environmentd env = make_environment<double>(sea, o);
    const double omega = 2.0 * kelp::pi / w.period, k = bisect_wave_number(omega, depth);
    const double x = 12.5, a = 1.0;
    Matrix3X<double> probe(3, 1), vel(3, 1), acc(3, 1);
    Eigen::VectorXd zeta(1);
    probe.col(0) << x, 0.0, 3.0;
    for (int i = 0; i <= 600; ++i) {
      const double t = 0.1 * i;
      const double want = a * std::cos(k * x - omega * t);
      CHECK(env.surface_elevation(x, 0.0, t) == Approx(want).margin(1e-12));
      env.sample_water(probe, t, vel, acc, zeta);
      CHECK(zeta(0) == Approx(want).margin(1e-12));
    }
    // A phase far beyond 2π is reduced exactly before the kernel's fast path: 0.7 + 1e6 · 2π
    // reads as 0.7 (to the rounding of that sum, ~1e-10 rad).
    {
      RegularWave far = w, near = w;
      near.phase = 0.7;
      far.phase = 0.7 + 1e6 * (2.0 * kelp::pi);
      const WaveField<double> f_near(regular_only(near, depth)), f_far(regular_only(far, depth));
      for (const double t : {0.0, 3.3, 1000.0})
        CHECK(f_far.elevation(x, 0.0, t) == Approx(f_near.elevation(x, 0.0, t)).margin(1e-8));
    }
    // A direction turns it: travelling east, the probe's phase is k y.
    w.direction = 0.5 * kelp::pi;
    const WaveField<double> east(regular_only(w, depth));
    CHECK(east.elevation(0.0, x, 2.0) == Approx(a * std::cos(k * x - omega * 2.0)).margin(1e-12));
  }
}

TEST_CASE("regular wave: superposes on a spectral sea; float and double agree",
          "[environment][waves][regular]") {
  WaveFieldParameters spectral;
  spectral.spectrum.significant_height = 2.0;
  spectral.spectrum.peak_period = 8.0;
  spectral.n_components = 40;
  spectral.depth = 50.0;
  RegularWave w;
  w.height = 1.0;
  w.period = 4.0;  // shorter than every spectral component: its k is the largest
  w.direction = -1.0;
  WaveFieldParameters both = spectral;
  both.regular = {w};
  const WaveField<double> s(spectral), r(regular_only(w, 50.0)), sr(both);
  REQUIRE(sr.size() == 41);
  CHECK(sr.omega(0) == s.omega(0));  // the spectral components are unchanged
  CHECK(sr.phase(39) == s.phase(39));
  CHECK(sr.variance() == Approx(s.variance() + 0.125));
  const WaveField<float> srf(both);
  for (const double t : {0.0, 3.3, 71.0})
    for (const double z : {0.0, 0.7, 6.0, 30.0}) {
      const Vector3<double> p(4.0, -9.0, z);
      const auto ks = s.kinematics(p, t), kr = r.kinematics(p, t), ksr = sr.kinematics(p, t);
      CHECK(ksr.elevation == Approx(ks.elevation + kr.elevation).margin(1e-12));
      if (z < -ksr.elevation || z < -ks.elevation || z < -kr.elevation) continue;
      check_close(ksr.velocity, ks.velocity + kr.velocity, 1.0);
      check_close(ksr.acceleration, ks.acceleration + kr.acceleration, 1.0);
      const auto kf = srf.kinematics(Vector3<float>(p.cast<float>()), t);
      CHECK(kf.velocity(2) == Approx(ksr.velocity(2)).margin(1e-5));
    }
}

TEST_CASE("Wheeler stretching: the surface reads linear theory's mean-level kinematics",
          "[environment][waves][regular][stretching]") {
  RegularWave w;
  w.height = 3.0;
  w.period = 6.0;
  w.direction = 0.4;
  for (const double depth : {kDeep, 20.0, 6.0}) {
    CAPTURE(depth);
    const double omega = 2.0 * kelp::pi / w.period;
    const Airy airy{1.5, omega, bisect_wave_number(omega, depth), w.direction, 0.0, depth};
    const WaveField<double> wheeler(regular_only(w, depth, WaveStretching::wheeler));
    const WaveField<double> vertical(regular_only(w, depth));
    const double scale = airy.a * omega * omega * airy.fh(0.0);
    for (int i = 0; i < 24; ++i) {
      const double t = 0.25 * i;  // crests, troughs and between
      const double x = 3.0, y = -1.0, eta = airy.elevation(x, y, t);
      // At the instantaneous surface (a hair below it, in the water): the linear value at z = 0.
      const Vector3<double> surface(x, y, -eta + 1e-12);
      const WaveKinematics<double> ks = wheeler.kinematics(surface, t);
      check_close(ks.velocity, airy.velocity(surface, t, 0.0), scale);
      check_close(ks.acceleration, airy.acceleration(surface, t, 0.0), scale);
      // Below it: linear theory at the stretched depth z' = (z + ζ) h / (h + ζ) (deep: z + ζ).
      for (const double z : {-0.5 * eta, 0.5, 2.0, 5.5}) {
        if (z < -eta || (!std::isinf(depth) && z > depth)) continue;
        const Vector3<double> p(x, y, z);
        const double zs = std::isinf(depth) ? z + eta : (z + eta) * depth / (depth + eta);
        check_close(wheeler.kinematics(p, t).velocity, airy.velocity(p, t, zs), scale);
        check_close(wheeler.kinematics(p, t).acceleration, airy.acceleration(p, t, zs), scale);
        // The default, vertical extrapolation: z = 0's kinematics above the mean level, linear
        // theory's below it.
        check_close(vertical.kinematics(p, t).velocity, airy.velocity(p, t, std::max(z, 0.0)),
                    scale);
      }
      // At the seabed stretching changes nothing.
      if (!std::isinf(depth)) {
        const Vector3<double> bed(x, y, depth);
        check_close(wheeler.kinematics(bed, t).velocity, airy.velocity(bed, t, depth), scale);
      }
      // Above the free surface: no water.
      const Vector3<double> air(x, y, -eta - 0.01);
      CHECK(wheeler.kinematics(air, t).velocity.norm() == 0.0);
      // The batch query agrees with the point query.
      Matrix3X<double> pts(3, 3), vel(3, 3), acc(3, 3);
      pts << x, x, x, y, y, y, -eta + 1e-12, 0.3, 4.0;
      wheeler.kinematics(pts, t, vel, acc);
      for (int c = 0; c < 3; ++c)
        check_close(vel.col(c), wheeler.kinematics(Vector3<double>(pts.col(c)), t).velocity, scale);
    }
  }
}

TEST_CASE("spectral sea: the kinematics above the mean level stay bounded",
          "[environment][waves][stretching]") {
  for (const double depth : {kDeep, 30.0}) {
    for (const WaveStretching stretching : {WaveStretching::vertical, WaveStretching::wheeler}) {
      CAPTURE(depth, static_cast<int>(stretching));
      WaveFieldParameters p;
      p.spectrum.significant_height = 4.0;
      p.spectrum.peak_period = 9.0;
      p.n_components = 64;
      p.spreading = 1.0;
      p.depth = depth;
      p.stretching = stretching;
      const WaveField<double> field(p);
      // |v_h| ≤ Σ a_j ω_j F_h,j(0) and |a| likewise anywhere in the water (F_h is largest at the
      // mean level, and neither method reads a profile above it).
      double vmax = 0.0, amax = 0.0;
      for (std::size_t j = 0; j < field.size(); ++j) {
        const double k = field.wave_number_of(j);
        const double fh0 = std::isinf(depth) ? 1.0 : 1.0 / std::tanh(k * depth);
        vmax += field.amplitude(j) * field.omega(j) * fh0;
        amax += field.amplitude(j) * field.omega(j) * field.omega(j) * fh0;
      }
      WaveFieldParameters mean_level = p;
      mean_level.stretching = WaveStretching::vertical;
      const WaveField<double> linear(mean_level);
      double highest = 0.0;
      for (int i = 0; i < 400; ++i) {
        const double t = 0.37 * i, x = 1.7 * i, y = -0.9 * i;
        const double eta = field.elevation(x, y, t);
        if (eta <= 0.0) continue;  // the crest region is empty under a trough
        highest = std::max(highest, eta);
        for (const double f : {1.0 - 1e-9, 0.5, 0.0}) {  // the surface, mid-crest, mean level
          const Vector3<double> pt(x, y, -f * eta);
          const WaveKinematics<double> k = field.kinematics(pt, t);
          CHECK(k.velocity.norm() <= vmax * std::sqrt(2.0));
          CHECK(k.acceleration.norm() <= amax * std::sqrt(2.0));
          CHECK(kelp::all_finite(k.velocity));
        }
        // Wheeler's surface velocity is the linear sum at the mean level.
        if (stretching == WaveStretching::wheeler) {
          const Vector3<double> top(x, y, -eta * (1.0 - 1e-12));
          check_close(field.kinematics(top, t).velocity,
                      linear.kinematics(Vector3<double>(x, y, 0.0), t).velocity, vmax);
        }
      }
      CHECK(highest > 1.0);  // the test saw real crests
    }
  }
}

TEST_CASE("Wheeler stretching: no heap allocation in a batch query",
          "[environment][waves][stretching]") {
  WaveFieldParameters p;
  p.spectrum.significant_height = 2.0;
  p.spectrum.peak_period = 7.0;
  p.depth = 25.0;
  p.stretching = WaveStretching::wheeler;
  RegularWave w;
  w.height = 1.0;
  w.wavelength = 30.0;
  p.regular = {w};
  const WaveField<double> field(p);
  Matrix3X<double> pts = Matrix3X<double>::Random(3, 70), vel(3, 70), acc(3, 70);
  Eigen::VectorXd zeta(70);
  Eigen::internal::set_is_malloc_allowed(false);
  field.kinematics(pts, 3.0, vel, acc, zeta);
  field.kinematics(pts, 4.0, vel, acc);
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(kelp::all_finite(vel));
  CHECK(kelp::all_finite(zeta));
}
