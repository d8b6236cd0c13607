// TetherParameters::line_model: LineModel::moordyn changes exactly what it says (no added-mass
// rate terms, a dashpot that pushes, seabed damping at once), and with it kelp reproduces MoorDyn
// v2.7.1's stored results on the validation cases (tests/tether/moordyn_cases.hpp; results in
// moordyn_reference.hpp, written by benchmarks/moordyn/side_by_side.cpp --write-reference),
// while kelp's default line differs from them by the effects of those terms.
#include <catch2/catch.hpp>
#include <cmath>
#include <iterator>

#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "moordyn_cases.hpp"
#include "moordyn_reference.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
namespace mc = moordyn_cases;
namespace mr = moordyn_reference;

namespace {

// A line of 8 segments, deep, stretched by 1 % along a bent path (every segment taut, so that
// the clamp plays no part), moving with arbitrary velocities in a current.
struct MovingLine {
  kelp_test::TestWater<double> env;
  kelp::Matrix3X<double> x, v;
  MovingLine() : x(3, 9), v(3, 9) {
    env.current = kelp::Vector3<double>(0.4, -0.2, 0.1);
    // An arc of radius 10 m with chords of 1.01 m (1 % strain), 30 m down.
    const double phi = 2 * std::asin(0.505 / 10.0);
    for (int i = 0; i <= 8; ++i) {
      x.col(i) = kelp::Vector3<double>(10 * std::sin(i * phi), 10 * (1 - std::cos(i * phi)), 30);
      v.col(i) =
          kelp::Vector3<double>(0.3 * std::sin(1.3 * i), 0.2 * std::cos(0.7 * i), -0.1 + 0.05 * i);
    }
  }
  static kt::TetherParametersd params(double cat, kt::LineModel lm) {
    kt::TetherParametersd p = kelp_test::benchmark_line<double>(8);
    p.length = 8.0;
    p.internal_damping = 10.0;
    p.tangential_added_mass = cat;
    p.line_model = lm;
    return p;
  }
  // compute_forces' node forces with Cat = cat, and the workspace's tangential added masses.
  kelp::Matrix3X<double> forces(double cat, kt::LineModel lm, double scale = 1.0,
                                kelp::VectorX<double>* mass_tan = nullptr) {
    const kt::TetherModeld m(params(cat, lm));
    kt::TetherWorkspaced ws(m);
    kelp_test::TestWater<double> e = env;
    e.current *= scale;
    kt::compute_forces(m, ws, e, 0.0, x, kelp::Matrix3X<double>(scale * v));
    for (int s = 0; s < 8; ++s) REQUIRE(ws.tension(s) > 0.0);  // all taut: no clamp at play
    if (mass_tan) *mass_tan = ws.mass_tan;
    return ws.force;
  }
};

kelp::Matrix3X<double> nodes(const double (*a)[3], int n) {
  kelp::Matrix3X<double> m(3, n + 1);
  for (int i = 0; i <= n; ++i) m.col(i) = kelp::Vector3<double>(a[i][0], a[i][1], a[i][2]);
  return m;
}

// The stored MoorDyn series of a case as an mc::Series (tension, mid x, mid z).
template <std::size_t N>
mc::Series stored(const double (&a)[N][3]) {
  mc::Series s;
  for (std::size_t i = 0; i < N; ++i) {
    s.tension.push_back(a[i][0]);
    s.mid_x.push_back(a[i][1]);
    s.mid_z.push_back(a[i][2]);
  }
  return s;
}

struct Agreement {
  double tension_rms, mid_node;
};

Agreement compare(const mc::Case& c, const kt::TetherParametersd& p,
                  const kelp::Matrix3X<double>& x0, const mc::Series& ref) {
  const mc::Series k = mc::run_kelp(c, p, x0);
  REQUIRE(k.tension.size() == ref.tension.size());
  return {mc::relative_rms(k.tension, ref.tension),
          mc::max_distance(k.mid_x, k.mid_z, ref.mid_x, ref.mid_z)};
}

}  // namespace

