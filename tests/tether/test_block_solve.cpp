// The twisted block-tridiagonal Newton solve (kelp::tether::detail::solve_block_tridiagonal)
// against a copy of the one-sided block-Thomas elimination it replaced and against J δ = rhs
// assembled block by block, on Jacobians of real tether states: all four end-mode combinations,
// 1 to 200 segments, well and badly conditioned; the pivot floor, non-finite input, float and
// the portable (Eigen array) lane pair.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

// The one-sided block-Thomas elimination (block LDLᵀ from the first free node down, three
// divisions in series per block) that solve_block_tridiagonal was before the twisted
// elimination, as of kelp 0aea047, writing the free columns of `delta`.
template <typename Scalar>
void reference_solve(const kt::TetherModel<Scalar>& model, const kt::TetherWorkspace<Scalar>& ws,
                     Scalar c_m, Scalar c_v, Scalar c_x, kelp::Matrix3X<Scalar>& delta) {
  using S = Scalar;
  Eigen::Matrix<S, 6, Eigen::Dynamic> block_inv(6, model.nodes());
  const int n = model.segments();
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  const S floor = S(0.5) * c_m * model.min_node_mass();
  // Segment coupling A_s = al u uᵀ + be I.
  const auto seg = [&](int s, S& al, S& be, S& ux, S& uy, S& uz) {
    al = c_v * ws.seg_c_uu(s) + c_x * ws.seg_k_uu(s);
    be = c_x * ws.seg_k_perp(s);
    ux = ws.direction(0, s);
    uy = ws.direction(1, s);
    uz = ws.direction(2, s);
  };
  // Previous node's inverse (symmetric: 00 10 20 11 21 22) and segment i−1.
  S p00(0), p10(0), p20(0), p11(0), p21(0), p22(0);
  S al_p(0), be_p(0), ux_p(0), uy_p(0), uz_p(0);
  if (f0 > 0) seg(f0 - 1, al_p, be_p, ux_p, uy_p, uz_p);
  for (int i = f0; i <= f1; ++i) {
    // D = c_m (a I + b q qᵀ) + c_v D_v + c_x kz e_z e_zᵀ.
    const S a = c_m * ws.mass_iso(i), bq = c_m * ws.mass_tan(i);
    const S qx = ws.tangent(0, i), qy = ws.tangent(1, i), qz = ws.tangent(2, i);
    const auto dv = ws.node_dv.col(i);
    S d00 = a + bq * qx * qx + c_v * dv(0);
    S d10 = bq * qy * qx + c_v * dv(1);
    S d20 = bq * qz * qx + c_v * dv(2);
    S d11 = a + bq * qy * qy + c_v * dv(3);
    S d21 = bq * qz * qy + c_v * dv(4);
    S d22 = a + bq * qz * qz + c_v * dv(5) + c_x * ws.node_kz(i);
    S r0 = ws.rhs(0, i), r1 = ws.rhs(1, i), r2 = ws.rhs(2, i);
    // + A_{i−1} − A_{i−1} P A_{i−1} with P = D'⁻¹_{i−1} (zero, as are α, β and u before the
    // first segment, when node i − 1 is not eliminated): with w = P u, σ = u·w,
    // A − A P A = u yᵀ + y uᵀ + β I − β² P, y = ½(α − α² σ) u − αβ w.
    {
      const S wx = p00 * ux_p + p10 * uy_p + p20 * uz_p;
      const S wy = p10 * ux_p + p11 * uy_p + p21 * uz_p;
      const S wz = p20 * ux_p + p21 * uy_p + p22 * uz_p;
      const S sig = ux_p * wx + uy_p * wy + uz_p * wz;
      const S cu = S(0.5) * al_p * (S(1) - al_p * sig), ab = al_p * be_p, bb = be_p * be_p;
      const S yx = cu * ux_p - ab * wx, yy = cu * uy_p - ab * wy, yz = cu * uz_p - ab * wz;
      d00 += S(2) * ux_p * yx + (be_p - bb * p00);
      d10 += uy_p * yx + yy * ux_p - bb * p10;
      d20 += uz_p * yx + yz * ux_p - bb * p20;
      d11 += S(2) * uy_p * yy + (be_p - bb * p11);
      d21 += uz_p * yy + yz * uy_p - bb * p21;
      d22 += S(2) * uz_p * yz + (be_p - bb * p22);
    }
    if (i > f0) {
      // r += A z_{i−1}
      const S z0 = delta(0, i - 1), z1 = delta(1, i - 1), z2 = delta(2, i - 1);
      const S uz_dot = al_p * (ux_p * z0 + uy_p * z1 + uz_p * z2);
      r0 += uz_dot * ux_p + be_p * z0;
      r1 += uz_dot * uy_p + be_p * z1;
      r2 += uz_dot * uz_p + be_p * z2;
    }
    S al(0), be(0), ux(0), uy(0), uz(0);
    if (i < n) {
      seg(i, al, be, ux, uy, uz);
      d00 += al * ux * ux + be;
      d10 += al * uy * ux;
      d20 += al * uz * ux;
      d11 += al * uy * uy + be;
      d21 += al * uz * uy;
      d22 += al * uz * uz + be;
    }
    // D' = L diag(e0, e1, e2) Lᵀ, pivots floored at the exact lower bound (see above); then
    // P = D'⁻¹ = L⁻ᵀ diag(1/e) L⁻¹ with L⁻¹ = [1 0 0; m10 1 0; m20 m21 1].
    const S e0 = std::max(d00, floor), i0 = S(1) / e0;
    const S l10 = d10 * i0, l20 = d20 * i0;
    const S e1 = std::max(d11 - l10 * d10, floor), i1 = S(1) / e1;
    const S l21 = (d21 - l20 * d10) * i1;
    const S e2 = std::max(d22 - l20 * d20 - l21 * l21 * e1, floor), i2 = S(1) / e2;
    if (!kelp::is_finite(i0 + i1 + i2 + l10 + l20 + l21))
      kelp::detail::throw_numerical_error(
          "tether Newton step: non-finite Jacobian block; the state is unchanged");
    const S m10 = -l10, m21 = -l21, m20 = l10 * l21 - l20;
    p00 = i0 + m10 * m10 * i1 + m20 * m20 * i2;
    p10 = m10 * i1 + m20 * m21 * i2;
    p20 = m20 * i2;
    p11 = i1 + m21 * m21 * i2;
    p21 = m21 * i2;
    p22 = i2;
    delta(0, i) = p00 * r0 + p10 * r1 + p20 * r2;
    delta(1, i) = p10 * r0 + p11 * r1 + p21 * r2;
    delta(2, i) = p20 * r0 + p21 * r1 + p22 * r2;
    auto inv = block_inv.col(i);
    inv(0) = p00;
    inv(1) = p10;
    inv(2) = p20;
    inv(3) = p11;
    inv(4) = p21;
    inv(5) = p22;
    al_p = al;
    be_p = be;
    ux_p = ux;
    uy_p = uy;
    uz_p = uz;
  }
  // Back substitution: δ_i += P_i A_i δ_{i+1}.
  for (int i = f1 - 1; i >= f0; --i) {
    S al, be, ux, uy, uz;
    seg(i, al, be, ux, uy, uz);
    const S y0 = delta(0, i + 1), y1 = delta(1, i + 1), y2 = delta(2, i + 1);
    const S ud = al * (ux * y0 + uy * y1 + uz * y2);
    const S t0 = ud * ux + be * y0, t1 = ud * uy + be * y1, t2 = ud * uz + be * y2;
    const auto p = block_inv.col(i);
    delta(0, i) += p(0) * t0 + p(1) * t1 + p(2) * t2;
    delta(1, i) += p(1) * t0 + p(3) * t1 + p(4) * t2;
    delta(2, i) += p(2) * t0 + p(4) * t1 + p(5) * t2;
  }
}

