// The paper's formulas against hand-computed values, Fossen's 3-D current, current profiles and
// the bounded Gauss–Markov variation, wind gusts and wind loads, wave loads on small bodies and
// surface-following restoring, the sea-state presets, and the calm preset's zero forces.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "kelp/core/rotation.hpp"
#include "kelp/environment/current.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/paper.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/environment/wave_loads.hpp"
#include "kelp/environment/wind.hpp"

using kelp::Matrix3;
using kelp::Matrix3X;
using kelp::Vector3;
using kelp::Vector6;
using namespace kelp::environment;

TEMPLATE_TEST_CASE("the paper's formulas match hand-computed values", "[environment][paper]",
                   double, float) {
  using S = TestType;
  // eq:wave, BlueBoat-like box B = 1.0 m, L = 1.2 m, T = 0.1 m, A = 0.5 m, Λ = 20 m, ρ = 1025,
  // g = 9.81: k = 2π/20 · 0.5 = 0.1570796; F = 1025·9.81·1.0·1.2·0.1·0.1570796
  // = 1206.63 · 0.1570796 = 189.5370 N.
  CHECK(paper_wave_parameter(S(0.5), S(20)) == Approx(0.15707963).epsilon(1e-6));
  CHECK(paper_wave_force(S(1025), S(9.81), S(1.0), S(1.2), S(0.1), S(0.5), S(20)) ==
        Approx(189.5369972).epsilon(1e-6));
  // eq:wind: ½ · 1.225 · 3² · 0.9 · 0.3 = 0.6125 · 9 · 0.27 = 1.488375 N.
  CHECK(paper_wind_force(S(1.225), S(3), S(0.9), S(0.3)) == Approx(1.488375).epsilon(1e-6));
  // Lateral twin: ½ · 1.225 · 4² · 0.7 · 0.5 = 0.6125 · 16 · 0.35 = 3.43 N.
  CHECK(paper_wind_force_lateral(S(1.225), S(4), S(0.7), S(0.5)) == Approx(3.43).epsilon(1e-6));
  // eq:current: 0.5 · cos 0.1 · cos(π/4) = 0.5 · 0.9950042 · 0.7071068 = 0.3517871 m/s.
  CHECK(paper_current(S(0.5), S(0.1), S(kelp::pi / 4)) == Approx(0.3517871).epsilon(1e-6));
}

TEST_CASE("Fossen's 3-D current has speed V_c and the paper's north component",
          "[environment][current]") {
  for (const double a : {-0.3, 0.0, 0.2})
    for (const double b : {-2.0, 0.0, 0.7, 3.0}) {
      const Vector3<double> v = current_velocity_ned(0.8, a, b);
      CHECK(v.norm() == Approx(0.8).epsilon(1e-14));
      CHECK(v(0) == Approx(paper_current(0.8, a, b)).margin(1e-15));
    }
  // Horizontal current towards east: (0, V, 0).
  const Vector3<double> e = current_velocity_ned(1.0, 0.0, kelp::pi / 2);
  CHECK((e - Vector3<double>(0, 1, 0)).norm() < 1e-15);
  // The constant-current builder inverts the angles exactly.
  const Vector3<double> v0(0.3, -0.4, 0.05);
  CHECK((CurrentModel<double>::constant(v0).velocity(Vector3<double>(0, 0, 5), 0.0) - v0).norm() <
        1e-15);
  // Its direction is the azimuth the current flows towards, in every quadrant (south-west here:
  // atan2(−0.4, −0.3) = −2.2143 rad), with and without a vertical part.
  for (const Vector3<double>& vq :
       {Vector3<double>(-0.3, -0.4, 0.0), Vector3<double>(-0.3, 0.4, 0.1),
        Vector3<double>(0.0, -0.5, 0.0), Vector3<double>(0.0, 0.0, 0.2)}) {
    const auto c = CurrentModel<double>::constant(vq);
    CHECK((c.velocity(Vector3<double>(0, 0, 5), 0.0) - vq).norm() < 1e-15);
    const double beta = c.direction_at(0.0);
    if (vq(2) == 0.0 && vq.head<2>().norm() > 0) {
      CHECK(beta == Approx(std::atan2(vq(1), vq(0))).margin(1e-12));
    }
    // With a vertical part β is Fossen's angle, not exactly the horizontal azimuth, but it points
    // into the same horizontal quadrant (before the fix a westward current was reported eastward).
    CHECK(std::cos(beta) * vq(0) >= 0.0);
    CHECK(std::sin(beta) * vq(1) >= 0.0);
  }
}