TEST_CASE("LineModel::moordyn removes exactly the added-mass rate terms", "[tether][moordyn]") {
  MovingLine line;
  const auto kelp_model = kt::LineModel::kelp, moordyn = kt::LineModel::moordyn;
  // In a uniform current (no water acceleration, so no Froude–Krylov term) Cat enters the node
  // forces only through the rate terms, whose factor Cat − Can vanishes for Cat = Can: MoorDyn's
  // line with Cat = 0.5 gives the forces of either line with Cat = Can = 1.
  kelp::VectorX<double> tan_kelp, tan_moordyn;
  const kelp::Matrix3X<double> f_md = line.forces(0.5, moordyn, 1.0, &tan_moordyn);
  const kelp::Matrix3X<double> f_iso = line.forces(1.0, kelp_model);
  CHECK((f_md - f_iso).cwiseAbs().maxCoeff() <= 1e-12 * f_iso.cwiseAbs().maxCoeff());
  CHECK((line.forces(1.0, moordyn) - f_iso).cwiseAbs().maxCoeff() == 0.0);
  // kelp's line with Cat = 0.5 differs by its rate terms G(Cat − Can, v_r): quadratic in the
  // relative velocities and linear in Cat − Can, ...
  const kelp::Matrix3X<double> g = line.forces(0.5, kelp_model, 1.0, &tan_kelp) - f_md;
  REQUIRE(g.cwiseAbs().maxCoeff() > 1e-4);  // [N], beside node forces of ~1e3 N
  const kelp::Matrix3X<double> g2 =
      line.forces(0.5, kelp_model, 2.0) - line.forces(0.5, moordyn, 2.0);
  CHECK((g2 - 4.0 * g).cwiseAbs().maxCoeff() <= 1e-6 * g.cwiseAbs().maxCoeff());
  const kelp::Matrix3X<double> g0 = line.forces(0.0, kelp_model) - line.forces(0.0, moordyn);
  CHECK((g0 - 2.0 * g).cwiseAbs().maxCoeff() <= 1e-6 * g.cwiseAbs().maxCoeff());
  // ... while the added mass itself (M_i = a I + b q qᵀ) is the same in both line models.
  CHECK((tan_kelp - tan_moordyn).cwiseAbs().maxCoeff() == 0.0);
  CHECK(tan_kelp.cwiseAbs().maxCoeff() > 0.0);
  // The model says which it uses.
  CHECK(kt::TetherModeld(MovingLine::params(0.5, kelp_model)).added_mass_rate_terms());
  CHECK_FALSE(kt::TetherModeld(MovingLine::params(0.5, moordyn)).added_mass_rate_terms());
  CHECK_FALSE(kt::TetherModeld(MovingLine::params(1.0, kelp_model)).added_mass_rate_terms());
}

TEST_CASE("LineModel::moordyn: the dashpot pushes, and the seabed damps from first contact",
          "[tether][moordyn]") {
  kelp_test::TestWater<double> env;
  env.bed = 40.0;
  auto p = kelp_test::benchmark_line<double>(2);
  p.length = 2.0;
  p.internal_damping = 50.0;
  p.normal_drag = p.tangential_drag = 0.0;
  auto md = p;
  md.line_model = kt::LineModel::moordyn;
  auto cd = p;
  cd.compressive_damping = true;
  const kt::TetherModeld m_kelp(p), m_md(md), m_cd(cd);
  // MoorDyn's implications are resolved in the model's parameters; the user's are left alone.
  CHECK(m_md.parameters().compressive_damping);
  CHECK(m_md.parameters().seabed_damping_depth == 0.0);
  CHECK(m_md.parameters().line_model == kt::LineModel::moordyn);
  CHECK_FALSE(md.compressive_damping);
  CHECK_FALSE(m_kelp.parameters().compressive_damping);
  CHECK(m_kelp.parameters().seabed_damping_depth == p.seabed_damping_depth);
  kt::TetherWorkspaced ws_kelp(m_kelp), ws_md(m_md), ws_cd(m_cd);
  // Segment 0 slack (0.99 m of 1 m) and shortening at 0.1 m/s: ε̇ = −0.1 /s, so MoorDyn's axial
  // force is BA ε̇ = −5 N (a push); kelp's is clamped at 0. Node 1 is 0.1 mm into the bed and
  // sinking at 1 mm/s: inside kelp's 1 mm damping ramp.
  kelp::Matrix3X<double> x(3, 3), v = kelp::Matrix3X<double>::Zero(3, 3);
  x << 0, 0.99, 1.99, 0, 0, 0, 39.9999, 40.0001, 39.9999;
  x(0, 2) = x(0, 1) + std::sqrt(1.0 - 2e-4 * 2e-4) * 1.0005;  // segment 1 taut
  v(0, 1) = -0.1;
  v(2, 1) = 1e-3;
  v(0, 2) = -0.1;
  kt::compute_forces(m_kelp, ws_kelp, env, 0.0, x, v);
  kt::compute_forces(m_md, ws_md, env, 0.0, x, v);
  kt::compute_forces(m_cd, ws_cd, env, 0.0, x, v);
  const kelp::Vector3<double> d = x.col(1) - x.col(0), dv = v.col(1) - v.col(0);
  const double push = 50.0 * d.dot(dv) / (d.norm() * 1.0);  // BA ε̇ with l = 1 m
  REQUIRE(push < -4.0);
  CHECK(ws_kelp.tension(0) == 0.0);
  CHECK(ws_md.tension(0) == Approx(push).epsilon(1e-12));
  CHECK(ws_cd.tension(0) == ws_md.tension(0));
  // Seabed under node 1: (z − h) kb d l + ż cb d l in MoorDyn's line (l = 1 m), the damping
  // scaled by the penetration / 1 mm ramp in kelp's.
  const double spring = 1e-4 * 3e6 * 0.008, damper = 1e-3 * 3e5 * 0.008;
  CHECK(ws_md.seabed_force(1) == Approx(spring + damper).epsilon(1e-9));
  CHECK(ws_kelp.seabed_force(1) == Approx(spring + 0.1 * damper).epsilon(1e-6));
}

