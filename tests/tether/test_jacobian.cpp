// The whole Jacobian of the tether's node forces (kelp/tether/jacobian.hpp) against central
// finite differences of compute_forces with the water held, block by block, on randomised
// states that cover every branch: wet interior nodes, ends (kinematic and free), the surface
// band, nodes in air, seabed contact (spring, ramped damper, friction sliding and sticking,
// with and without the frozen normal force), taut, slack and clamped segments with a dashpot,
// a segment folded below the dashpot's fade length, compressive damping, bending, Cat ≠ Can
// (added-mass rate terms). Also: the check can fail (the symmetric approximation the implicit steps
// used so far is rejected), and the whole Newton matrix's factor/solve against a dense solve.
#include <Eigen/Dense>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/jacobian.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/tether/whole_newton.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Matrix3X;
using kelp::Vector3;

namespace {

using Mat = Eigen::MatrixXd;

struct Config {
  bool free_start = false, free_end = false, compressive = false, frozen_friction = false;
  // Segment 5 folded to 0.5 … 0.9 of the dashpot's fade length (TetherModel::dashpot_fade),
  // stretching (its dashpot pulling).
  bool fold = false;
  double bending = 0.5, cat = 0.3, damping = 20.0;
  // The line parted at this segment (TetherState::parted; -1: intact).
  int parted = -1;
  // Both ends clamped (EndMotion::direction) in random directions.
  bool clamp = false;
};

// A short, soft, thick line (so that drag, added mass and the band are not swamped by the axial
// stiffness in the comparison): 12 segments of 0.2 m, d 5 cm, EA 1e3 N, BA 20 N s.
kt::TetherParameters<double> test_line(const Config& c) {
  kt::TetherParameters<double> p;
  p.segments = 12;
  p.length = 2.4;
  p.diameter = 0.05;
  p.mass_per_length = 0.5;
  p.axial_stiffness = 1e3;
  p.internal_damping = c.damping;
  p.compressive_damping = c.compressive;
  p.bending_stiffness = c.bending;
  p.tangential_drag = 0.1;
  p.normal_added_mass = 1.0;
  p.tangential_added_mass = c.cat;
  p.seabed_stiffness = 1e5;
  p.seabed_damping = 1e4;
  p.seabed_damping_depth = 0.01;
  p.seabed_friction = 0.4;
  p.friction_velocity = 0.05;
  p.start_mode = c.free_start ? kt::EndMode::free : kt::EndMode::kinematic;
  p.end_mode = c.free_end ? kt::EndMode::free : kt::EndMode::kinematic;
  p.start_point_mass = 0.3;
  p.end_point_mass = 0.2;
  return p;
}

// A random state of the line: a wavy line of segments 0.85 … 1.15 l long (taut and slack),
// nodes 0–3 in air or in the surface band, the last three on the seabed (penetration inside
// and beyond the damper's ramp), random velocities (some nodes on the bed below the friction
// velocity), random water velocity, acceleration and surface elevation, held.
struct Scene {
  kt::TetherModel<double> model;
  kt::TetherWorkspace<double> ws;
  kelp_test::TestWater<double> env;
  Matrix3X<double> x, v, d;
  Scene(const Config& c, unsigned seed) : model(test_line(c)), ws(model) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int n = model.segments();
    const double l = model.segment_length(), diam = model.parameters().diameter;
    env.bed = 3.0;
    x.resize(3, n + 1);
    v.resize(3, n + 1);
    d.resize(3, n + 1);
    Vector3<double> p(0.0, 0.0, 0.0);
    for (int i = 0; i <= n; ++i) {
      if (i > 0) {
        Vector3<double> dir(1.0, 0.4 * u(rng), 0.4 * u(rng) + 0.35);
        dir.normalize();
        double length = l * (1.0 + 0.15 * u(rng));
        if (c.fold && i == 6) length = model.dashpot_fade_length() * (0.5 + 0.4 * std::abs(u(rng)));
        p += length * dir;
      }
      x.col(i) = p;
      for (int k = 0; k < 3; ++k) {
        v(k, i) = 0.5 * u(rng);
        d(k, i) = 0.3 * u(rng);
        ws.water_velocity(k, i) = 0.6 * u(rng);
        ws.water_acceleration(k, i) = 0.8 * u(rng);
      }
      ws.surface_elevation(i) = 0.02 * u(rng);
    }
    if (c.fold) {
      const Vector3<double> dir = (x.col(6) - x.col(5)).normalized();
      v.col(6) += (0.3 + 0.2 * std::abs(u(rng)) - dir.dot(v.col(6) - v.col(5))) * dir;
    }
    // Surface: nodes 0 and 1 in air (node 0's half segment wholly dry), nodes 2 and 3 in the band
    // (well inside it), node 4 deeper: segments 1 to 3 are partly wet, and the wet share of nodes
    // 1 to 4 depends on their neighbours' depths.
    for (int i : {0, 1}) x(2, i) = -ws.surface_elevation(i) - diam * (0.6 + 0.3 * std::abs(u(rng)));
    for (int i : {2, 3}) x(2, i) = -ws.surface_elevation(i) + 0.3 * diam * u(rng);
    // Seabed: the last three nodes lie on it, one inside the damper's ramp.
    const double depth = model.parameters().seabed_damping_depth;
    x(2, n - 2) = env.bed + depth * (1.5 + std::abs(u(rng)));
    x(2, n - 1) = env.bed + depth * (0.2 + 0.6 * std::abs(u(rng)));
    x(2, n) = env.bed + depth * (2.0 + std::abs(u(rng)));
    // Landing slowly (the damper pushes), one node sticking (|v_h| < v_f).
    v(2, n - 1) = 0.05 + 0.05 * std::abs(u(rng));
    v(2, n - 2) = 0.02 * u(rng);
    v(2, n) = 0.02 * u(rng);
    v(0, n) = 0.01 * u(rng);
    v(1, n) = 0.01 * u(rng);
    if (c.frozen_friction) {
      ws.frozen_friction = true;
      for (int i = 0; i <= n; ++i) ws.friction_normal(i) = 3.0 * std::abs(u(rng));
    }
    ws.water_frozen = true;
    ws.water_is_zero = false;
    if (c.parted >= 0) {
      kt::TetherState<double> st(model);
      st.parted(c.parted) = 1;
      kt::detail::load_parted(st, ws);
    }
    if (c.clamp) {
      kt::TetherBoundary<double> b;
      b.start.direction = Vector3<double>(1.0, 0.5 * u(rng), 0.5 * u(rng));
      b.end.direction = Vector3<double>(-1.0, 0.5 * u(rng), 0.5 * u(rng));
      kt::detail::load_clamps(model, b, ws);
    }
  }
  // compute_forces at (xx, vv); returns the forces and M_i d_i per node.
  void forces(const Matrix3X<double>& xx, const Matrix3X<double>& vv, Matrix3X<double>& f,
              Matrix3X<double>& md) {
    kt::compute_forces<true>(model, ws, env, 0.0, xx, vv);
    f = ws.force;
    md.resize(3, model.nodes());
    for (int i = 0; i < model.nodes(); ++i) {
      const Vector3<double> q = ws.tangent.col(i);
      md.col(i) = ws.mass_iso(i) * d.col(i) + ws.mass_tan(i) * q.dot(d.col(i)) * q;
    }
  }
  // Which branch every kink of compute_forces is on (so that a difference across a kink is not
  // taken for a derivative).
  std::vector<int> signature(const Matrix3X<double>& vv) const {
    std::vector<int> s;
    const kt::TetherParameters<double>& p = model.parameters();
    for (int k = 0; k < model.segments(); ++k) {
      const double r = ws.direction.col(k).dot(vv.col(k + 1) - vv.col(k));
      s.push_back(int(
          kt::detail::segment_branch(model, ws.stretched_length(k) - model.segment_length(), r)));
    }
    for (int i = 0; i < model.nodes(); ++i) {
      const double phi = ws.submerged(i);
      s.push_back(phi <= 0.0 ? 0 : (phi >= 1.0 ? 2 : 1));
      s.push_back(ws.seabed_force(i) > 0.0);
      s.push_back(x(2, i) - env.bed < p.seabed_damping_depth);
      s.push_back(vv.col(i).head<2>().norm() > p.friction_velocity);
    }
    return s;
  }
};