TEST_CASE("current profiles: power law is zero at the seabed, linear reaches its ratio",
          "[environment][current]") {
  CurrentProfile pl;
  pl.kind = CurrentProfileKind::power_law;
  pl.depth = 30.0;
  CHECK(profile_factor(pl, 30.0) == 0.0);
  CHECK(profile_factor(pl, 35.0) == 0.0);
  CHECK(profile_factor(pl, 0.0) == 1.0);
  CHECK(profile_factor(pl, -1.0) == 1.0);
  // ((30 − 15)/30)^(1/7) = 0.5^(1/7) = 0.905724
  CHECK(profile_factor(pl, 15.0) == Approx(0.9057236643).epsilon(1e-9));
  double prev = 1.0;
  for (int i = 1; i <= 30; ++i) {
    const double f = profile_factor(pl, double(i));
    CHECK(f < prev);
    prev = f;
  }
  CurrentProfile li;
  li.kind = CurrentProfileKind::linear;
  li.depth = 20.0;
  li.bottom_ratio = 0.25;
  CHECK(profile_factor(li, 20.0) == Approx(0.25));
  CHECK(profile_factor(li, 10.0) == Approx(0.625));
  CurrentParameters p;
  p.speed = 1.2;
  p.direction = 0.4;
  p.profile = pl;
  const CurrentModel<double> c(p);
  CHECK(c.velocity(Vector3<double>(3, 4, 30.0), 10.0).norm() == 0.0);
  CHECK(c.velocity(Vector3<double>(3, 4, 0.0), 10.0).norm() == Approx(1.2));
  CHECK(c.velocity(Vector3<double>(3, 4, -0.5), 10.0).norm() == Approx(1.2));
}

TEST_CASE("the Gauss-Markov current stays within its bounds and is reproducible",
          "[environment][current]") {
  CurrentParameters p;
  p.speed = 0.5;
  p.direction = 1.0;
  p.speed_variation = {300.0, 0.02, 0.3, 0.7};
  p.direction_variation = {600.0, 0.01, 0.8, 1.2};
  p.seed = 5;
  const CurrentModel<double> a(p), b(p);
  p.seed = 6;
  const CurrentModel<double> c(p);
  double vmin = 1e9, vmax = -1e9, dmin = 1e9, dmax = -1e9, diff_ab = 0, diff_ac = 0;
  for (double t = 0; t <= 40000.0; t += 0.7) {
    const double v = a.speed_at(t), d = a.direction_at(t);
    vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    dmin = std::min(dmin, d), dmax = std::max(dmax, d);
    diff_ab = std::max(diff_ab, std::abs(v - b.speed_at(t)));
    diff_ac = std::max(diff_ac, std::abs(v - c.speed_at(t)));
    const Vector3<double> u = a.velocity(Vector3<double>(0, 0, 2), t);
    CHECK(u.norm() == Approx(v).epsilon(1e-12));
  }
  CHECK(vmin >= 0.3);
  CHECK(vmax <= 0.7);
  CHECK(dmin >= 0.8);
  CHECK(dmax <= 1.2);
  // It really varies: stationary std σ√(τ/2) = 0.02·12.2 = 0.24 m/s > half the band.
  CHECK(vmax - vmin > 0.3);
  CHECK(diff_ab == 0.0);
  CHECK(diff_ac > 0.05);
}

TEST_CASE("bad current and wind input throws naming the field", "[environment][current]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CurrentParameters p;
  p.speed = -0.1;
  CHECK_THROWS_WITH(CurrentModel<double>(p), Catch::Contains("speed"));
  p.speed = nan;
  CHECK_THROWS_AS(CurrentModel<double>(p), kelp::invalid_argument);
  p = CurrentParameters();
  p.profile.kind = CurrentProfileKind::power_law;  // no depth
  CHECK_THROWS_WITH(CurrentModel<double>(p), Catch::Contains("profile.depth"));
  p = CurrentParameters();
  p.speed = 1.0;
  p.speed_variation = {100.0, 0.1, 1.5, 2.0};  // nominal outside bounds
  CHECK_THROWS_WITH(CurrentModel<double>(p), Catch::Contains("speed_variation"));
  WindParameters w;
  w.speed = -3.0;
  CHECK_THROWS_WITH(WindField<double>(w), Catch::Contains("wind speed"));
  w.speed = 3.0;
  w.n_components = 0;
  CHECK_THROWS_WITH(WindField<double>(w), Catch::Contains("n_components"));
  w.n_components = 8;
  w.direction = nan;
  CHECK_THROWS_WITH(WindField<double>(w), Catch::Contains("direction"));
  PaperWave pw;
  pw.wavelength = 0.0;
  CHECK_THROWS_WITH(paper_wave_load(pw, 0.0, 0.0, 0.0), Catch::Contains("wavelength"));
}

