// Bad input at the environment's public boundary: absurd but finite parameters whose derived
// quantities would overflow, NaN / Inf / zero / negative arguments of the pure functions, sizes
// that do not match, and times beyond the range of the fast wave kernel. Each bad input must
// throw kelp::invalid_argument; the valid inputs next to it must keep working.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "kelp/core/fast_math.hpp"
#include "kelp/environment/current.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/paper.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/environment/spectra.hpp"
#include "kelp/environment/wave_loads.hpp"
#include "kelp/environment/waves.hpp"
#include "kelp/environment/wind.hpp"
#include "support/non_finite.hpp"

using kelp::Matrix3X;
using kelp::Vector3;
using namespace kelp::environment;

namespace {

using kelp_test::kInf;
using kelp_test::kNan;

WaveFieldParameters sea(double hs = 2.0, double tp = 7.0) {
  WaveFieldParameters p;
  p.spectrum.significant_height = hs;
  p.spectrum.peak_period = tp;
  p.spreading = 1.0;
  p.n_components = 32;
  p.seed = 11;
  return p;
}

// ζ at (x, y, t) of a field by plain long-double arithmetic from the field's reduced time
// phases (whose accuracy the reduce_phase test checks) and the C library's cosine.
double reference_elevation(const WaveField<double>& w, double x, double y, double t) {
  long double z = 0.0L;
  for (std::size_t j = 0; j < w.size(); ++j) {
    const long double kx = w.wave_number_of(j) * std::cos(w.direction(j));
    const long double ky = w.wave_number_of(j) * std::sin(w.direction(j));
    const long double th = static_cast<long double>(w.time_phase(j, t)) +
                           kx * static_cast<long double>(x) + ky * static_cast<long double>(y);
    z += static_cast<long double>(w.amplitude(j)) * std::cos(th);
  }
  return static_cast<double>(z);
}

}  // namespace