// A_s = α u uᵀ + β I of segment s (α = c_v BA/l + c_x k_uu, β = c_x k_perp).
template <typename S>
Eigen::Matrix<S, 3, 3> coupling(const kt::TetherWorkspace<S>& ws, int s, S c_v, S c_x) {
  const Vector3<S> u = ws.direction.col(s);
  Eigen::Matrix<S, 3, 3> a = (c_v * ws.seg_c_uu(s) + c_x * ws.seg_k_uu(s)) * u * u.transpose();
  a.diagonal().array() += c_x * ws.seg_k_perp(s);
  return a;
}

// J δ over the free nodes, assembled block by block from the workspace (δ of the kinematic end
// nodes taken as zero), and |J| |δ| (entrywise absolute values) as its scale.
template <typename S>
void apply_jacobian(const kt::TetherModel<S>& model, const kt::TetherWorkspace<S>& ws, S c_m, S c_v,
                    S c_x, const kelp::Matrix3X<S>& delta, kelp::Matrix3X<S>& jd,
                    kelp::Matrix3X<S>& scale) {
  using M3 = Eigen::Matrix<S, 3, 3>;
  const int n = model.segments(), f0 = model.first_free_node(), f1 = model.last_free_node();
  jd.setZero(3, n + 1);
  scale.setZero(3, n + 1);
  for (int i = f0; i <= f1; ++i) {
    const Vector3<S> q = ws.tangent.col(i);
    M3 d = c_m * (ws.mass_iso(i) * M3::Identity() + ws.mass_tan(i) * q * q.transpose());
    const auto dv = ws.node_dv.col(i);
    M3 dvm;
    dvm << dv(0), dv(1), dv(2), dv(1), dv(3), dv(4), dv(2), dv(4), dv(5);
    d += c_v * dvm;
    d(2, 2) += c_x * ws.node_kz(i);
    if (i > 0) d += coupling(ws, i - 1, c_v, c_x);
    if (i < n) d += coupling(ws, i, c_v, c_x);
    jd.col(i) = d * delta.col(i);
    scale.col(i) = d.cwiseAbs() * delta.col(i).cwiseAbs();
    if (i > f0) {
      const M3 a = coupling(ws, i - 1, c_v, c_x);
      jd.col(i) -= a * delta.col(i - 1);
      scale.col(i) += a.cwiseAbs() * delta.col(i - 1).cwiseAbs();
    }
    if (i < f1) {
      const M3 a = coupling(ws, i, c_v, c_x);
      jd.col(i) -= a * delta.col(i + 1);
      scale.col(i) += a.cwiseAbs() * delta.col(i + 1).cwiseAbs();
    }
  }
}