TEST_CASE("Harris gusts carry the spectrum's variance and are reproducible",
          "[environment][wind]") {
  // ∫₀^∞ 4κLU/(2 + (Lf/U)²)^{5/6} df = 4κU² ∫₀^∞ (2 + x²)^{−5/6} dx
  // = 4κU² · 2^{−1/3} √π Γ(1/3) / (2 Γ(5/6)) = 4 · 0.0026 · 1.669369 U² = 0.0173614 U².
  // The band 1e-4..1 Hz at U = 10 m/s keeps x ∈ [0.018, 180]: the tails hold
  // ≈ (0.018·2^{−5/6} + 1.5·180^{−2/3}) / 1.669 ≈ 3.4 % of it.
  WindParameters p;
  p.speed = 10.0;
  p.direction = 0.5;
  p.gust = GustSpectrum::harris;
  p.n_components = 64;
  const WindField<double> w(p);
  const double total = 0.0173614 * 100.0;
  CHECK(w.gust_variance() == Approx(0.966 * total).epsilon(0.01));
  const WindField<double> w2(p);
  for (double t = 0; t < 100; t += 1.3) {
    CHECK(w.speed(t) == w2.speed(t));
    const Vector3<double> v = w.velocity(t);
    CHECK(v(2) == 0.0);
    CHECK(std::atan2(v(1), v(0)) == Approx(0.5));
  }
  // Mean of a long record ≈ U₁₀ (the gust has zero mean).
  double s = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) s += w.speed(0.5 * i);
  CHECK(s / n == Approx(10.0).epsilon(0.02));
  // NORSEPP at 10 m: S(f) at f = 0.01 Hz, U = 10: f̃ = 1.72, f̃^0.468 = 1.2889,
  // S = 320 / 2.2889^{3.5613} = 320 / 19.07 = 16.78 (m/s)²/Hz.
  CHECK(norsepp_spectrum(0.01, 10.0) == Approx(16.78).epsilon(2e-3));
  CHECK(WindField<double>().velocity(3.0).norm() == 0.0);
}

TEST_CASE("wind loads: the constant-coefficient model reduces to the paper's formula",
          "[environment][wind]") {
  const ConstantWindCoefficients c{0.9, 0.7, 0.1};
  const WindAreas areas{0.3, 0.5, 1.2};
  const double rho = 1.225;
  // Vessel at rest heading north; wind blowing south (from ahead) at 3 m/s: head wind, γ = 0.
  Vector3<double> f = wind_load(c, areas, rho, Vector3<double>(-3, 0, 0), 0.0, 0.0, 0.0);
  CHECK(f(0) == Approx(-paper_wind_force(rho, 3.0, 0.9, 0.3)));
  CHECK(std::abs(f(1)) < 1e-12);
  CHECK(std::abs(f(2)) < 1e-12);
  // Same relative wind from the vessel moving north at 3 m/s in still air.
  const Vector3<double> g = wind_load(c, areas, rho, Vector3<double>(0, 0, 0), 0.0, 3.0, 0.0);
  CHECK((f - g).norm() < 1e-12);
  // Beam wind from starboard (air moving towards port = −y body) pushes to port: Y < 0 equal to
  // the paper's lateral twin.
  f = wind_load(c, areas, rho, Vector3<double>(0, -4, 0), 0.0, 0.0, 0.0);
  CHECK(f(1) == Approx(-paper_wind_force_lateral(rho, 4.0, 0.7, 0.5)));
  CHECK(std::abs(f(0)) < 1e-12);
  // Heading east, wind towards east (following): pushes forward.
  f = wind_load(c, areas, rho, Vector3<double>(0, 2, 0), kelp::pi / 2, 0.0, 0.0);
  CHECK(f(0) == Approx(paper_wind_force(rho, 2.0, 0.9, 0.3)));
  // A table sampled from the constant model reproduces it at the nodes and interpolates between.
  TabulatedWindCoefficients t;
  for (int i = 0; i <= 18; ++i) {
    const double a = kelp::pi * i / 18;
    const Eigen::Vector3d ci = c(a);
    t.angle.push_back(a);
    t.cx.push_back(ci(0));
    t.cy.push_back(ci(1));
    t.cn.push_back(ci(2));
  }
  validate(t);
  for (const double a : {0.0, kelp::pi / 6, -kelp::pi / 3, kelp::pi})
    CHECK((t(a) - c(a)).norm() < 1e-12);
  CHECK((t(0.25) - c(0.25)).norm() < 0.01);  // linear interpolation over 10° steps
  const Vector3<double> ft = wind_load(t, areas, rho, Vector3<double>(1.0, -2.0, 0), 0.3, 0.5, 0.1);
  const Vector3<double> fc = wind_load(c, areas, rho, Vector3<double>(1.0, -2.0, 0), 0.3, 0.5, 0.1);
  CHECK((ft - fc).norm() < 0.02 * fc.norm());
  TabulatedWindCoefficients bad = t;
  bad.cy.pop_back();
  CHECK_THROWS_WITH(validate(bad), Catch::Contains("cx, cy, cn"));
  // A malformed table is refused at evaluation too, never read out of bounds.
  CHECK_THROWS_WITH(bad(0.3), Catch::Contains("cx, cy, cn"));
  CHECK_THROWS_AS(TabulatedWindCoefficients{}(0.3), kelp::invalid_argument);
}