// Finite-difference Jacobians (3(N+1) × 3(N+1)): of F in x and v, of M(x) d in x; the columns
// whose ±h differences straddle a kink are flagged.
struct Differences {
  Mat fx, fv, mx;
  std::vector<bool> x_ok, v_ok;
};

Differences finite_differences(Scene& sc, double h) {
  const int nodes = sc.model.nodes(), m = 3 * nodes;
  Differences out{Mat::Zero(m, m), Mat::Zero(m, m), Mat::Zero(m, m), std::vector<bool>(m, true),
                  std::vector<bool>(m, true)};
  Matrix3X<double> fp, fm, mp, mm;
  sc.forces(sc.x, sc.v, fp, mp);
  const std::vector<int> base = sc.signature(sc.v);
  for (int which = 0; which < 2; ++which)
    for (int c = 0; c < m; ++c) {
      Matrix3X<double> xx = sc.x, vv = sc.v;
      Matrix3X<double>& z = which == 0 ? xx : vv;
      z(c % 3, c / 3) += h;
      sc.forces(xx, vv, fp, mp);
      const bool same_p = sc.signature(vv) == base;
      z(c % 3, c / 3) -= 2 * h;
      sc.forces(xx, vv, fm, mm);
      const bool same_m = sc.signature(vv) == base;
      const Eigen::Map<const Eigen::VectorXd> a(fp.data(), m), b(fm.data(), m);
      const Eigen::Map<const Eigen::VectorXd> ma(mp.data(), m), mb(mm.data(), m);
      (which == 0 ? out.fx : out.fv).col(c) = (a - b) / (2 * h);
      if (which == 0) out.mx.col(c) = (ma - mb) / (2 * h);
      (which == 0 ? out.x_ok : out.v_ok)[c] = same_p && same_m;
    }
  sc.forces(sc.x, sc.v, fp, mp);
  return out;
}