// Largest |x| over the free columns.
template <typename S>
double free_max(const kt::TetherModel<S>& m, const kelp::Matrix3X<S>& x) {
  double r = 0;
  for (int i = m.first_free_node(); i <= m.last_free_node(); ++i)
    r = std::max(r, double(x.col(i).cwiseAbs().maxCoeff()));
  return r;
}

// Largest |x − y| over the free columns.
template <typename S>
double free_diff(const kt::TetherModel<S>& m, const kelp::Matrix3X<S>& x,
                 const kelp::Matrix3X<S>& y) {
  double r = 0;
  for (int i = m.first_free_node(); i <= m.last_free_node(); ++i)
    r = std::max(r, double((x.col(i) - y.col(i)).cwiseAbs().maxCoeff()));
  return r;
}

// Backward error of δ: max |J δ − rhs| over max (|J| |δ| + |rhs|).
template <typename S>
double backward_error(const kt::TetherModel<S>& m, const kt::TetherWorkspace<S>& ws, S c_m, S c_v,
                      S c_x, const kelp::Matrix3X<S>& delta) {
  kelp::Matrix3X<S> jd, scale;
  apply_jacobian(m, ws, c_m, c_v, c_x, delta, jd, scale);
  double res = 0, sc = 0;
  for (int i = m.first_free_node(); i <= m.last_free_node(); ++i) {
    res = std::max(res, double((jd.col(i) - ws.rhs.col(i)).cwiseAbs().maxCoeff()));
    sc = std::max(sc, double(scale.col(i).maxCoeff() + ws.rhs.col(i).cwiseAbs().maxCoeff()));
  }
  return res / sc;
}

