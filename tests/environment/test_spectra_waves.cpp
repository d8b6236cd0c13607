// Wave spectra, dispersion and irregular-wave kinematics: variances, peaks, the dispersion
// relation, depth decay, the kinematic free-surface condition, continuity, reproducibility by
// seed, batch vs point queries without allocation, and input validation.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>

#include "kelp/core/fast_math.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/spectra.hpp"
#include "kelp/environment/waves.hpp"

using kelp::Matrix3X;
using kelp::Vector3;
using namespace kelp::environment;

namespace {
WaveFieldParameters sea(double hs, double tp, SpectrumKind kind, double gamma = 3.3) {
  WaveFieldParameters p;
  p.spectrum.kind = kind;
  p.spectrum.significant_height = hs;
  p.spectrum.peak_period = tp;
  p.spectrum.peak_enhancement = gamma;
  return p;
}
}  // namespace

TEST_CASE("fast sin/cos/exp agree with the standard library", "[environment][waves]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> big(-1e5, 1e5), small(-4.0, 4.0), neg(-700.0, 0.0);
  double es = 0, ec = 0, ee = 0;
  for (int i = 0; i < 200000; ++i) {
    const double x = (i % 2) ? big(rng) : small(rng);
    double s, c;
    kelp::simd::fast_sincos(x, s, c);
    es = std::max(es, std::abs(s - std::sin(x)));
    ec = std::max(ec, std::abs(c - std::cos(x)));
    const double y = (i % 3) ? neg(rng) : small(rng) - 4.0;
    ee = std::max(ee, std::abs(kelp::simd::fast_exp_nonpositive(y) - std::exp(y)) / std::exp(y));
  }
  CHECK(es < 1e-11);  // |x| up to 1e5: the reduction loses ~|x|·ε of the argument
  CHECK(ec < 1e-11);
  CHECK(ee < 2e-14);
  CHECK(kelp::simd::fast_exp_nonpositive(-1e6) >= 0.0);
  CHECK(kelp::simd::fast_exp_nonpositive(-1e6) < 1e-300);
}

TEST_CASE("PM and JONSWAP discretised variance is Hs^2/16 within 1 %", "[environment][waves]") {
  // m0 = Hs²/16 is exact for PM; for JONSWAP the DNV normalisation 1 − 0.287 ln γ holds it to
  // about 1 % for γ ≤ 5. The discretisation keeps 0.5..5 ωp (< 0.2 % left out).
  for (const double hs : {0.5, 2.0, 4.5}) {
    for (const double tp : {4.0, 8.0, 12.0}) {
      for (const int n : {16, 64, 200}) {
        auto p = sea(hs, tp, SpectrumKind::pierson_moskowitz);
        p.n_components = n;
        CHECK(WaveField<double>(p).variance() == Approx(hs * hs / 16).epsilon(0.01));
        for (const double g : {1.0, 2.0, 3.3, 5.0}) {
          auto q = sea(hs, tp, SpectrumKind::jonswap, g);
          q.n_components = n;
          q.jitter = (n != 16);
          CHECK(WaveField<double>(q).variance() == Approx(hs * hs / 16).epsilon(0.01));
        }
      }
    }
  }
}

TEST_CASE("JONSWAP peaks at the peak frequency and reduces to PM for gamma = 1",
          "[environment][waves]") {
  const double hs = 3.0, tp = 8.0, wp = 2 * kelp::pi / tp;
  for (const double g : {1.0, 2.0, 3.3, 7.0}) {
    double best_w = 0, best_s = -1;
    for (int i = 1; i < 200000; ++i) {  // scan 0.00001..2 ωp·... finely
      const double w = wp * (0.2 + 1e-5 * i);
      const double s = jonswap(w, hs, tp, g);
      if (s > best_s) best_s = s, best_w = w;
    }
    CHECK(best_w == Approx(wp).epsilon(2e-5));
  }
  for (const double w : {0.3, 0.7, 1.0, 2.0})
    CHECK(jonswap(w, hs, tp, 1.0) == Approx(pierson_moskowitz(w, hs, tp)).epsilon(1e-14));
  // Peak enhancement: at ωp, S_J/S_PM = (1 − 0.287 ln γ) γ.
  CHECK(jonswap(wp, hs, tp, 3.3) / pierson_moskowitz(wp, hs, tp) ==
        Approx((1 - 0.287 * std::log(3.3)) * 3.3).epsilon(1e-12));
  CHECK(pierson_moskowitz(0.0, hs, tp) == 0.0);
  CHECK(pierson_moskowitz(-1.0, hs, tp) == 0.0);
}