// Dense 3(N+1) × 3(N+1) matrix of a block store (9 × 5(N+1), see kt::ForceJacobian).
Mat dense(const Eigen::Matrix<double, 9, Eigen::Dynamic>& store, int nodes) {
  Mat a = Mat::Zero(3 * nodes, 3 * nodes);
  for (int i = 0; i < nodes; ++i)
    for (int j = std::max(0, i - 2); j <= std::min(nodes - 1, i + 2); ++j)
      a.block<3, 3>(3 * i, 3 * j) =
          Eigen::Map<const Eigen::Matrix3d>(store.col(kt::detail::band_block_index(i, j)).data());
  return a;
}

// Entry-wise comparison of an analytic Jacobian with its finite differences. Tolerance: central
// differences with h = 1e-6 m (m/s) err by h²/6·|F'''| (≤ ~1e-6 N/m here: the stiffest term,
// EA/l = 5e3 N/m over lengths of 0.2 m, has |F'''| ~ EA/l/l_s² ~ 1e5 N/m³) plus rounding
// ε|F|/h (~1e-8 for forces of tens of N); allowed: 1e-5 + 1e-6·|entry| + 1e-8 × the column's
// largest entry. The terms the test must see are far above that (drag's tangent terms on this
// line ~0.1–1 N/m, the added-mass rate terms ~0.1 N s/m).
struct Verdict {
  double worst = 0.0;  // largest error over its tolerance
  int checked = 0, skipped = 0;
  std::string where;
};

Verdict compare(const Mat& analytic, const Mat& fd, const std::vector<bool>& ok, const char* what) {
  Verdict r;
  for (Eigen::Index c = 0; c < fd.cols(); ++c) {
    if (!ok[c]) {
      ++r.skipped;
      continue;
    }
    ++r.checked;
    const double col = fd.col(c).cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < fd.rows(); ++i) {
      const double tol = 1e-5 + 1e-6 * std::abs(fd(i, c)) + 1e-8 * col;
      const double e = std::abs(analytic(i, c) - fd(i, c)) / tol;
      if (e > r.worst) {
        r.worst = e;
        r.where = std::string(what) + " row " + std::to_string(i) + " (node " +
                  std::to_string(i / 3) + ") col " + std::to_string(c) + " (node " +
                  std::to_string(c / 3) + "): analytic " + std::to_string(analytic(i, c)) +
                  ", fd " + std::to_string(fd(i, c));
      }
    }
  }
  return r;
}