// Upper bound of the condition number of J: the Gershgorin bound of λ_max (the largest row sum
// of |J|) over λ_min(J) ≥ c_m min_i λ_min(M_i) (J − c_m M is positive semi-definite here).
template <typename S>
double condition_bound(const kt::TetherModel<S>& m, const kt::TetherWorkspace<S>& ws, S c_m, S c_v,
                       S c_x) {
  kelp::Matrix3X<S> ones = kelp::Matrix3X<S>::Ones(3, m.nodes()), jd, scale;
  apply_jacobian(m, ws, c_m, c_v, c_x, ones, jd, scale);
  double lmax = 0, lmin = std::numeric_limits<double>::infinity();
  for (int i = m.first_free_node(); i <= m.last_free_node(); ++i) {
    lmax = std::max(lmax, double(scale.col(i).maxCoeff()));
    lmin = std::min(lmin, double(c_m * std::min(ws.mass_iso(i), ws.mass_iso(i) + ws.mass_tan(i))));
  }
  return lmax / lmin;
}

// A tether of `segments` segments (kelp's benchmark line, internal damping 50 N s) with the
// given end modes, its nodes perturbed at random about a chord 0.15 % longer than the line
// (mostly taut, some segments slack), random velocities in a current, partly in air and partly
// on the seabed: compute_forces<true> fills the Jacobian ingredients, rhs is random.
// c_m = 1, c_v = γh, c_x = (γh)² (γ = 2/3, BDF2).
template <typename S>
struct System {
  kt::TetherModel<S> model;
  kt::TetherWorkspace<S> ws;
  S c_m = S(1), c_v, c_x;

  static kt::TetherParameters<S> params(int segments, bool start_free, bool end_free) {
    auto p = kelp_test::benchmark_line<S>(segments);
    p.internal_damping = S(50);
    if (start_free) {
      p.start_mode = kt::EndMode::free;
      p.start_point_mass = S(0.3);
    }
    if (end_free) p.end_mode = kt::EndMode::free;
    return p;
  }

  System(int segments, bool start_free, bool end_free, double h, unsigned seed)
      : model(params(segments, start_free, end_free)),
        ws(model),
        c_v(S(2.0 / 3.0 * h)),
        c_x(S(4.0 / 9.0 * h * h)) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    kelp_test::TestWater<S> env;
    env.current = Vector3<S>(S(0.5), S(-0.2), S(0.1));
    env.surface_z = S(0.6);  // nodes above NED z = 0.6 m are (partly) in air
    env.bed = S(4.5);        // nodes below 4.5 m touch the seabed
    const Vector3<S> a(0, 0, 0), b(S(19.42), S(1), S(5));
    kt::TetherState<S> s = kt::straight_line_state(model, a, b);
    const double l = 20.0 / segments;
    for (int i = 0; i < model.nodes(); ++i)
      for (int r = 0; r < 3; ++r) {
        s.position(r, i) += S(0.3 * l * uni(rng));
        s.velocity(r, i) = S(0.5 * uni(rng));
      }
    kt::compute_forces<true>(model, ws, env, 0.0, s.position, s.velocity);
    for (int i = 0; i < model.nodes(); ++i)
      for (int r = 0; r < 3; ++r) ws.rhs(r, i) = S(uni(rng));
  }

  bool has_free_nodes() const { return model.last_free_node() >= model.first_free_node(); }
};

const int kSegments[] = {1, 2, 3, 4, 5, 20, 101, 200};

std::string describe(int n, int modes) {
  return std::to_string(n) + " segments, start " + (modes & 1 ? "free" : "kinematic") + ", end " +
         (modes & 2 ? "free" : "kinematic");
}

}  // namespace