TEST_CASE("the paper's wave load oscillates at the encounter frequency along the wave",
          "[environment][waves]") {
  PaperWave w;
  w.beam = 1.0, w.length = 1.2, w.draft = 0.1, w.amplitude = 0.5, w.wavelength = 20.0;
  w.rho = 1025, w.gravity = 9.81, w.direction = 0.0;
  const double f0 = 189.5369972;  // as in the hand-computed case above
  // At t = 0 the load is the full amplitude along the wave direction relative to the heading.
  Vector3<double> x = paper_wave_load(w, 0.0, 0.0, 0.0);
  CHECK(x(0) == Approx(f0).epsilon(1e-9));
  CHECK(std::abs(x(1)) < 1e-9);
  x = paper_wave_load(w, 0.0, -kelp::pi / 2, 0.0);  // heading west: wave from port side
  CHECK(x(1) == Approx(f0).epsilon(1e-9));
  // Zero speed: period 2π/ω, ω = √(2πg/Λ) = √(3.0819) = 1.75554 rad/s → T = 3.5791 s.
  const double T = 2 * kelp::pi / std::sqrt(2 * kelp::pi * 9.81 / 20.0);
  CHECK(paper_wave_load(w, T, 0.0, 0.0)(0) == Approx(f0).epsilon(1e-9));
  CHECK(paper_wave_load(w, T / 2, 0.0, 0.0)(0) == Approx(-f0).epsilon(1e-9));
  // Head sea (heading south, wave towards north) at U = 2 m/s: ω_e = ω + ω²U/g.
  const double om = 2 * kelp::pi / T, we = om + om * om * 2.0 / 9.81;
  CHECK(encounter_frequency(om, 9.81, 2.0, kelp::pi) == Approx(we));
  CHECK(paper_wave_load(w, kelp::pi / we, kelp::pi, 2.0)(0) == Approx(f0).epsilon(1e-9));
}

TEST_CASE("small-body wave force is (rho V + M_A) times the fluid acceleration",
          "[environment][waves]") {
  // BlueROV2 Heavy numbers (von Benzon et al. 2022, Table A1): ∇ = 0.0134 m³, added mass
  // 6.36/7.12/18.68 kg.
  const double rho = 1025, vol = 0.0134;
  const Vector3<double> ma(6.36, 7.12, 18.68);
  const Matrix3<double> R = kelp::rotation_zyx(0.0, 0.0, kelp::pi / 2);  // heading east
  const Vector3<double> a_ned(0.2, 0.0, -0.1);  // northwards = body port (−y)
  const Vector3<double> f = small_body_wave_force(rho, vol, ma, R, a_ned);
  // a_body = (0, −0.2, −0.1): F_y = −(13.735 + 7.12)·0.2 = −4.171, F_z = −(13.735 + 18.68)·0.1.
  CHECK(f(0) == Approx(0.0).margin(1e-12));
  CHECK(f(1) == Approx(-(rho * vol + 7.12) * 0.2).epsilon(1e-12));
  CHECK(f(2) == Approx(-(rho * vol + 18.68) * 0.1).epsilon(1e-12));
  const Matrix3<double> MA = ma.asDiagonal();
  CHECK((small_body_wave_force(rho, vol, MA, R, a_ned) - f).norm() < 1e-12);
}