void check_scene(const Config& c, unsigned seed) {
  Scene sc(c, seed);
  const Differences fd = finite_differences(sc, 1e-6);
  kt::ForceJacobian<double> jac(sc.model);
  kt::force_jacobian(sc.model, sc.ws, sc.env, sc.x, sc.v, sc.d, jac);
  const int nodes = sc.model.nodes();
  for (const auto& [name, a, b, ok] :
       {std::make_tuple("dF/dx", dense(jac.dfdx, nodes), fd.fx, fd.x_ok),
        std::make_tuple("dF/dv", dense(jac.dfdv, nodes), fd.fv, fd.v_ok),
        std::make_tuple("d(Md)/dx", dense(jac.dmdx, nodes), fd.mx, fd.x_ok)}) {
    const Verdict r = compare(a, b, ok, name);
    INFO("seed " << seed << " " << r.where << "; skipped " << r.skipped << " columns at kinks");
    CHECK(r.worst <= 1.0);
    CHECK(r.checked >= 3 * nodes - 6);
  }
  // Outside the band or the nodes: a zero block, never a read beyond the store.
  for (const auto& [i, j] : {std::make_pair(-1, 0), std::make_pair(-2, -1),
                             std::make_pair(nodes, nodes), std::make_pair(0, 3)})
    CHECK(jac.dF_dx(i, j).isZero(0.0));
  CHECK_FALSE(jac.dF_dx(nodes / 2, nodes / 2).isZero(0.0));  // an interior node's stiffness
}

}  // namespace

TEST_CASE("whole Jacobian: every block matches central differences of compute_forces",
          "[tether][jacobian]") {
  // Both ends kinematic (an ROV tether), both free, one of each; compressive damping; frozen
  // friction; bending off; Cat = Can (no rate terms); no dashpot.
  std::vector<std::pair<std::string, Config>> configs;
  configs.push_back({"kinematic ends", Config{}});
  {
    Config c;
    c.free_start = c.free_end = true;
    configs.push_back({"free ends", c});
  }
  {
    Config c;
    c.free_end = true;
    c.compressive = true;
    configs.push_back({"compressive damping, one free end", c});
  }
  {
    Config c;
    c.frozen_friction = true;
    c.free_start = true;
    configs.push_back({"frozen friction normal", c});
  }
  {
    Config c;
    c.bending = 0.0;
    c.cat = 1.0;
    c.damping = 0.0;
    configs.push_back({"no bending, Cat = Can, no dashpot", c});
  }
  {
    Config c;
    c.fold = true;
    configs.push_back({"a segment folded below the dashpot's fade length", c});
  }
  {
    Config c;
    c.parted = 5;
    configs.push_back({"a parted segment (TetherState::parted) inside the line", c});
  }
  {
    Config c;
    c.parted = 0;
    c.free_end = true;
    configs.push_back({"parted at the kinematic start, free far end", c});
  }
  {
    Config c;
    c.clamp = true;
    configs.push_back({"both ends clamped (EndMotion::direction)", c});
  }
  for (const auto& [name, c] : configs)
    for (unsigned seed = 1; seed <= 6; ++seed) {
      INFO(name);
      check_scene(c, seed);
    }
}

