// One clock: time is a double for every Scalar, and wave/wind phases are formed in double, so a
// float model reads the same sea as a double model after a day (or a year) of simulation.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/paper.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/environment/wave_loads.hpp"

using namespace kelp::environment;
using kelp::Vector3;

namespace {

WaveFieldParameters day_sea() {
  WaveFieldParameters p;
  p.spectrum.significant_height = 2.0;
  p.spectrum.peak_period = 7.0;
  p.spreading = 1.0;
  p.n_components = 48;
  p.seed = 7;
  return p;
}

// 24 h plus one 10 ms step: 86400.01 s is not a float (the nearest is 86400.0078125), so a float
// clock would put the phase of a 4 rad/s component ~1e-2 rad off.
constexpr double t_day = 86400.01;

// float rounding of a result of size ~|scale|: a few float ulps of the largest term.
double float_tol(double scale) { return 8.0 * std::numeric_limits<float>::epsilon() * scale; }

}  // namespace

TEST_CASE("time: float and double seas agree after 24 h (double clock)", "[environment][time]") {
  const WaveField<double> wd(day_sea());
  const WaveField<float> wf(day_sea());
  double amp_sum = 0.0, vel_scale = 0.0;
  for (std::size_t j = 0; j < wd.size(); ++j) {
    amp_sum += wd.amplitude(j);
    vel_scale += wd.amplitude(j) * wd.omega(j) * wd.omega(j);  // acceleration scale ≥ velocity's
  }
  for (const double t : {t_day, t_day + 0.37, 100.0 * 3600.0 + 0.01}) {
    const float x = 12.5F, y = -3.25F;
    const double zd = wd.elevation(x, y, t);
    const float zf = wf.elevation(x, y, t);
    CHECK(std::abs(zf - zd) <= float_tol(amp_sum));
    const auto sd = wd.slope(x, y, t);
    const auto sf = wf.slope(x, y, t);
    CHECK(std::abs(sf(0) - sd(0)) <= float_tol(vel_scale));
    CHECK(std::abs(sf(1) - sd(1)) <= float_tol(vel_scale));
    const auto kd = wd.kinematics(Vector3<double>(x, y, 2.0), t);
    const auto kf = wf.kinematics(Vector3<float>(x, y, 2.0F), t);
    for (int r = 0; r < 3; ++r) {
      CHECK(std::abs(kf.velocity(r) - kd.velocity(r)) <= float_tol(vel_scale));
      CHECK(std::abs(kf.acceleration(r) - kd.acceleration(r)) <= float_tol(vel_scale));
    }
    // Through the environment facade, batch path included.
    Environment<float> ef;
    ef.set_waves(wf);
    Environment<double> ed;
    ed.set_waves(wd);
    CHECK(std::abs(ef.surface_elevation(x, y, t) - ed.surface_elevation(x, y, t)) <=
          float_tol(amp_sum));
    kelp::Matrix3X<float> pf(3, 2), vf(3, 2), af(3, 2);
    kelp::Matrix3X<double> pd(3, 2), vd(3, 2), ad(3, 2);
    pf << x, 0.5F, y, 1.5F, 2.0F, 6.0F;
    pd = pf.cast<double>();
    ef.sample_water(pf, t, vf, af);
    ed.sample_water(pd, t, vd, ad);
    CHECK((vf.cast<double>() - vd).cwiseAbs().maxCoeff() <= float_tol(vel_scale));
    CHECK((af.cast<double>() - ad).cwiseAbs().maxCoeff() <= float_tol(vel_scale));
  }
}

TEST_CASE("time: wave phase after 24 h matches an independent long-double computation",
          "[environment][time]") {
  const WaveField<float> w(day_sea());
  for (const double t : {t_day, 3.0 * 86400.0 + 0.01, 365.0 * 86400.0}) {
    for (std::size_t j = 0; j < w.size(); ++j) {
      const long double two_pi = 6.283185307179586476925286766559005768L;
      const long double exact = std::remainder(
          static_cast<long double>(w.phase(j)) - static_cast<long double>(w.omega(j)) * t, two_pi);
      double diff = std::abs(static_cast<double>(exact) - w.time_phase(j, t));
      diff = std::min(diff, 2.0 * kelp::pi - diff);  // ±π is the same phase
      // 1e-9 s relative: the phase error stays below ω t · 1e-9 (in practice ≈ 1e-16 ω t).
      CHECK(diff <= 1e-9 * w.omega(j) * t);
      CHECK(diff <= 1e-15 * w.omega(j) * t + 1e-15);
    }
    // Elevation of one component by plain double math at the same phase.
    const double x = 40.0, y = -10.0;
    long double z = 0.0L;
    for (std::size_t j = 0; j < w.size(); ++j) {
      const long double two_pi = 6.283185307179586476925286766559005768L;
      const double kx = w.wave_number_of(j) * std::cos(w.direction(j));
      const double ky = w.wave_number_of(j) * std::sin(w.direction(j));
      const long double th = std::remainder(static_cast<long double>(w.phase(j)) -
                                                static_cast<long double>(w.omega(j)) * t,
                                            two_pi) +
                             static_cast<long double>(kx) * x + static_cast<long double>(ky) * y;
      z += static_cast<long double>(w.amplitude(j)) * std::cos(th);
    }
    CHECK(std::abs(static_cast<double>(z) - static_cast<double>(w.elevation(40.0F, -10.0F, t))) <=
          1e-6);
  }
}

TEST_CASE("time: wind gusts and the paper's wave load read a double clock", "[environment][time]") {
  WindParameters wp;
  wp.speed = 10.0;
  wp.gust = GustSpectrum::harris;
  wp.f_min = 1e-3;
  const WindField<double> wd(wp);
  const WindField<float> wf(wp);
  for (const double t : {t_day, 100.0 * 3600.0 + 0.01})
    CHECK(std::abs(wf.speed(t) - wd.speed(t)) <= float_tol(wp.speed + 3.0));
  PaperWave pw;
  pw.beam = 1.0;
  pw.length = 1.2;
  pw.draft = 0.1;
  pw.amplitude = 0.5;
  pw.wavelength = 20.0;
  const double f0 = paper_wave_force(pw.rho, pw.gravity, pw.beam, pw.length, pw.draft, pw.amplitude,
                                     pw.wavelength);
  // Heading and speed exactly representable in float: only the clock could make them differ.
  const Vector3<double> ld = paper_wave_load(pw, t_day, 0.25, 1.0);
  const Vector3<float> lf = paper_wave_load(pw, t_day, 0.25F, 1.0F);
  CHECK(std::abs(lf(0) - ld(0)) <= float_tol(f0));
  CHECK(std::abs(lf(1) - ld(1)) <= float_tol(f0));
}