TEST_CASE("the dispersion relation holds in deep and finite depth", "[environment][waves]") {
  const double g = kelp::standard_gravity;
  const double inf = std::numeric_limits<double>::infinity();
  for (const double w : {0.2, 0.5, 1.0, 2.0, 5.0}) {
    CHECK(wave_number(w, g, inf) == Approx(w * w / g).epsilon(1e-15));
    for (const double h : {1.0, 5.0, 10.0, 50.0, 500.0}) {
      const double k = wave_number(w, g, h);
      CHECK(g * k * std::tanh(k * h) == Approx(w * w).epsilon(1e-13));
      CHECK(k >= w * w / g);  // finite depth shortens the wave
      CHECK(wave_frequency(k, g, h) == Approx(w).epsilon(1e-13));
    }
  }
  // Independent value: T = 8 s in h = 10 m. Bisection of g k tanh(10k) = (2π/8)² (Python, 200
  // halvings) gives k = 0.0886411288224 rad/m, wavelength 70.88 m (deep: 99.9 m).
  CHECK(wave_number(2 * kelp::pi / 8, g, 10.0) == Approx(0.0886411288224).epsilon(1e-10));
  // Shallow-water limit k h → 0: ω ≈ k √(g h).
  const double k = wave_number(0.01, g, 2.0);
  CHECK(0.01 / k == Approx(std::sqrt(g * 2.0)).epsilon(1e-4));
}

TEST_CASE("a long elevation record has variance Hs^2/16 within 5 %", "[environment][waves]") {
  for (const auto kind : {SpectrumKind::pierson_moskowitz, SpectrumKind::jonswap}) {
    auto p = sea(2.5, 7.0, kind);
    p.n_components = 128;
    p.seed = 42;
    const WaveField<double> w(p);
    // 3 h at 0.25 s, at a point off the origin.
    double sum = 0, sum2 = 0;
    const int n = 43200;
    for (int i = 0; i < n; ++i) {
      const double z = w.elevation(13.0, -7.0, 0.25 * i);
      sum += z;
      sum2 += z * z;
    }
    const double mean = sum / n, var = sum2 / n - mean * mean;
    CHECK(std::abs(mean) < 0.05);
    CHECK(var == Approx(2.5 * 2.5 / 16).epsilon(0.05));
  }
}

TEST_CASE("a regular deep-water wave has circular orbits decaying as e^{-kz}",
          "[environment][waves]") {
  // One component: the orbital speed is a ω e^{−kz} and the acceleration a ω² e^{−kz} at every
  // phase (Airy), independent of t.
  auto p = sea(2.0, 6.0, SpectrumKind::pierson_moskowitz);
  p.n_components = 1;
  p.jitter = false;
  p.omega_min_factor = 0.99;
  p.omega_max_factor = 1.01;
  p.direction = 0.7;
  const WaveField<double> w(p);
  const double a = w.amplitude(0), om = w.omega(0), k = w.wave_number_of(0);
  REQUIRE(a > 0.1);
  // From just below the deepest trough (z = a) downwards, so every point is always wet.
  for (const double z : {a + 1e-6, 1.0, 3.0, 10.0, 25.0}) {
    for (const double t : {0.0, 0.3, 1.7, 4.1}) {
      const auto kin = w.kinematics(Vector3<double>(2.0, -1.0, z), t);
      CHECK(kin.velocity.norm() == Approx(a * om * std::exp(-k * z)).epsilon(1e-12));
      CHECK(kin.acceleration.norm() == Approx(a * om * om * std::exp(-k * z)).epsilon(1e-12));
      // Horizontal motion is along the wave direction.
      CHECK(std::abs(kin.velocity(0) * std::sin(0.7) - kin.velocity(1) * std::cos(0.7)) < 1e-12);
    }
  }
  // Above the free surface there is no water.
  const double zeta = w.elevation(2.0, -1.0, 0.0);
  const auto above = w.kinematics(Vector3<double>(2.0, -1.0, -zeta - 0.01), 0.0);
  CHECK(above.velocity.norm() == 0.0);
  CHECK(above.acceleration.norm() == 0.0);
}