TEST_CASE("surface-following restoring: a hull riding the surface feels nothing",
          "[environment][waves]") {
  SurfaceHydrostatics h;
  h.waterplane_area = 0.6, h.displaced_volume = 0.015, h.gm_transverse = 0.4,
  h.gm_longitudinal = 1.0;
  const double zeta = 0.3, sn = 0.05, se = -0.02, psi = 0.4;
  const auto att = surface_attitude(sn, se, psi);
  // Heave at the surface (z = −ζ) with the surface's roll and pitch: zero restoring.
  const Vector6<double> t0 =
      surface_following_restoring(h, -zeta, att(0), att(1), psi, zeta, sn, se);
  CHECK(t0.norm() < 1e-12);
  // Calm water: the wave part vanishes and the full form is the linear −Gη.
  CHECK(wave_restoring(h, psi, 0.0, 0.0, 0.0).norm() == 0.0);
  const Vector6<double> tc = surface_following_restoring(h, 0.02, 0.01, -0.02, psi, 0.0, 0.0, 0.0);
  CHECK(tc(2) == Approx(-1025 * 9.80665 * 0.6 * 0.02));
  // Full = calm + wave part.
  const Vector6<double> full = surface_following_restoring(h, 0.02, 0.01, -0.02, psi, zeta, sn, se);
  const Vector6<double> calm =
      surface_following_restoring(h, 0.02, 0.01, -0.02, psi, 0.0, 0.0, 0.0);
  CHECK((full - calm - wave_restoring(h, psi, zeta, sn, se)).norm() < 1e-9);
  // A crest under the hull lifts it (force up = negative NED z); a surface rising ahead pitches
  // the bow up (positive pitch moment) for a hull heading north.
  CHECK(wave_restoring(h, 0.0, 0.3, 0.0, 0.0)(2) < 0.0);
  CHECK(wave_restoring(h, 0.0, 0.0, 0.1, 0.0)(4) > 0.0);
  CHECK(wave_restoring(h, 0.0, 0.0, 0.0, 0.1)(3) < 0.0);  // rising to starboard: roll to port
}

TEST_CASE("sea-state presets follow the paper's table", "[environment][sea_state]") {
  const SeaState m = presets::moderate(), r = presets::rough(), c = presets::calm();
  CHECK(m.significant_height == 3.0);
  CHECK(m.peak_period == Approx(4.5 * std::sqrt(3.0)));
  CHECK(m.peak_enhancement == Approx(1.7771305269).epsilon(1e-9));  // exp(5.75 − 1.15·4.5)
  CHECK(m.wind_speed == 3.0);
  CHECK(m.current_speed == 0.5);
  CHECK(r.significant_height == 4.5);
  CHECK(r.wind_speed == 4.5);
  CHECK(r.current_speed == 1.0);
  CHECK(c.significant_height == 0.0);
  CHECK(dnv_peak_enhancement(4.0, 7.0) == 5.0);  // Tp/√Hs = 3.5
  CHECK(dnv_peak_enhancement(1.0, 6.0) == 1.0);  // 6
  const auto env = make_environment<double>(m);
  CHECK(env.waves().variance() == Approx(9.0 / 16).epsilon(0.01));
  CHECK(env.wind().parameters().speed == 3.0);
  const auto s = env.sample(Vector3<double>(0, 0, 5), 0.0);
  CHECK(s.current.norm() == Approx(0.5));
  CHECK(std::atan2(s.current(1), s.current(0)) == Approx(kelp::pi / 4));
  CHECK(s.wave_velocity.norm() > 0.0);
  const auto env_r = make_environment<double>(r);
  CHECK(env_r.waves().variance() == Approx(4.5 * 4.5 / 16).epsilon(0.01));
}