TEST_CASE("bad input: wave spectrum parameters out of their physical bounds",
          "[environment][bad_input]") {
  // Absurd but finite values whose spectral moments or wave numbers overflow.
  for (const double hs : {1e300, 101.0, -1.0, kNan, kInf}) {
    INFO("Hs = " << hs);
    REQUIRE_THROWS_AS(WaveField<double>(sea(hs, 7.0)), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(WaveField<double>(sea(hs, 7.0)), Catch::Contains("significant_height"));
  }
  for (const double tp : {1e-300, 0.0, 0.05, 1e300, 1001.0, kNan}) {
    INFO("Tp = " << tp);
    REQUIRE_THROWS_AS(WaveField<double>(sea(2.0, tp)), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(WaveField<double>(sea(2.0, tp)), Catch::Contains("peak_period"));
  }
  // The message carries the value.
  REQUIRE_THROWS_WITH(WaveField<double>(sea(1e300, 7.0)), Catch::Contains("1e+300"));
  for (const double gamma : {0.0, 0.5, 25.0, 1e300, kNan}) {
    INFO("gamma = " << gamma);
    WaveFieldParameters p = sea();
    p.spectrum.peak_enhancement = gamma;
    REQUIRE_THROWS_AS(WaveField<double>(p), kelp::invalid_argument);
  }
  WaveFieldParameters p = sea();
  p.omega_max_factor = 1e300;
  REQUIRE_THROWS_AS(WaveField<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(WaveField<double>(p), Catch::Contains("omega_max_factor"));
  p = sea();
  p.gravity = 1e300;
  REQUIRE_THROWS_AS(WaveField<double>(p), kelp::invalid_argument);
  p.gravity = 0.0;
  REQUIRE_THROWS_AS(WaveField<double>(p), kelp::invalid_argument);
  p = sea();
  p.spreading = 1e300;  // the direction sampling would spin and fall back to long-crested
  REQUIRE_THROWS_AS(WaveField<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(WaveField<double>(p), Catch::Contains("spreading"));
  p.spreading = 1000.0;  // the bound: narrow (±2°) but accepted
  {
    const WaveField<double> narrow(p);
    for (std::size_t j = 0; j < narrow.size(); ++j)
      CHECK(std::abs(narrow.direction(j) - p.direction) < 0.2);
  }
  p = sea();
  p.n_components = 2'000'000'000;
  REQUIRE_THROWS_AS(WaveField<double>(p), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(WaveField<double>(p), Catch::Contains("n_components"));

  // The bounds themselves are accepted and give finite, correct seas.
  for (const auto& hs_tp : {std::pair<double, double>{100.0, 20.0}, {0.01, 0.1}, {1.0, 1000.0}}) {
    INFO("Hs = " << hs_tp.first << ", Tp = " << hs_tp.second);
    WaveFieldParameters q = sea(hs_tp.first, hs_tp.second);
    q.spreading = 0.0;
    q.n_components = 128;
    const WaveField<double> w(q);
    CHECK(std::isfinite(w.elevation(3.0, 4.0, 10.0)));
    CHECK(w.variance() == Approx(hs_tp.first * hs_tp.first / 16.0).epsilon(0.05));
  }
  WaveFieldParameters peaked = sea();
  peaked.spectrum.peak_enhancement = 20.0;  // the largest γ accepted
  CHECK(WaveField<double>(peaked).variance() > 0.0);
}

TEST_CASE("bad input: regular waves", "[environment][bad_input][regular]") {
  RegularWave good;
  good.height = 1.0;
  good.period = 6.0;
  const auto field = [](const RegularWave& w, double hs = 0.0) {
    WaveFieldParameters p = sea(hs == 0.0 ? 0.0 : hs, 7.0);
    p.regular = {w};
    return WaveField<double>(p);
  };
  REQUIRE(field(good).size() == 1);
  REQUIRE(field(good, 2.0).size() == 33);
  const auto refused = [&](RegularWave w, const char* field_name) {
    INFO(field_name);
    REQUIRE_THROWS_AS(field(w), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(field(w), Catch::Contains(field_name));
  };
  for (const double h : {-1.0, 101.0, kNan, kInf}) {
    RegularWave w = good;
    w.height = h;
    refused(w, "regular.height");
  }
  RegularWave both = good;
  both.wavelength = 50.0;  // period and wavelength
  refused(both, "exactly one of regular.period and regular.wavelength");
  RegularWave neither = good;
  neither.period = 0.0;
  refused(neither, "exactly one of regular.period and regular.wavelength");
  for (const double t : {-6.0, kNan}) {
    RegularWave w = good;
    w.period = t;
    refused(w, "regular.period");
  }
  for (const double t : {0.01, 1e4, kInf}) {
    RegularWave w = good;
    w.period = t;
    refused(w, "regular.period");
  }
  for (const double l : {-5.0, kInf, 1e7}) {
    RegularWave w = good;
    w.period = 0.0;
    w.wavelength = l;
    refused(w, "regular.wavelength");
  }
  RegularWave w = good;
  w.direction = kNan;
  refused(w, "regular.direction");
  w = good;
  w.phase = kInf;
  refused(w, "regular.phase");
  // Steeper than the breaking limit H/λ = 1/7: λ = g T²/2π ≈ 56.2 m for T = 6 s (deep water).
  w = good;
  w.height = 8.1;
  refused(w, "breaking limit");
  w.height = 7.9;
  CHECK(field(w).size() == 1);
  // In shallow water Miche's limit H/λ = tanh(k h)/7 is lower: 2 m of water and T = 7 s give
  // λ = 30.0 m (k = 0.2094 rad/m from ω² = g k tanh(k h)) and a limit of 4.29 · tanh(0.419) =
  // 1.70 m; Michell's deep-water λ/7 let 4.2 m through, a trough below the seabed.
  w = good;
  w.period = 7.0;
  const auto shallow = [](const RegularWave& r) {
    WaveFieldParameters p = sea(0.0, 7.0);
    p.depth = 2.0;
    p.regular = {r};
    return WaveField<double>(p);
  };
  w.height = 1.75;
  REQUIRE_THROWS_WITH(shallow(w), Catch::Contains("breaking limit"));
  w.height = 1.65;
  CHECK(shallow(w).size() == 1);
  // The stretching enum out of range.
  WaveFieldParameters p = sea();
  p.stretching = static_cast<WaveStretching>(7);
  REQUIRE_THROWS_WITH(WaveField<double>(p), Catch::Contains("stretching"));
}

TEST_CASE("bad input: spectra and dispersion as pure functions", "[environment][bad_input]") {
  const double hs = 3.0, tp = 8.0, w = 0.9;
  // Tp = 0 and γ = 0 used to give NaN.
  REQUIRE_THROWS_AS(pierson_moskowitz(w, hs, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(jonswap(w, hs, 0.0, 3.3), kelp::invalid_argument);
  REQUIRE_THROWS_AS(jonswap(w, hs, tp, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(jonswap(w, hs, tp, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(jonswap(w, hs, tp, 40.0), kelp::invalid_argument);  // A_γ < 0
  REQUIRE_THROWS_AS(jonswap_normalisation(0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(pierson_moskowitz(kNan, hs, tp), kelp::invalid_argument);
  REQUIRE_THROWS_AS(pierson_moskowitz(w, kNan, tp), kelp::invalid_argument);
  REQUIRE_THROWS_AS(pierson_moskowitz(w, -1.0, tp), kelp::invalid_argument);
  REQUIRE_THROWS_AS(pierson_moskowitz(w, hs, -8.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(pierson_moskowitz(w, hs, kInf), kelp::invalid_argument);
  REQUIRE_THROWS_AS(pierson_moskowitz(w, 1e300, tp), kelp::invalid_argument);  // Hs² overflows
  // A tiny (but positive) Tp puts ω far below the peak: S is exactly 0, not ∞ · 0 = NaN.
  CHECK(pierson_moskowitz(w, hs, 1e-300) == 0.0);
  CHECK(jonswap(w, hs, 1e-300, 3.3) == 0.0);
  CHECK(pierson_moskowitz(kInf, hs, tp) == 0.0);
  // Valid inputs: the peak value S(ω_p) = 5/16 Hs² ω_p⁻¹ e^{−5/4}.
  const double wp = 2.0 * kelp::pi / tp;
  CHECK(pierson_moskowitz(wp, hs, tp) ==
        Approx(5.0 / 16.0 * hs * hs / wp * std::exp(-1.25)).epsilon(1e-14));
  CHECK(jonswap(wp, hs, tp, 3.3) ==
        Approx(jonswap_normalisation(3.3) * 3.3 * pierson_moskowitz(wp, hs, tp)).epsilon(1e-14));
  WaveSpectrum s;
  s.peak_enhancement = 0.0;
  REQUIRE_THROWS_AS(spectral_density(s, w), kelp::invalid_argument);

  // Dispersion: zero, NaN or overflowing inputs.
  REQUIRE_THROWS_AS(wave_number(1.0, 0.0, kInf), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wave_number(kNan, 9.81, kInf), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wave_number(1.0, 9.81, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wave_number(1e200, 9.81, kInf), kelp::invalid_argument);   // ω² overflows
  REQUIRE_THROWS_AS(wave_number(1e-200, 9.81, 10.0), kelp::invalid_argument);  // ω² underflows
  REQUIRE_THROWS_AS(wave_number(1.0, 1e-320, kInf), kelp::invalid_argument);
  CHECK(wave_number(2.0, 9.81, kInf) == Approx(4.0 / 9.81).epsilon(1e-15));
  REQUIRE_THROWS_AS(wave_frequency(-1.0, 9.81, kInf), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wave_frequency(kNan, 9.81, 10.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wave_frequency(0.4, 0.0, 10.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wave_frequency(1e300, 1e10, kInf), kelp::invalid_argument);
  CHECK(wave_frequency(wave_number(1.3, 9.81, 12.0), 9.81, 12.0) == Approx(1.3).epsilon(1e-13));
  // DNV's γ needs a positive Hs and Tp.
  REQUIRE_THROWS_AS(dnv_peak_enhancement(0.0, 8.0), kelp::invalid_argument);
  CHECK(dnv_peak_enhancement(3.0, 4.5 * std::sqrt(3.0)) == Approx(std::exp(5.75 - 1.15 * 4.5)));
}

TEST_CASE("bad input: wave loads and encounter frequency", "[environment][bad_input]") {
  // g = 0 used to give ±Inf / NaN.
  REQUIRE_THROWS_AS(encounter_frequency(1.0, 0.0, 2.0, 0.3), kelp::invalid_argument);
  REQUIRE_THROWS_AS(encounter_frequency(kNan, 9.81, 2.0, 0.3), kelp::invalid_argument);
  REQUIRE_THROWS_AS(encounter_frequency(1.0, 9.81, kInf, 0.3), kelp::invalid_argument);
  REQUIRE_THROWS_AS(encounter_frequency(1.0, 9.81, 2.0, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(encounter_frequency(1e200, 9.81, 2.0, 0.0), kelp::invalid_argument);
  // Head sea (β = π): ω_e = ω + ω² U / g.
  CHECK(encounter_frequency(1.0, 9.81, 2.0, kelp::pi) == Approx(1.0 + 2.0 / 9.81));

  REQUIRE_THROWS_AS(paper_wave_parameter(1.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_parameter(-1.0, 10.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_parameter(1e300, 1e-300), kelp::invalid_argument);
  CHECK(paper_wave_parameter(0.5, 10.0) == Approx(0.1 * kelp::pi));
  REQUIRE_THROWS_AS(paper_wave_force(1e300, 9.81, 1.0, 1.0, 1.0, 0.5, 10.0),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_force(1025.0, 0.0, 1.0, 1.0, 1.0, 0.5, 10.0),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_force(1025.0, 9.81, kNan, 1.0, 1.0, 0.5, 10.0),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_force(1025.0, 9.81, 1e200, 1e200, 1.0, 0.5, 10.0),
                    kelp::invalid_argument);
  CHECK(paper_wave_force(1000.0, 10.0, 1.0, 2.0, 0.5, 0.5, 10.0) ==
        Approx(1000.0 * 10.0 * 1.0 * 2.0 * 0.5 * 0.1 * kelp::pi));

  PaperWave pw;
  pw.beam = 1.0;
  pw.length = 1.2;
  pw.draft = 0.1;
  pw.amplitude = 0.5;
  pw.wavelength = 20.0;
  CHECK(std::isfinite(paper_wave_load(pw, 12.0, 0.2, 1.0)(0)));
  REQUIRE_THROWS_AS(paper_wave_load(pw, kNan, 0.2, 1.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_load(pw, 12.0, kNan, 1.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wave_load(pw, 12.0, 0.2, kInf), kelp::invalid_argument);
  PaperWave dense = pw;
  dense.rho = 1e300;
  REQUIRE_THROWS_AS(validate(dense), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(validate(dense), Catch::Contains("rho") && Catch::Contains("1e+300"));
  PaperWave still_g = pw;
  still_g.gravity = 0.0;
  REQUIRE_THROWS_AS(paper_wave_load(still_g, 1.0, 0.0, 1.0), kelp::invalid_argument);

  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  const Vector3<double> ma(1.0, 2.0, 3.0), acc(0.1, 0.2, 0.3);
  CHECK(small_body_wave_force(1000.0, 0.01, ma, R, acc)(2) == Approx((1000.0 * 0.01 + 3.0) * 0.3));
  REQUIRE_THROWS_AS(small_body_wave_force(kNan, 0.01, ma, R, acc), kelp::invalid_argument);
  REQUIRE_THROWS_AS(small_body_wave_force(1000.0, -0.01, ma, R, acc), kelp::invalid_argument);
  REQUIRE_THROWS_AS(small_body_wave_force(1000.0, 0.01, ma, R, Vector3<double>(kNan, 0.0, 0.0)),
                    kelp::invalid_argument);
  const Eigen::VectorXd ma_wrong = Eigen::VectorXd::Ones(5);
  REQUIRE_THROWS_AS(small_body_wave_force(1000.0, 0.01, ma_wrong, R, acc), kelp::invalid_argument);

  SurfaceHydrostatics h;
  h.waterplane_area = 0.2;
  h.displaced_volume = 0.015;
  h.gm_transverse = 0.3;
  h.gm_longitudinal = 1.0;
  CHECK(wave_restoring(h, 0.0, 0.1, 0.0, 0.0)(2) == Approx(-h.rho * h.gravity * 0.2 * 0.1));
  SurfaceHydrostatics bad = h;
  bad.rho = 1e300;
  REQUIRE_THROWS_AS(wave_restoring(bad, 0.0, 0.1, 0.0, 0.0), kelp::invalid_argument);
  bad = h;
  bad.gm_transverse = kNan;
  REQUIRE_THROWS_AS(surface_following_restoring(bad, 0.0, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0),
                    kelp::invalid_argument);
  bad = h;
  bad.waterplane_area = -1.0;
  REQUIRE_THROWS_AS(validate(bad), kelp::invalid_argument);
}

TEST_CASE("bad input: wind spectra, fields and loads", "[environment][bad_input]") {
  REQUIRE_THROWS_AS(harris_spectrum(kNan, 10.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(harris_spectrum(0.1, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(harris_spectrum(0.1, 10.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(norsepp_spectrum(kNan, 10.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(norsepp_spectrum(0.1, 10.0, -10.0), kelp::invalid_argument);
  CHECK(harris_spectrum(0.0, 10.0) == 0.0);
  const double ft = 1800.0 * 0.1 / 10.0;
  CHECK(harris_spectrum(0.1, 10.0) ==
        Approx(4.0 * 0.0026 * 1800.0 * 10.0 / std::pow(2.0 + ft * ft, 5.0 / 6.0)));

  WindParameters wp;
  wp.speed = 1e300;
  wp.gust = GustSpectrum::harris;
  REQUIRE_THROWS_AS(WindField<double>(wp), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(WindField<double>(wp), Catch::Contains("wind speed"));
  wp.speed = 10.0;
  wp.f_max = 1e300;
  REQUIRE_THROWS_AS(WindField<double>(wp), kelp::invalid_argument);
  wp.f_max = 1.0;
  wp.n_components = 2'000'000'000;
  REQUIRE_THROWS_AS(WindField<double>(wp), kelp::invalid_argument);
  wp.n_components = 64;
  const WindField<double> wind(wp);
  REQUIRE_THROWS_AS(wind.speed(kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wind.velocity(kInf), kelp::invalid_argument);
  const double u = wind.speed(1234.5);
  CHECK(std::isfinite(u));
  CHECK(std::abs(u - 10.0) < 10.0 * 0.13 * 8.0);  // within 8 σ_u of the mean

  REQUIRE_THROWS_AS(paper_wind_force(1.225, kNan, 0.6, 0.15), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wind_force(0.0, 3.0, 0.6, 0.15), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wind_force(1e300, 3.0, 0.6, 0.15), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wind_force(1.225, 1e200, 0.6, 0.15), kelp::invalid_argument);
  REQUIRE_THROWS_AS(paper_wind_force_lateral(1.225, 3.0, 0.8, -0.25), kelp::invalid_argument);
  CHECK(paper_wind_force(1.2, 3.0, 0.5, 2.0) == Approx(0.5 * 1.2 * 9.0 * 0.5 * 2.0));

  ConstantWindCoefficients cc{0.6, 0.8, 0.1};
  WindAreas areas{0.15, 0.25, 1.2};
  const Vector3<double> w_ned(5.0, 0.0, 0.0);
  REQUIRE_THROWS_AS(wind_load(cc, areas, 1.225, w_ned, kNan, 0.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wind_load(cc, areas, 1.225, w_ned, 0.0, kNan, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wind_load(cc, areas, 1.225, Vector3<double>(kNan, 0.0, 0.0), 0.0, 0.0, 0.0),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(wind_load(cc, areas, -1.0, w_ned, 0.0, 0.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wind_load(cc, WindAreas{-1.0, 0.25, 1.2}, 1.225, w_ned, 0.0, 0.0, 0.0),
                    kelp::invalid_argument);
  const Eigen::VectorXd w_wrong = Eigen::VectorXd::Zero(2);
  REQUIRE_THROWS_AS(wind_load(cc, areas, 1.225, w_wrong, 0.0, 0.0, 0.0), kelp::invalid_argument);
  // Stern wind of 5 m/s on a vessel at rest heading north: u_rw = −5, γ_rw = π, C_X = c_x.
  const Vector3<double> f = wind_load(cc, areas, 1.225, w_ned, 0.0, 0.0, 0.0);
  CHECK(f(0) == Approx(0.5 * 1.225 * 25.0 * 0.6 * 0.15));
  REQUIRE_THROWS_AS(cc(kNan), kelp::invalid_argument);

  TabulatedWindCoefficients table;
  table.angle = {0.0, kelp::pi};
  table.cx = {-0.6, 0.6};
  table.cy = {0.0, 0.0};
  table.cn = {0.0, 0.0};
  CHECK(table(0.5 * kelp::pi)(0) == Approx(0.0).margin(1e-15));
  REQUIRE_THROWS_AS(table(kNan), kelp::invalid_argument);
  table.cx[1] = kNan;
  REQUIRE_THROWS_AS(validate(table), kelp::invalid_argument);
}

TEST_CASE("bad input: currents", "[environment][bad_input]") {
  REQUIRE_THROWS_AS(paper_current(kNan, 0.0, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(current_velocity_ned(1.0, kInf, 0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(current_velocity_ned(1.0, 0.0, kNan), kelp::invalid_argument);
  CHECK(current_velocity_ned(2.0, 0.0, 0.5 * kelp::pi)(1) == Approx(2.0));

  CurrentParameters cp;
  cp.speed = 1e300;
  REQUIRE_THROWS_AS(CurrentModel<double>(cp), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(CurrentModel<double>(cp), Catch::Contains("speed"));
  REQUIRE_THROWS_AS(CurrentModel<double>::constant(Vector3<double>(1e300, 0.0, 0.0)),
                    kelp::invalid_argument);
  const Eigen::VectorXd v_wrong = Eigen::VectorXd::Zero(4);
  REQUIRE_THROWS_AS(CurrentModel<double>::constant(v_wrong), kelp::invalid_argument);
  cp.speed = 0.5;
  cp.speed_variation.sigma = 1e300;
  REQUIRE_THROWS_AS(CurrentModel<double>(cp), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(CurrentModel<double>(cp), Catch::Contains("speed_variation"));
  cp.speed_variation.sigma = 0.001;
  cp.n_harmonics = 2'000'000'000;
  REQUIRE_THROWS_AS(CurrentModel<double>(cp), kelp::invalid_argument);
  cp.n_harmonics = 64;
  const CurrentModel<double> c(cp);
  REQUIRE_THROWS_AS(c.speed_at(kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(c.velocity(Vector3<double>(0.0, 0.0, 1.0), kInf), kelp::invalid_argument);
  CHECK(c.speed_at(100.0) == Approx(0.5).margin(0.1));
  // Far beyond the fast reduction's range (where wrap_two_pi gave garbage) the variation stays
  // finite and near its nominal value (128 harmonics of amplitude √(2σ²T/2/N)).
  const double v17 = c.speed_at(1e17);
  CHECK(std::isfinite(v17));
  CHECK(std::abs(v17 - 0.5) < 0.1);
  // A constant current at 50 m/s (the bound) is accepted.
  CHECK(CurrentModel<double>::constant(Vector3<double>(50.0, 0.0, 0.0)).speed_at(0.0) ==
        Approx(50.0));
}

TEST_CASE("bad input: environment setters", "[environment][bad_input]") {
  Environment<double> env;
  REQUIRE_THROWS_AS(env.set_water_density(1e300), kelp::invalid_argument);
  REQUIRE_THROWS_WITH(env.set_water_density(1e300),
                      Catch::Contains("water_density") && Catch::Contains("1e+300"));
  REQUIRE_THROWS_AS(env.set_water_density(0.0), kelp::invalid_argument);
  REQUIRE_THROWS_AS(env.set_air_density(1e300), kelp::invalid_argument);
  REQUIRE_THROWS_AS(env.set_gravity(1e300), kelp::invalid_argument);
  REQUIRE_THROWS_AS(env.set_gravity(kNan), kelp::invalid_argument);
  // The environment is unchanged by a refused setter; valid values pass.
  CHECK(env.water_density() == kelp::seawater_density);
  env.set_water_density(1000.0).set_air_density(1.2).set_gravity(9.81);
  CHECK(env.water_density() == 1000.0);
  CHECK(env.gravity() == 9.81);
  // make_environment refuses an absurd sea state by its field name.
  SeaState s = presets::moderate();
  s.wind_speed = 1e300;
  REQUIRE_THROWS_AS(make_environment<double>(s), kelp::invalid_argument);
  s = presets::moderate();
  s.peak_period = 1e-300;
  REQUIRE_THROWS_AS(make_environment<double>(s), kelp::invalid_argument);
  REQUIRE_NOTHROW(make_environment<double>(presets::rough()));
}

TEST_CASE("bad input: wave queries at non-finite times, huge times and far positions",
          "[environment][bad_input]") {
  const WaveField<double> w(sea());
  const WaveField<float> wf(sea());
  REQUIRE_THROWS_AS(w.elevation(0.0, 0.0, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(wf.elevation(0.0F, 0.0F, kInf), kelp::invalid_argument);
  REQUIRE_THROWS_AS(w.slope(0.0, 0.0, kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(w.kinematics(Vector3<double>(0.0, 0.0, 2.0), kNan), kelp::invalid_argument);
  REQUIRE_THROWS_AS(w.time_phase(0, kNan), kelp::invalid_argument);
  Matrix3X<double> pts(3, 5), vel(3, 5), acc(3, 5), vel_short(3, 4);
  pts.setZero();
  pts.row(2).setConstant(3.0);
  REQUIRE_THROWS_AS(w.kinematics(pts, kNan, vel, acc), kelp::invalid_argument);
  REQUIRE_THROWS_AS(w.kinematics(pts, 1.0, vel_short, acc), kelp::invalid_argument);
  Environment<double> env;
  env.set_waves(w);
  REQUIRE_THROWS_AS(env.sample_water(pts, kNan, vel, acc), kelp::invalid_argument);
  REQUIRE_THROWS_AS(env.surface_elevation(1.0, 2.0, kInf), kelp::invalid_argument);

  // t = 1e17 s: the fast kernel returned garbage there; now every query agrees with a
  // long-double evaluation (reduction of the same double phase), for double and float.
  double amp_sum = 0.0, acc_scale = 0.0;
  for (std::size_t j = 0; j < w.size(); ++j) {
    amp_sum += w.amplitude(j);
    acc_scale += w.amplitude(j) * w.omega(j) * w.omega(j);
  }
  for (const double t : {1e9, 3.7e12, 1e17, -2.5e16}) {
    INFO("t = " << t);
    const double x = 12.5, y = -3.25;
    const double ref = reference_elevation(w, x, y, t);
    CHECK(std::abs(w.elevation(x, y, t) - ref) <= 1e-9 * amp_sum);
    CHECK(std::abs(wf.elevation(static_cast<float>(x), static_cast<float>(y), t) - ref) <=
          1e-5 * amp_sum);
    const auto k = w.kinematics(Vector3<double>(x, y, 0.0), t);
    CHECK(std::abs(k.elevation - ref) <= 1e-9 * amp_sum);
    CHECK(k.velocity.allFinite());
    CHECK(k.acceleration.norm() <= acc_scale);
    const auto sl = w.slope(x, y, t);
    CHECK(sl.allFinite());
    for (std::size_t j = 0; j < w.size(); ++j) CHECK(std::abs(w.time_phase(j, t)) <= kelp::pi);
    // The batch path gives the single-point values.
    Matrix3X<double> p(3, 3), v(3, 3), a(3, 3);
    Eigen::VectorXd zeta(3);
    p << x, 0.0, -40.0, y, 5.0, 7.0, 0.0, 2.0, 30.0;
    w.kinematics(p, t, v, a, zeta);
    CHECK(std::abs(zeta(0) - ref) <= 1e-9 * amp_sum);
    for (int i = 0; i < 3; ++i) {
      const auto ki = w.kinematics(Vector3<double>(p.col(i)), t);
      CHECK((v.col(i) - ki.velocity).norm() <= 1e-12 * acc_scale);
      CHECK((a.col(i) - ki.acceleration).norm() <= 1e-12 * acc_scale);
    }
  }
  // Just inside the fast range the fast and exact paths agree (the switch is seamless).
  const double t_edge = 1e8 / w.omega(w.size() - 1);
  CHECK(std::abs(w.elevation(1.0, 2.0, t_edge) - reference_elevation(w, 1.0, 2.0, t_edge)) <=
        1e-7 * amp_sum);

  // Far from the origin (k_max (|x| + |y|) beyond 1e6 rad): bounded values that match the
  // reference, where fast_sincos alone would lose all accuracy.
  // The reference sums in long double: the difference is the rounding of the double phase,
  // ≲ 1e-7 rad at these distances.
  for (const double x : {1e7, -3e8}) {
    INFO("x = " << x);
    const double ref = reference_elevation(w, x, 0.5, 100.0);
    CHECK(std::abs(w.elevation(x, 0.5, 100.0) - ref) <= 1e-6 * amp_sum);
    const auto k = w.kinematics(Vector3<double>(x, 0.5, 0.0), 100.0);
    CHECK(std::abs(k.elevation - ref) <= 1e-6 * amp_sum);
    CHECK(k.acceleration.norm() <= acc_scale);
  }
  // Farther still the double phase itself is coarse, but the values stay bounded.
  for (const double x : {3e12, -1e15, 1e300}) {
    INFO("x = " << x);
    CHECK(std::abs(w.elevation(x, 0.5, 100.0)) <= amp_sum);
    const auto k = w.kinematics(Vector3<double>(x, 0.5, 0.0), 100.0);
    CHECK(std::abs(k.elevation) <= amp_sum);
    CHECK(k.acceleration.norm() <= acc_scale);
  }
  // A NaN position is not an exception (the tether reports it as a numerical error), it gives
  // NaN at that point only.
  pts(0, 1) = kNan;
  w.kinematics(pts, 10.0, vel, acc);
  CHECK(std::isnan(vel(0, 1)));
  CHECK(vel.col(0).allFinite());
  CHECK(vel.col(4).allFinite());
}

TEST_CASE("bad input: the exact phase reduction beyond the fast range",
          "[environment][bad_input]") {
  // reduce_phase agrees with wrap_two_pi inside its range and, far beyond it (where
  // wrap_two_pi's magic-number rounding no longer works), with the C library's sin and cos of x,
  // which reduce by a many-digit 2π: sin and cos of r both match, so r ≡ x (mod 2π) to 1e-15.
  for (const double x : {0.0, 3.0, -7.5, 1e5, 7.9e8}) {
    CHECK(kelp::simd::reduce_phase(x) == kelp::simd::wrap_two_pi(x));
  }
  for (const double x : {8.1e8, 1e12, 4.2e15, 1e17, -6.0e18, 1e300}) {
    INFO("x = " << x);
    const double r = kelp::simd::reduce_phase(x);
    CHECK(std::abs(r) <= kelp::pi);
    CHECK(std::cos(r) == Approx(std::cos(x)).margin(1e-15));
    CHECK(std::sin(r) == Approx(std::sin(x)).margin(1e-15));
  }
  // wrap_two_pi alone is what went wrong at t = 1e17 s (not even in [−π, π]).
  CHECK_FALSE(std::abs(kelp::simd::wrap_two_pi(4.2e17)) <= kelp::pi);
}

// The probe: profile_factor(p, NaN) returned NaN, though the header promises f ∈ [0, 1].
TEST_CASE("bad input: a current profile's factor at a NaN depth", "[environment][bad_input]") {
  for (const CurrentProfileKind kind :
       {CurrentProfileKind::uniform, CurrentProfileKind::power_law, CurrentProfileKind::linear}) {
    CurrentProfile p;
    p.kind = kind;
    p.depth = 40.0;
    p.bottom_ratio = 0.25;
    INFO("kind " << static_cast<int>(kind));
    REQUIRE_THROWS_AS(profile_factor(p, kNan), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(profile_factor(p, kNan), Catch::Contains("z"));
    REQUIRE_THROWS_AS(profile_factor(p, std::numeric_limits<float>::quiet_NaN()),
                      kelp::invalid_argument);
    // Every other depth, ±∞ included, has a factor in [0, 1]: 1 at and above the surface, the
    // seabed value (0 for the power law, r for the linear profile) at and below the seabed.
    for (const double z : {-kInf, -5.0, 0.0, 10.0, 20.0, 39.9, 40.0, 1e6, kInf}) {
      const double f = profile_factor(p, z);
      INFO("z " << z << " f " << f);
      CHECK(f >= 0.0);
      CHECK(f <= 1.0);
    }
    CHECK(profile_factor(p, -kInf) == 1.0);
    const double bottom = kind == CurrentProfileKind::uniform     ? 1.0
                          : kind == CurrentProfileKind::power_law ? 0.0
                                                                  : 0.25;
    CHECK(profile_factor(p, kInf) == bottom);
  }
}

// The probe: CurrentModel::velocity, the public query that applies the profile at a point,
// gave NaN for a NaN point where profile_factor refused it. It refuses a NaN point the same way
// (±∞ depths give the surface and seabed values, as profile_factor's); the per-node sampler of
// the tether step (Environment::sample_water) keeps its documented NaN for a NaN node, which the
// step reports as numerical_error with the state unchanged.
TEST_CASE("bad input: a current's velocity at a NaN point", "[environment][bad_input]") {
  CurrentParameters cp;
  cp.speed = 1.0;
  cp.profile.kind = CurrentProfileKind::power_law;
  cp.profile.depth = 40.0;
  const CurrentModel<double> c(cp);
  for (int i = 0; i < 3; ++i) {
    Vector3<double> p(0.0, 0.0, 5.0);
    p(i) = kNan;
    INFO("coordinate " << i);
    REQUIRE_THROWS_AS(c.velocity(p, 0.0), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(c.velocity(p, 0.0), Catch::Contains("must not be NaN"));
  }
  CHECK(c.velocity(Vector3<double>(0.0, 0.0, 20.0), 0.0)(0) == Approx(std::pow(0.5, 1.0 / 7.0)));
  CHECK(c.velocity(Vector3<double>(0.0, 0.0, -kInf), 0.0)(0) == 1.0);
  CHECK(c.velocity(Vector3<double>(0.0, 0.0, kInf), 0.0)(0) == 0.0);
  const CurrentModel<float> cf(cp);
  REQUIRE_THROWS_AS(
      cf.velocity(Vector3<float>(0.0F, 0.0F, std::numeric_limits<float>::quiet_NaN()), 0.0),
      kelp::invalid_argument);

  Environment<double> env;
  env.set_current(c);
  Matrix3X<double> pts(3, 3), vel(3, 3), acc(3, 3);
  pts << 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 5.0, kNan, 20.0;
  env.sample_water(pts, 0.0, vel, acc);  // the step's sampler: no exception, NaN at that node
  CHECK(std::isnan(vel(0, 1)));
  CHECK(vel.col(0).allFinite());
  CHECK(vel(0, 2) == Approx(std::pow(0.5, 1.0 / 7.0)));
}

// The probe: Environment::sample answered a NaN point with NaN values (in calm water with
// zeros). It is the public single-point query and refuses a point that is not finite (no depth,
// no wave phase); the vehicle steps sample their stages through sample_unchecked, so a stage
// that blows up still ends the step as numerical_error (tests/vehicle/test_bad_input_vehicle.cpp).
TEST_CASE("bad input: Environment::sample at a NaN or infinite point", "[environment][bad_input]") {
  const Environment<double> sea_env = make_environment<double>(presets::moderate());
  const Environment<double> calm;
  const Environment<float> sea_f = make_environment<float>(presets::moderate());
  for (const double bad : {kNan, kInf, -kInf})
    for (int i = 0; i < 3; ++i) {
      Vector3<double> p(10.0, -4.0, 3.0);
      p(i) = bad;
      INFO("coordinate " << i << " = " << bad);
      REQUIRE_THROWS_AS(sea_env.sample(p, 30.0), kelp::invalid_argument);
      REQUIRE_THROWS_WITH(sea_env.sample(p, 30.0, false), Catch::Contains("p_ned must be finite"));
      REQUIRE_THROWS_AS(calm.sample(p, 30.0), kelp::invalid_argument);
      REQUIRE_THROWS_AS(sea_f.sample(p.cast<float>(), 30.0), kelp::invalid_argument);
    }
  // The finite neighbours answer with finite values, and the unchecked sampler the steps use gives
  // the same numbers bit for bit.
  const Vector3<double> p(10.0, -4.0, 3.0);
  const EnvironmentSample<double> s = sea_env.sample(p, 30.0);
  CHECK(s.current.allFinite());
  CHECK(s.wave_velocity.allFinite());
  CHECK(s.wave_velocity.norm() > 0.0);
  CHECK(s.wind.allFinite());
  const EnvironmentSample<double> u = sea_env.sample_unchecked(p, 30.0, true);
  CHECK(u.current == s.current);
  CHECK(u.wave_velocity == s.wave_velocity);
  CHECK(u.wave_acceleration == s.wave_acceleration);
  CHECK(u.wave_velocity_gradient == s.wave_velocity_gradient);
  CHECK(u.surface_elevation == s.surface_elevation);
  CHECK(u.surface_slope == s.surface_slope);
  CHECK(u.wind == s.wind);
  CHECK(std::isnan(
      sea_env.sample_unchecked(Vector3<double>(kNan, 0.0, 3.0), 30.0, false).wave_velocity(0)));
}