TEST_CASE("finite depth: no vertical flow through the seabed, deep limit recovered",
          "[environment][waves]") {
  auto p = sea(1.0, 8.0, SpectrumKind::jonswap);
  p.depth = 12.0;
  p.n_components = 32;
  const WaveField<double> w(p);
  for (const double t : {0.0, 2.0, 5.5}) {
    const auto bed = w.kinematics(Vector3<double>(1.0, 2.0, 12.0), t);
    CHECK(std::abs(bed.velocity(2)) < 1e-14);
    CHECK(std::abs(bed.acceleration(2)) < 1e-14);
    CHECK(bed.velocity.head<2>().norm() > 0.0);
  }
  auto pd = p;
  pd.depth = 2000.0;  // k h ≫ 1 for every component: identical to deep water
  auto pi = p;
  pi.depth = std::numeric_limits<double>::infinity();
  const WaveField<double> wd(pd), wi(pi);
  const auto a = wd.kinematics(Vector3<double>(3.0, 1.0, 4.0), 1.5);
  const auto b = wi.kinematics(Vector3<double>(3.0, 1.0, 4.0), 1.5);
  CHECK((a.velocity - b.velocity).norm() < 1e-12);
}

TEST_CASE("kinematics satisfy the free-surface condition, continuity and d/dt",
          "[environment][waves]") {
  for (const double depth : {std::numeric_limits<double>::infinity(), 15.0}) {
    auto p = sea(2.0, 7.0, SpectrumKind::jonswap);
    p.spreading = 2.0;
    p.depth = depth;
    const WaveField<double> w(p);
    const double h = 1e-4;
    for (const double t : {0.5, 3.0, 11.0}) {
      const double x = 4.0, y = -3.0;
      // Linear kinematic surface condition at z = 0: ∂ζ/∂t = upward velocity = −v_z(NED).
      const double dzdt = (w.elevation(x, y, t + h) - w.elevation(x, y, t - h)) / (2 * h);
      // Evaluate below the mean level by a hair so the crest rule does not zero it.
      const auto k0 = w.kinematics(Vector3<double>(x, y, 0.0), t);
      if (k0.elevation > 0.0) CHECK(dzdt == Approx(-k0.velocity(2)).margin(1e-6));
      // Slope against finite differences of the elevation.
      const auto sl = w.slope(x, y, t);
      CHECK(sl(0) ==
            Approx((w.elevation(x + h, y, t) - w.elevation(x - h, y, t)) / (2 * h)).margin(1e-6));
      CHECK(sl(1) ==
            Approx((w.elevation(x, y + h, t) - w.elevation(x, y - h, t)) / (2 * h)).margin(1e-6));
      // At depth: ∂v/∂t matches the acceleration and ∇·v = 0 (incompressible).
      const Vector3<double> q(x, y, 3.0);
      const auto kq = w.kinematics(q, t);
      const Vector3<double> dvdt =
          (w.kinematics(q, t + h).velocity - w.kinematics(q, t - h).velocity) / (2 * h);
      CHECK((dvdt - kq.acceleration).norm() < 1e-6);
      double div = 0;
      for (int d = 0; d < 3; ++d) {
        Vector3<double> e = Vector3<double>::Zero();
        e(d) = h;
        div += (w.kinematics(q + e, t).velocity(d) - w.kinematics(q - e, t).velocity(d)) / (2 * h);
      }
      CHECK(std::abs(div) < 1e-6);
    }
  }
}