TEST_CASE("a vehicle in the calm preset feels zero environmental force",
          "[environment][sea_state]") {
  const auto env = make_environment<double>(presets::calm());
  CHECK(env.waves().empty());
  // BlueBoat-like ASV at the surface, BlueROV2-like AUV at 10 m, over a minute.
  const WindAreas boat_areas{0.25, 0.45, 1.2};
  const ConstantWindCoefficients boat_c{0.9, 0.8, 0.1};
  SurfaceHydrostatics boat;
  boat.waterplane_area = 0.55, boat.displaced_volume = 0.015, boat.gm_transverse = 0.5,
  boat.gm_longitudinal = 1.2;
  const Vector3<double> rov_ma(6.36, 7.12, 18.68);
  for (double t = 0; t < 60; t += 0.37) {
    const auto asv = env.sample(Vector3<double>(1, 2, 0.0), t);
    const auto auv = env.sample(Vector3<double>(1, 2, 10.0), t);
    const Vector3<double> wind =
        wind_load(boat_c, boat_areas, env.air_density(), asv.wind, 0.3, 0.0, 0.0);
    const Vector6<double> restoring =
        wave_restoring(boat, 0.3, asv.surface_elevation, env.surface_slope(1, 2, t)(0),
                       env.surface_slope(1, 2, t)(1));
    const Vector3<double> fk = small_body_wave_force(
        env.water_density(), 0.0134, rov_ma, Matrix3<double>::Identity(), auv.wave_acceleration);
    CHECK(wind.norm() == 0.0);
    CHECK(restoring.norm() == 0.0);
    CHECK(fk.norm() == 0.0);
    CHECK(asv.current.norm() == 0.0);
    CHECK(auv.current.norm() == 0.0);
    CHECK(auv.wave_velocity.norm() == 0.0);
  }
  PaperWave pw;  // calm: zero amplitude
  pw.beam = 1.0, pw.length = 1.2, pw.draft = 0.1, pw.wavelength = 20.0;
  CHECK(paper_wave_load(pw, 3.0, 0.2, 1.0).norm() == 0.0);
}

TEMPLATE_TEST_CASE("the full environment's batch query matches sample() without allocating",
                   "[environment]", double, float) {
  using S = TestType;
  SeaStateOptions o;
  o.spreading = 1.0;
  o.seabed_depth = 40.0;
  auto env = make_environment<S>(presets::rough(), o);
  CurrentParameters cp;
  cp.speed = 0.8;
  cp.direction = 0.3;
  cp.profile.kind = CurrentProfileKind::power_law;
  cp.profile.depth = 40.0;
  env.set_current(CurrentModel<S>(cp));
  const int n = 50;
  Matrix3X<S> pts(3, n), vel(3, n), acc(3, n);
  for (int i = 0; i < n; ++i) pts.col(i) << S(0.2 * i), S(0.1 * i), S(-0.5 + 0.4 * i);
  pts(2, 0) = S(-20);  // in the air
  Matrix3X<S> vel2(3, n), acc2(3, n);
  kelp::VectorX<S> zeta(n);
  Eigen::internal::set_is_malloc_allowed(false);
  env.sample_water(pts, S(7.0), vel, acc);
  env.sample_water(pts, S(7.0), vel2, acc2, zeta);
  const auto probe = env.sample(Vector3<S>(pts.col(3)), S(7.0));
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(probe.wind.norm() > S(0));
  int above = 0;
  for (int i = 0; i < n; ++i) {
    const auto s = env.sample(Vector3<S>(pts.col(i)), S(7.0));
    CHECK((vel.col(i) - s.current - s.wave_velocity).norm() <= S(1e-5));
    CHECK((acc.col(i) - s.wave_acceleration).norm() <= S(1e-5));
    CHECK(s.surface_elevation ==
          Approx(env.surface_elevation(pts(0, i), pts(1, i), S(7.0))).margin(1e-5));
    // The query with elevations: the same kinematics, and ζ at every point, deep ones too.
    CHECK((vel2.col(i) - vel.col(i)).norm() == S(0));
    CHECK((acc2.col(i) - acc.col(i)).norm() == S(0));
    CHECK(zeta(i) == Approx(env.surface_elevation(pts(0, i), pts(1, i), S(7.0))).margin(1e-5));
    above += pts(2, i) < -zeta(i);
  }
  CHECK(above >= 1);  // the first point is above the surface: no orbital motion there
  CHECK(vel2.col(0).norm() == Approx(env.current().velocity(Vector3<S>(pts.col(0)), 7.0).norm()));
  kelp::VectorX<S> short_zeta(n - 1);
  CHECK_THROWS_AS(env.sample_water(pts, S(7.0), vel2, acc2, short_zeta), kelp::invalid_argument);
}