TEST_CASE("line_model is validated", "[tether][moordyn][errors]") {
  auto p = kelp_test::benchmark_line<double>(4);
  p.line_model = static_cast<kt::LineModel>(5);
  CHECK_THROWS_AS(kt::TetherModeld(p), kelp::invalid_argument);
  CHECK_THROWS_WITH(kt::validate(p), Catch::Contains("line_model"));
}

TEST_CASE("with LineModel::moordyn kelp reproduces MoorDyn v2.7.1's surge and snap loads",
          "[tether][moordyn]") {
  // Measured (x86-64, g++ 12): end-segment force RMS difference / RMS 4.5e-9 (surge) and 8.6e-13
  // (snap), mid node within 1.4e-12 m; kelp's default line 2.6e-3 and 1.7e-2 (3.8 mm and
  // 0.12 m); the default line with compressive_damping only 2.6e-3 and 1.1e-3.
  const mc::Series surge_ref = stored(mr::surge_series), snap_ref = stored(mr::snap_series);
  const kelp::Matrix3X<double> surge_x0 = nodes(mr::surge_x0, mc::surge.segments);
  const kelp::Matrix3X<double> snap_x0 = nodes(mr::snap_x0, mc::snap.segments);
  const auto md = kt::LineModel::moordyn, kelp_model = kt::LineModel::kelp;

  const Agreement surge = compare(mc::surge, mc::parameters(mc::surge, md), surge_x0, surge_ref);
  CHECK(surge.tension_rms <= 2e-4);
  CHECK(surge.mid_node <= 1e-6);
  const Agreement snap = compare(mc::snap, mc::parameters(mc::snap, md), snap_x0, snap_ref);
  CHECK(snap.tension_rms <= 1e-3);
  CHECK(snap.mid_node <= 1e-6);

  // kelp's default line is a different model: the rate terms alone move the surge tension by
  // ~2.6e-3 of its RMS; in the snap loads the clamp dominates (1.7e-2), the rate terms leave
  // ~1.1e-3 once the dashpot may push.
  const Agreement surge_kelp =
      compare(mc::surge, mc::parameters(mc::surge, kelp_model), surge_x0, surge_ref);
  CHECK(surge_kelp.tension_rms > 1e-3);
  const Agreement snap_kelp =
      compare(mc::snap, mc::parameters(mc::snap, kelp_model), snap_x0, snap_ref);
  CHECK(snap_kelp.tension_rms > 1e-2);
  auto pushing = mc::parameters(mc::snap, kelp_model);
  pushing.compressive_damping = true;
  const Agreement snap_pushing = compare(mc::snap, pushing, snap_x0, snap_ref);
  CHECK(snap_pushing.tension_rms > 1e-4);
  CHECK(snap_pushing.tension_rms < snap_kelp.tension_rms / 5);
}

TEST_CASE("with LineModel::moordyn kelp's static shape in a current is MoorDyn v2.7.1's",
          "[tether][moordyn][statics]") {
  const mc::Case& c = mc::current;
  const kelp::Matrix3X<double> ref = nodes(mr::current_nodes, c.segments);
  const auto shape = [&](kt::LineModel lm) {
    const kt::TetherModeld model(mc::parameters(c, lm));
    kt::TetherWorkspaced ws(model);
    kt::TetherStated st(model);
    kt::StaticOptionsd o;
    o.force_tolerance = 1e-8;  // [N]
    o.max_iterations = 5000;
    const auto r = kt::static_initial_state(
        model, ws, mc::environment(c), kelp::Vector3<double>(c.start[0], c.start[1], c.start[2]),
        kelp::Vector3<double>(c.end[0], c.end[1], c.end[2]), st, o);
    REQUIRE(r.converged);
    return kelp::Matrix3X<double>(st.position);
  };
  // Measured: 2.0e-8 m with MoorDyn's line; 7.4e-3 m with kelp's (the rate terms in a steady
  // flow along a curved line: the fluid's "centrifugal" force).
  CHECK((shape(kt::LineModel::moordyn) - ref).colwise().norm().maxCoeff() <= 1e-6);
  CHECK((shape(kt::LineModel::kelp) - ref).colwise().norm().maxCoeff() > 1e-3);
}