TEST_CASE("the velocity gradient matches finite differences and is symmetric and trace-free",
          "[environment][waves]") {
  // Point queries (the SIMD single-point kernel) and the generic (automatic-differentiation) path
  // of the same field, deep and finite depth, against central differences of the velocity.
  for (const double depth : {std::numeric_limits<double>::infinity(), 15.0}) {
    auto p = sea(2.0, 7.0, SpectrumKind::jonswap);
    p.spreading = 2.0;
    p.depth = depth;
    const WaveField<double> w(p);
    const double h = 1e-5;
    for (const double t : {0.5, 3.0, 11.0}) {
      const Vector3<double> q(4.0, -3.0, 2.5);
      const auto k = w.kinematics(q, t);
      Eigen::Matrix3d fd;
      for (int d = 0; d < 3; ++d) {
        Vector3<double> e = Vector3<double>::Zero();
        e(d) = h;
        fd.col(d) = (w.kinematics(q + e, t).velocity - w.kinematics(q - e, t).velocity) / (2 * h);
      }
      INFO("depth " << depth << ", t " << t);
      CHECK((k.velocity_gradient - fd).norm() < 1e-6);
      CHECK(fd.norm() > 1e-2);  // the gradient is not trivially zero here
      CHECK((k.velocity_gradient - k.velocity_gradient.transpose()).norm() < 1e-12);
      CHECK(std::abs(k.velocity_gradient.trace()) < 1e-12);
    }
    // Above the free surface: no water, no gradient.
    const auto air = w.kinematics(Vector3<double>(4.0, -3.0, -50.0), 3.0);
    CHECK(air.velocity_gradient.norm() == 0.0);
  }
}

TEST_CASE("the single-point query's slope is slope(), below, at and above the surface",
          "[environment][waves]") {
  // The slope summed with the kinematics (SIMD single-point kernel, baseline and dispatched; the
  // exact path for a huge t) against WaveField::slope, and against central differences of the
  // elevation; through Environment::sample too.
  for (const double depth : {std::numeric_limits<double>::infinity(), 15.0}) {
    auto p = sea(3.0, 7.5, SpectrumKind::jonswap);
    p.spreading = 2.0;
    p.depth = depth;
    WaveField<double> fast(p), base(p);
    base.set_force_baseline_kernel(true);
    Environment<double> env;
    env.set_waves(fast);
    const double h = 1e-5;
    for (const double t : {0.5, 3.0, 11.0, 1e17}) {
      for (const double z : {2.5, 0.0, -50.0}) {
        const double x = 4.0, y = -3.0;
        INFO("depth " << depth << ", t " << t << ", z " << z);
        const Eigen::Vector2d ref = fast.slope(x, y, t);
        const double tol = 1e-12 * (1.0 + ref.norm());
        CHECK((fast.kinematics(Vector3<double>(x, y, z), t).slope - ref).norm() <= tol);
        CHECK((base.kinematics(Vector3<double>(x, y, z), t).slope - ref).norm() <= tol);
        CHECK((env.sample(Vector3<double>(x, y, z), t).surface_slope - ref).norm() <= tol);
        if (t < 1e6) {
          const Eigen::Vector2d fd((fast.elevation(x + h, y, t) - fast.elevation(x - h, y, t)),
                                   (fast.elevation(x, y + h, t) - fast.elevation(x, y - h, t)));
          CHECK((ref - fd / (2 * h)).norm() < 1e-6);
          CHECK(ref.norm() > 1e-3);  // not trivially zero here
        }
      }
    }
  }
}