TEST_CASE("whole Jacobian: the states of the check cover every branch", "[tether][jacobian]") {
  // The scenes above must reach each branch the Jacobian distinguishes, or the check proves
  // nothing about it.
  int air = 0, band = 0, bed = 0, ramp = 0, sliding = 0, sticking = 0, taut = 0, slack = 0,
      clamped = 0, faded = 0;
  Config folded;
  folded.fold = true;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    Scene sc(seed <= 6 ? Config{} : folded, seed);
    Matrix3X<double> f, md;
    sc.forces(sc.x, sc.v, f, md);
    const auto& p = sc.model.parameters();
    for (int i = 0; i < sc.model.nodes(); ++i) {
      air += sc.ws.submerged(i) == 0.0;
      band += sc.ws.submerged(i) > 0.0 && sc.ws.submerged(i) < 1.0;
      if (sc.ws.seabed_force(i) > 0.0) {
        ++bed;
        ramp += sc.x(2, i) - sc.env.bed < p.seabed_damping_depth;
        (sc.v.col(i).head<2>().norm() > p.friction_velocity ? sliding : sticking)++;
      }
    }
    for (int s = 0; s < sc.model.segments(); ++s) {
      const double r = sc.ws.direction.col(s).dot(sc.v.col(s + 1) - sc.v.col(s));
      const double b = kt::detail::segment_branch(
          sc.model, sc.ws.stretched_length(s) - sc.model.segment_length(), r);
      faded += b == 1.0 && sc.ws.stretched_length(s) < sc.model.dashpot_fade_length();
      taut += b == 2.0;
      slack += b == 1.0;
      clamped += b == 0.0;
    }
  }
  CHECK(air > 0);
  CHECK(band > 0);
  CHECK(bed > 0);
  CHECK(ramp > 0);
  CHECK(sliding > 0);
  CHECK(sticking > 0);
  CHECK(taut > 0);
  CHECK(slack > 0);
  CHECK(clamped > 0);
  CHECK(faded >= 6);
}

TEST_CASE("whole Jacobian: the check rejects the symmetric approximation", "[tether][jacobian]") {
  // The block-tridiagonal Jacobian of the symmetric Newton path (ws.seg_*, ws.node_dv,
  // ws.node_kz) leaves out the tangent terms, the rate terms, the band's drag and added mass,
  // the dashpot's direction and bending: the same comparison must fail on it.
  Scene sc(Config{}, 3);
  const Differences fd = finite_differences(sc, 1e-6);
  const int nodes = sc.model.nodes(), n = sc.model.segments();
  Mat fx = Mat::Zero(3 * nodes, 3 * nodes), fv = fx;
  for (int s = 0; s < n; ++s) {
    const Vector3<double> u = sc.ws.direction.col(s);
    Eigen::Matrix3d k = sc.ws.seg_k_uu(s) * u * u.transpose();
    k.diagonal().array() += sc.ws.seg_k_perp(s);
    const Eigen::Matrix3d cm = sc.ws.seg_c_uu(s) * u * u.transpose();
    for (const auto& [a, b, sg] :
         {std::make_tuple(s, s + 1, 1.0), std::make_tuple(s, s, -1.0),
          std::make_tuple(s + 1, s + 1, -1.0), std::make_tuple(s + 1, s, 1.0)}) {
      fx.block<3, 3>(3 * a, 3 * b) += sg * k;
      fv.block<3, 3>(3 * a, 3 * b) += sg * cm;
    }
  }
  for (int i = 0; i < nodes; ++i) {
    const auto dv = sc.ws.node_dv.col(i);
    Eigen::Matrix3d m;
    m << dv(0), dv(1), dv(2), dv(1), dv(3), dv(4), dv(2), dv(4), dv(5);
    fv.block<3, 3>(3 * i, 3 * i) -= m;
    fx(3 * i + 2, 3 * i + 2) -= sc.ws.node_kz(i);
  }
  CHECK(compare(fx, fd.fx, fd.x_ok, "dF/dx").worst > 10.0);
  CHECK(compare(fv, fd.fv, fd.v_ok, "dF/dv").worst > 10.0);
}