TEST_CASE("twisted block solve agrees with the one-sided elimination and solves J δ = rhs",
          "[tether][block_solve]") {
  // Steps of 1 ms and 10 ms are well conditioned (κ(J) up to ~7e4 at 200 segments); 0.1 s and
  // 1 s are not ((γh)² EA/l up to 4e5 N/m against ~0.02 kg nodes, κ(J) up to ~6e8). Both
  // eliminations are backward stable: each agrees with J δ = rhs to a few ulps, and they differ
  // from each other (and from the exact solution) by round-off times κ(J).
  const double eps = std::numeric_limits<double>::epsilon();
  for (const double h : {1e-3, 1e-2, 0.1, 1.0})
    for (const int n : kSegments)
      for (int modes = 0; modes < 4; ++modes)
        for (unsigned seed = 1; seed <= 2; ++seed) {
          System<double> sys(n, modes & 1, modes & 2, h, seed);
          auto& ws = sys.ws;
          const auto& m = sys.model;
          INFO("h " << h << " s, " << describe(n, modes) << ", seed " << seed);
          kelp::Matrix3X<double> ref = kelp::Matrix3X<double>::Zero(3, m.nodes());
          if (sys.has_free_nodes()) reference_solve(m, ws, sys.c_m, sys.c_v, sys.c_x, ref);
          // Allocation-free, and the kinematic end columns of ws.delta are left as they were.
          ws.delta.setConstant(7.0);
          Eigen::internal::set_is_malloc_allowed(false);
          kt::detail::solve_block_tridiagonal(m, ws, sys.c_m, sys.c_v, sys.c_x);
          Eigen::internal::set_is_malloc_allowed(true);
          if (m.first_free_node() == 1) CHECK((ws.delta.col(0).array() == 7.0).all());
          if (m.last_free_node() == n - 1) CHECK((ws.delta.col(n).array() == 7.0).all());
          if (!sys.has_free_nodes()) continue;
          const double kappa = condition_bound(m, ws, sys.c_m, sys.c_v, sys.c_x);
          CHECK(free_diff(m, ws.delta, ref) <=
                std::max(1e-12, 16 * eps * kappa) * free_max(m, ref));
          CHECK(backward_error(m, ws, sys.c_m, sys.c_v, sys.c_x, ws.delta) <= 1e-13);
        }
}

TEST_CASE("twisted block solve on the benchmark line's BDF2 Jacobian", "[tether][block_solve]") {
  // kelp's benchmark line (bench_tether, BM_BlockSolve) after 20 BDF2 steps at 10 ms: within
  // 1e-12 of the one-sided elimination, or round-off times κ(J) where that is larger (200
  // segments: κ ≈ 2e4).
  for (const int n : {20, 50, 100, 200}) {
    kelp::environment::Environmentd env;
    const kt::TetherModeld model(kelp_test::benchmark_line<double>(n));
    kt::TetherWorkspaced ws(model);
    kt::TetherStated state;
    const Vector3<double> a(0, 0, 0), b(10, 0, 5);
    REQUIRE(kt::static_initial_state(model, ws, env, a, b, state).converged);
    const double dt = 0.01, gh = 2.0 / 3.0 * dt;
    for (int k = 0; k < 20; ++k) {
      auto bnd = kt::TetherBoundaryd::fixed(a, b);
      bnd.end.position.z() = 5.0 + 0.1 * (1 - std::cos(0.4 * kelp::pi * state.time));
      kt::step(model, ws, env, state, bnd, dt, {kt::Integrator::bdf2});
    }
    kt::compute_forces<true>(model, ws, env, state.time, state.position, state.velocity);
    for (int i = 0; i < model.nodes(); ++i)
      ws.rhs.col(i) = Vector3<double>(std::cos(i), 1.0, std::sin(0.5 * i));
    kelp::Matrix3X<double> ref = kelp::Matrix3X<double>::Zero(3, model.nodes());
    reference_solve(model, ws, 1.0, gh, gh * gh, ref);
    kt::detail::solve_block_tridiagonal(model, ws, 1.0, gh, gh * gh);
    const double kappa = condition_bound(model, ws, 1.0, gh, gh * gh);
    INFO(n << " segments, condition bound " << kappa);
    CHECK(free_diff(model, ws.delta, ref) <=
          std::max(1e-12, 16 * std::numeric_limits<double>::epsilon() * kappa) *
              free_max(model, ref));
  }
}