TEST_CASE("same seed gives the identical sea, another seed a different one",
          "[environment][waves]") {
  auto p = sea(2.0, 8.0, SpectrumKind::jonswap);
  p.spreading = 1.0;
  p.seed = 7;
  const WaveField<double> a(p), b(p);
  p.seed = 8;
  const WaveField<double> c(p);
  double max_ab = 0, max_ac = 0;
  for (int i = 0; i < 2000; ++i) {
    const double t = 0.1 * i;
    max_ab = std::max(max_ab, std::abs(a.elevation(1.0, 2.0, t) - b.elevation(1.0, 2.0, t)));
    max_ac = std::max(max_ac, std::abs(a.elevation(1.0, 2.0, t) - c.elevation(1.0, 2.0, t)));
  }
  CHECK(max_ab == 0.0);
  CHECK(max_ac > 0.5);  // Hs = 2 m: independent records differ by O(Hs)
  for (std::size_t j = 0; j < a.size(); ++j) {
    CHECK(a.phase(j) == b.phase(j));
    CHECK(a.direction(j) == b.direction(j));
  }
}

TEMPLATE_TEST_CASE("the batch query equals point queries and does not allocate",
                   "[environment][waves]", double, float) {
  using S = TestType;
  auto p = sea(3.0, 8.0, SpectrumKind::jonswap);
  p.spreading = 1.0;
  for (const double depth : {std::numeric_limits<double>::infinity(), 20.0}) {
    p.depth = depth;
    const WaveField<S> w(p);
    const int n = 37;  // not a multiple of the block size
    Matrix3X<S> pts(3, n), vel(3, n), acc(3, n);
    for (int i = 0; i < n; ++i) pts.col(i) << S(0.5 * i), S(-0.3 * i), S(-1.0 + 0.6 * i);
    Eigen::internal::set_is_malloc_allowed(false);
    w.kinematics(pts, S(2.5), vel, acc);
    Eigen::internal::set_is_malloc_allowed(true);
    for (int i = 0; i < n; ++i) {
      const auto k = w.kinematics(Vector3<S>(pts.col(i)), S(2.5));
      CHECK((vel.col(i) - k.velocity).norm() <= S(1e-6) * (S(1) + k.velocity.norm()));
      CHECK((acc.col(i) - k.acceleration).norm() <= S(1e-6) * (S(1) + k.acceleration.norm()));
    }
    // float and double fields built from the same parameters agree.
    const WaveField<double> wd(p);
    const auto kd = wd.kinematics(Vector3<double>(1.0, 2.0, 3.0), 4.0);
    const auto kf = w.kinematics(Vector3<S>(S(1), S(2), S(3)), S(4));
    CHECK((kd.velocity - kf.velocity.template cast<double>()).norm() < 1e-5);
  }
}

TEST_CASE("the run-time dispatched SIMD kernel agrees with the baseline kernel",
          "[environment][waves]") {
  // On a CPU with AVX2/AVX-512 the batch query runs a kernel compiled for it; it must give the
  // baseline's numbers up to FMA rounding.
  for (const double depth : {std::numeric_limits<double>::infinity(), 25.0}) {
    auto p = sea(4.5, 9.5, SpectrumKind::jonswap);
    p.spreading = 1.0;
    p.depth = depth;
    WaveField<double> fast(p), base(p);
    base.set_force_baseline_kernel(true);
    const int n = 70;
    Matrix3X<double> pts(3, n), v1(3, n), a1(3, n), v2(3, n), a2(3, n);
    for (int i = 0; i < n; ++i) pts.col(i) << 0.3 * i, 0.1 * i, -1.0 + 0.3 * i;
    for (const double t : {0.0, 17.3, 1234.5}) {
      fast.kinematics(pts, t, v1, a1);
      base.kinematics(pts, t, v2, a2);
      CHECK((v1 - v2).norm() <= 1e-12 * (1 + v2.norm()));
      CHECK((a1 - a2).norm() <= 1e-12 * (1 + a2.norm()));
    }
  }
}