TEST_CASE("whole Newton matrix: block LU factor and solve match a dense solve",
          "[tether][jacobian]") {
  for (const bool free_ends : {false, true}) {
    Config c;
    c.free_start = c.free_end = free_ends;
    Scene sc(c, 4);
    Matrix3X<double> f, md;
    sc.forces(sc.x, sc.v, f, md);
    const double gh = 0.01;
    kt::assemble_whole_newton_matrix(sc.model, sc.ws, sc.env, sc.x, sc.v, sc.d, gh);
    // The dense matrix M + γh ∂(Md)/∂x − γh ∂F/∂v − (γh)² ∂F/∂x over the free nodes.
    kt::ForceJacobian<double> jac(sc.model);
    kt::force_jacobian(sc.model, sc.ws, sc.env, sc.x, sc.v, sc.d, jac);
    const int nodes = sc.model.nodes();
    Mat a = gh * dense(jac.dmdx, nodes) - gh * dense(jac.dfdv, nodes) -
            gh * gh * dense(jac.dfdx, nodes);
    for (int i = 0; i < nodes; ++i) {
      const Vector3<double> q = sc.ws.tangent.col(i);
      a.block<3, 3>(3 * i, 3 * i) +=
          sc.ws.mass_iso(i) * Eigen::Matrix3d::Identity() + sc.ws.mass_tan(i) * q * q.transpose();
    }
    const int f0 = sc.model.first_free_node(), f1 = sc.model.last_free_node();
    const int m = 3 * (f1 - f0 + 1);
    const Mat af = a.block(3 * f0, 3 * f0, m, m);
    CHECK((af - af.transpose()).norm() > 1e-6 * af.norm());  // not symmetric
    CHECK((dense(sc.ws.newton_lu, nodes).block(3 * f0, 3 * f0, m, m) - af).norm() <=
          1e-12 * af.norm());
    kt::factor_whole_newton_matrix(sc.model, sc.ws);
    Matrix3X<double> rhs = Matrix3X<double>::Random(3, nodes), delta(3, nodes);
    kt::solve_whole_newton_matrix(sc.model, sc.ws, rhs, delta);
    const Eigen::VectorXd b =
        Eigen::Map<const Eigen::VectorXd>(rhs.data(), 3 * nodes).segment(3 * f0, m);
    const Eigen::VectorXd x = af.fullPivLu().solve(b);
    const Eigen::VectorXd y =
        Eigen::Map<const Eigen::VectorXd>(delta.data(), 3 * nodes).segment(3 * f0, m);
    CHECK((x - y).norm() <= 1e-10 * x.norm());
    // Several solves with one factor.
    kt::solve_whole_newton_matrix(sc.model, sc.ws, rhs, rhs);
    CHECK(
        (Eigen::Map<const Eigen::VectorXd>(rhs.data(), 3 * nodes).segment(3 * f0, m) - x).norm() <=
        1e-10 * x.norm());
  }
}

TEST_CASE("whole Newton matrix: a singular pivot is refused with numerical_error",
          "[tether][jacobian]") {
  Scene sc(Config{}, 2);
  Matrix3X<double> f, md;
  sc.forces(sc.x, sc.v, f, md);
  kt::assemble_whole_newton_matrix(sc.model, sc.ws, sc.env, sc.x, sc.v, sc.d, 0.01);
  const int i = 4;
  Eigen::Map<Eigen::Matrix3d>(sc.ws.newton_lu.col(kt::detail::band_block_index(i, i)).data())
      .row(2)
      .setZero();
  for (int j = i - 2; j <= i + 2; ++j)
    Eigen::Map<Eigen::Matrix3d>(sc.ws.newton_lu.col(kt::detail::band_block_index(i, j)).data())
        .row(2)
        .setZero();
  CHECK_THROWS_AS(kt::factor_whole_newton_matrix(sc.model, sc.ws), kelp::numerical_error);
}

namespace {

// The paper's 15 m ROV tether in the rough sea (seed 5): the start end rides the free surface
// (0.08 m under it, so that the nodes near it cross the surface band), the far end is held at
// 5 m depth 12 m astern.
struct RoughLine {
  const Vector3<double> far{-12.0, 0.0, 5.0};
  kelp::environment::Environmentd env;
  kt::TetherModel<double> model;
  kt::TetherWorkspace<double> ws;
  kt::TetherStated state;
  RoughLine()
      : env(kelp::environment::make_environment<double>(kelp::environment::presets::rough(),
                                                        sea_options())),
        model(kt::presets::rov_tether(15.0, 0.5)),
        ws(model),
        state(kt::straight_line_state(model, surface(0.0), far)) {}
  static kelp::environment::SeaStateOptions sea_options() {
    kelp::environment::SeaStateOptions o;
    o.seed = 5;
    return o;
  }
  Vector3<double> surface(double t) const {
    return Vector3<double>(0.0, 0.0, 0.08 - env.surface_elevation(0.0, 0.0, t));
  }
  kt::TetherBoundaryd boundary(double dt) const {
    kt::TetherBoundaryd b;
    b.start.position = surface(state.time);
    b.start.velocity = (surface(state.time + dt) - surface(state.time)) / dt;
    b.end.position = far;
    return b;
  }
};

}  // namespace