TEST_CASE("the portable lane pair (Eigen array) gives the same solution", "[tether][block_solve]") {
  for (const int n : kSegments)
    for (int modes = 0; modes < 4; ++modes) {
      System<double> sys(n, modes & 1, modes & 2, 0.01, 11);
      if (!sys.has_free_nodes()) continue;
      auto& ws = sys.ws;
      kt::detail::solve_block_tridiagonal(sys.model, ws, sys.c_m, sys.c_v, sys.c_x);
      const kelp::Matrix3X<double> fast = ws.delta;
      ws.delta.setZero();
      kt::detail::solve_block_tridiagonal<double, Eigen::Array<double, 2, 1>>(
          sys.model, ws, sys.c_m, sys.c_v, sys.c_x);
      INFO(describe(n, modes));
      CHECK(free_diff(sys.model, ws.delta, fast) <= 1e-14 * free_max(sys.model, fast));
    }
}

TEST_CASE("single precision agrees with double", "[tether][block_solve]") {
  // The same Jacobian (the float workspace's, widened) solved in float and in double: they
  // differ by float round-off times κ(J) (≤ ~7e2 at 1 ms).
  for (const int n : {1, 2, 5, 20, 101})
    for (int modes = 0; modes < 4; ++modes) {
      System<float> f(n, modes & 1, modes & 2, 0.001, 5);
      if (!f.has_free_nodes()) continue;
      System<double> d(n, modes & 1, modes & 2, 0.001, 5);
      auto& wd = d.ws;
      const auto& wf = f.ws;
      wd.mass_iso = wf.mass_iso.cast<double>();
      wd.mass_tan = wf.mass_tan.cast<double>();
      wd.tangent = wf.tangent.cast<double>();
      wd.node_dv = wf.node_dv.cast<double>();
      wd.node_kz = wf.node_kz.cast<double>();
      wd.seg_c_uu = wf.seg_c_uu.cast<double>();
      wd.seg_k_uu = wf.seg_k_uu.cast<double>();
      wd.seg_k_perp = wf.seg_k_perp.cast<double>();
      wd.direction = wf.direction.cast<double>();
      wd.rhs = wf.rhs.cast<double>();
      kt::detail::solve_block_tridiagonal(f.model, f.ws, f.c_m, f.c_v, f.c_x);
      kt::detail::solve_block_tridiagonal(d.model, wd, double(f.c_m), double(f.c_v), double(f.c_x));
      const kelp::Matrix3X<double> wide = f.ws.delta.cast<double>();
      INFO(describe(n, modes));
      CHECK(free_diff(d.model, wide, wd.delta) <= 1e-4 * free_max(d.model, wd.delta));
    }
}