TEST_CASE("bad wave input throws kelp::invalid_argument naming the field", "[environment][waves]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto p = sea(2.0, 8.0, SpectrumKind::jonswap);
  auto bad = p;
  bad.spectrum.significant_height = -1.0;
  CHECK_THROWS_AS(WaveField<double>(bad), kelp::invalid_argument);
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("significant_height"));
  bad = p;
  bad.spectrum.significant_height = nan;
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("significant_height"));
  for (const double tp : {0.0, -3.0, nan}) {
    bad = p;
    bad.spectrum.peak_period = tp;
    CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("peak_period"));
  }
  bad = p;
  bad.n_components = 0;
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("n_components"));
  bad = p;
  bad.spectrum.peak_enhancement = 0.5;
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("peak_enhancement"));
  bad = p;
  bad.direction = nan;
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("direction"));
  bad = p;
  bad.depth = -4.0;
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("depth"));
  bad = p;
  bad.spreading = -1.0;
  CHECK_THROWS_WITH(WaveField<double>(bad), Catch::Contains("spreading"));
  CHECK_THROWS_WITH(wave_number(-1.0, 9.81, 10.0), Catch::Contains("omega"));
  // Hs = 0 is a valid calm sea.
  auto calm = p;
  calm.spectrum.significant_height = 0.0;
  const WaveField<double> c(calm);
  CHECK(c.empty());
  CHECK(c.kinematics(Vector3<double>(0, 0, 1), 3.0).velocity.norm() == 0.0);
}

TEST_CASE("the wave kernel's exp and sign-split sin/cos keep their error bounds",
          "[environment][waves]") {
  // fast_exp_nonpositive_unchecked<false> (one-term ln 2 reduction, used by the wave kernel):
  // absolute error ≤ 1.3e-17 + 1e-15·e^x (the kernel sums a·e^{−kz}); fast_sincos_unsigned
  // returns (sin, cos) up to the sign it reports.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> neg(-700.0, 0.0), small(-8.0, 0.0), ang(-1e4, 1e4);
  double worst_exp = 0, worst_sc = 0;
  for (int i = 0; i < 100000; ++i) {
    const double x = (i % 2) ? neg(rng) : small(rng);
    const double e = kelp::simd::fast_exp_nonpositive_unchecked<false>(x);
    worst_exp = std::max(worst_exp, std::abs(e - std::exp(x)) / (1.3e-17 + 1e-15 * std::exp(x)));
    const double a = ang(rng);
    double s, c;
    std::uint64_t sign;
    kelp::simd::fast_sincos_unsigned(a, s, c, sign);
    const double sg = sign ? -1.0 : 1.0;
    worst_sc = std::max({worst_sc, std::abs(sg * s - std::sin(a)), std::abs(sg * c - std::cos(a))});
  }
  CHECK(worst_exp <= 1.0);
  CHECK(worst_sc < 1e-12);  // |a| ≤ 1e4: the argument itself carries ~|a|·1e-16
}

TEST_CASE("points below every trough (elevation sum skipped) match point queries",
          "[environment][waves]") {
  // The batch kernel skips the elevation sum for lane groups deeper than Σ a_j; their results
  // must be those of the point query, which always sums it.
  auto p = sea(4.5, 9.5, SpectrumKind::jonswap);
  p.spreading = 1.0;
  const WaveField<double> w(p);
  double amp_sum = 0;
  for (std::size_t j = 0; j < w.size(); ++j) amp_sum += w.amplitude(j);
  const int n = 45;
  Matrix3X<double> pts(3, n), vel(3, n), acc(3, n);
  for (int i = 0; i < n; ++i) pts.col(i) << 0.4 * i, -0.2 * i, amp_sum - 3.0 + 0.25 * i;
  w.kinematics(pts, 3.3, vel, acc);
  for (int i = 0; i < n; ++i) {
    const auto k = w.kinematics(Vector3<double>(pts.col(i)), 3.3);
    CHECK((vel.col(i) - k.velocity).norm() <= 1e-12 * (1 + k.velocity.norm()));
    CHECK((acc.col(i) - k.acceleration).norm() <= 1e-12 * (1 + k.acceleration.norm()));
  }
}