TEST_CASE("BDF2 with the whole Jacobian: the same steps in fewer Newton iterations",
          "[tether][jacobian][implicit]") {
  RoughLine sym, whole;
  kt::ImplicitOptionsd os, ow;
  ow.jacobian = kt::JacobianKind::whole;
  const double dt = 0.01;
  long ns = 0, nw = 0;
  for (int k = 0; k < 1000; ++k) {
    ns += kt::step(sym.model, sym.ws, sym.env, sym.state, sym.boundary(dt), dt,
                   {kt::Integrator::bdf2, os})
              .newton_iterations;
    const kt::TetherBoundaryd b = whole.boundary(dt);
    Eigen::internal::set_is_malloc_allowed(false);
    nw += kt::step(whole.model, whole.ws, whole.env, whole.state, b, dt, {kt::Integrator::bdf2, ow})
              .newton_iterations;
    Eigen::internal::set_is_malloc_allowed(true);
  }
  // Both solve the same equations to the same tolerance (1.5e-4 m/s² per node): 10 s later the
  // lines agree to far below a millimetre.
  CHECK((sym.state.position - whole.state.position).cwiseAbs().maxCoeff() < 1e-5);
  CHECK((sym.ws.end_forces.on_end - whole.ws.end_forces.on_end).norm() <
        1e-4 * (1.0 + sym.ws.end_forces.on_end.norm()));
  // Measured over these 10 s: 1.21 and 1.03 Newton iterations per step (1.84 and 1.04 before
  // BDF2 predicted from the accelerations, TetherState::acceleration: a closer start saves the
  // symmetric matrix more corrections than the whole one, which converges quadratically).
  INFO("Newton iterations: symmetric " << ns << ", whole " << nw);
  CHECK(nw < 0.9 * ns);
}

TEST_CASE("BDF2 with the whole Jacobian: Newton converges quadratically",
          "[tether][jacobian][implicit]") {
  // The residual after k = 1, 2, … Newton iterations of one step (nothing committed), from a
  // state 5 s into the rough-sea run, at a step of 40 ms (a hard step: the predictor is far
  // off). Quadratic: each residual is at most C × the square of the one before, down to the
  // rounding floor of the forces (~1e-11 m/s here); the symmetric approximation's contraction
  // is linear.
  RoughLine line;
  const double dt = 0.04;
  for (int k = 0; k < 125; ++k)
    kt::step(line.model, line.ws, line.env, line.state, line.boundary(dt), dt,
             {kt::Integrator::bdf2, kt::ImplicitOptionsd{}});
  const auto residuals = [&](kt::JacobianKind kind) {
    std::vector<double> r;
    for (int k = 1; k <= 5; ++k) {
      kt::TetherStated copy = line.state;
      kt::ImplicitOptionsd o;
      o.jacobian = kind;
      o.max_iterations = k;
      o.acceleration_tolerance = 1e-300;
      kt::StepReportd report;
      CHECK_FALSE(kt::detail::try_implicit(line.model, line.ws, line.env, copy, line.boundary(dt),
                                           dt, true, o, report));
      r.push_back(report.rejected_residual);
    }
    return r;
  };
  const std::vector<double> w = residuals(kt::JacobianKind::whole);
  const std::vector<double> s = residuals(kt::JacobianKind::symmetric);
  INFO("whole: " << w[0] << " " << w[1] << " " << w[2] << " " << w[3] << " " << w[4]);
  INFO("symmetric: " << s[0] << " " << s[1] << " " << s[2] << " " << s[3] << " " << s[4]);
  const double floor = 1e-9;
  for (int k = 0; k + 1 < 5; ++k)
    if (w[k] > floor) CHECK(w[k + 1] <= std::max(floor, 100.0 * w[k] * w[k]));
  CHECK(w[2] <= floor);
  CHECK(s[2] > 10.0 * w[2]);
}