TEST_CASE("pivots below the floor are raised to it", "[tether][block_solve]") {
  // Node i made deficient by hand: its segments slack (no coupling to its neighbours) and its
  // block set, through its drag derivative, to d_xx = ½ floor, d_yx = d_zx = 0 with
  // floor = ½ c_m min_node_mass. J is then no longer bounded below by c_m M and the first LDLᵀ
  // pivot of node i is raised to the floor: J δ ≠ rhs, δ stays finite and a descent direction
  // (rhs·δ > 0, for the line search), and it is the one-sided elimination's δ, which floors the
  // same block.
  const auto make_deficient = [](System<double>& sys, int i) {
    const auto& m = sys.model;
    auto& ws = sys.ws;
    for (const int s : {i - 1, i})
      if (s >= 0 && s < m.segments()) ws.seg_k_uu(s) = ws.seg_c_uu(s) = ws.seg_k_perp(s) = 0;
    kelp::Matrix3X<double> e = kelp::Matrix3X<double>::Zero(3, m.nodes()), jd, scale;
    e(0, i) = 1;
    apply_jacobian(m, ws, sys.c_m, sys.c_v, sys.c_x, e, jd, scale);
    const double floor = 0.5 * sys.c_m * m.min_node_mass();
    ws.node_dv(0, i) -= (jd(0, i) - 0.5 * floor) / sys.c_v;
    ws.node_dv(1, i) -= jd(1, i) / sys.c_v;
    ws.node_dv(2, i) -= jd(2, i) / sys.c_v;
  };
  const auto descent = [](const System<double>& sys, const kelp::Matrix3X<double>& d) {
    double g = 0;
    for (int i = sys.model.first_free_node(); i <= sys.model.last_free_node(); ++i)
      g += sys.ws.rhs.col(i).dot(d.col(i));
    return g;
  };
  for (const int n : {1, 2, 3, 20, 101})
    for (int modes = 0; modes < 4; ++modes)
      for (int where = 0; where < 3; ++where) {
        System<double> sys(n, modes & 1, modes & 2, 0.01, 3);
        if (!sys.has_free_nodes()) continue;
        const auto& m = sys.model;
        // The first free node (top chain, lane 0), the meeting node, the node below it (bottom
        // chain, lane 1).
        const int f0 = m.first_free_node(), f1 = m.last_free_node(), mid = (f0 + f1 + 1) / 2;
        const int node = where == 0 ? f0 : where == 1 ? mid : mid + 1;
        if (node > f1) continue;
        make_deficient(sys, node);
        auto& ws = sys.ws;
        kelp::Matrix3X<double> ref = kelp::Matrix3X<double>::Zero(3, m.nodes());
        INFO(describe(n, modes) << ", deficient node " << node);
        REQUIRE_NOTHROW(reference_solve(m, ws, sys.c_m, sys.c_v, sys.c_x, ref));
        REQUIRE_NOTHROW(kt::detail::solve_block_tridiagonal(m, ws, sys.c_m, sys.c_v, sys.c_x));
        CHECK(ws.delta.allFinite());
        CHECK(backward_error(m, ws, sys.c_m, sys.c_v, sys.c_x, ws.delta) > 1e-6);  // floored
        CHECK(descent(sys, ws.delta) > 0);
        CHECK(free_diff(m, ws.delta, ref) <= 1e-12 * free_max(m, ref));
      }
}

TEST_CASE("non-finite input: a Jacobian block throws, the right-hand side propagates",
          "[tether][block_solve]") {
  // As the one-sided elimination: a non-finite Jacobian ingredient throws numerical_error; a
  // non-finite rhs is not checked and gives a non-finite δ.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const int n : {1, 2, 5, 20})
    for (int modes = 0; modes < 4; ++modes) {
      System<double> probe(n, modes & 1, modes & 2, 0.01, 9);
      if (!probe.has_free_nodes()) continue;
      const int f0 = probe.model.first_free_node(), f1 = probe.model.last_free_node();
      for (const int node : {f0, (f0 + f1) / 2, f1}) {
        INFO(describe(n, modes) << ", node " << node);
        {
          System<double> sys(n, modes & 1, modes & 2, 0.01, 9);
          sys.ws.rhs(1, node) = nan;
          kelp::Matrix3X<double> ref = kelp::Matrix3X<double>::Zero(3, sys.model.nodes());
          CHECK_NOTHROW(reference_solve(sys.model, sys.ws, sys.c_m, sys.c_v, sys.c_x, ref));
          CHECK_NOTHROW(
              kt::detail::solve_block_tridiagonal(sys.model, sys.ws, sys.c_m, sys.c_v, sys.c_x));
          CHECK_FALSE(ref.allFinite());
          CHECK_FALSE(sys.ws.delta.allFinite());
        }
        for (int field = 0; field < 3; ++field) {
          System<double> sys(n, modes & 1, modes & 2, 0.01, 9);
          if (field == 0) sys.ws.node_dv(4, node) = nan;
          if (field == 1) sys.ws.mass_iso(node) = nan;
          if (field == 2) sys.ws.direction(2, std::min(node, n - 1)) = nan;
          kelp::Matrix3X<double> ref = kelp::Matrix3X<double>::Zero(3, sys.model.nodes());
          CHECK_THROWS_AS(reference_solve(sys.model, sys.ws, sys.c_m, sys.c_v, sys.c_x, ref),
                          kelp::numerical_error);
          CHECK_THROWS_AS(
              kt::detail::solve_block_tridiagonal(sys.model, sys.ws, sys.c_m, sys.c_v, sys.c_x),
              kelp::numerical_error);
        }
      }
    }
}
