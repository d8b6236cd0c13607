// compute_forces' vectorised passes against the scalar evaluation they replaced
// (reference_forces.hpp): every workspace output, with and without the Jacobian terms, on lines
// that exercise every branch (surface band, in air, seabed with friction, slack and clamped
// segments, coincident nodes, bending, free ends, water current and acceleration, inputs given
// as expressions), in double to 1e-12 of each field's magnitude and in float to 1e-5; and the
// passes' AVX2 build against the baseline build, bit for bit.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "reference_forces.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Matrix3X;
using kelp::Vector3;

namespace {

template <typename Scalar>
struct Case {
  std::string name;
  kt::TetherParameters<Scalar> params;
  kelp_test::TestWater<Scalar> water;
  Matrix3X<Scalar> x, v;
};

// Largest |a − b| over a field, relative to the field's largest magnitude (or 1 if it is 0).
template <typename A, typename B>
double field_error(const A& a, const B& b) {
  const double scale = std::max(1.0, double(b.cwiseAbs().maxCoeff()));
  return double((a - b).cwiseAbs().maxCoeff()) / scale;
}

// Node positions along a sagging line from (0, 0, z0) to (10, 0, z1) with random offsets of
// size `jitter`, velocities uniform in ±vmax; a few nodes made coincident when asked.
template <typename Scalar>
Case<Scalar> make_case(const std::string& name, int n, Scalar z0, Scalar z1, double jitter,
                       double vmax, unsigned seed, bool coincident = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Case<Scalar> c;
  c.name = name;
  c.params.segments = n;
  c.x.resize(3, n + 1);
  c.v.resize(3, n + 1);
  for (int i = 0; i <= n; ++i) {
    const double s = double(i) / n;
    c.x(0, i) = Scalar(10 * s + jitter * u(rng));
    c.x(1, i) = Scalar(jitter * u(rng));
    c.x(2, i) = Scalar(z0 + (z1 - z0) * s + 2.0 * std::sin(kelp::pi * s) + jitter * u(rng));
    for (int k = 0; k < 3; ++k) c.v(k, i) = Scalar(vmax * u(rng));
  }
  if (coincident && n >= 4) {
    c.x.col(2) = c.x.col(1);          // a zero-length segment
    c.x.col(n - 1) = c.x.col(n - 3);  // a zero chord at node n − 2
    c.v.col(2) = c.v.col(1);
  }
  return c;
}

template <typename Scalar>
std::vector<Case<Scalar>> cases() {
  std::vector<Case<Scalar>> out;
  // The benchmark line in still water, several sizes (odd and even interiors, remainders).
  for (int n : {1, 2, 3, 4, 5, 7, 8, 20, 101}) {
    auto c = make_case<Scalar>("still N=" + std::to_string(n), n, Scalar(0.5), Scalar(5), 0.05, 0.5,
                               17u + unsigned(n));
    out.push_back(c);
  }
  {
    auto c =
        make_case<Scalar>("current, water acceleration", 30, Scalar(1), Scalar(6), 0.1, 1.0, 3u);
    c.water.current = Vector3<Scalar>(Scalar(0.7), Scalar(-0.2), Scalar(0.1));
    c.water.accel = Vector3<Scalar>(Scalar(0.3), Scalar(0.1), Scalar(-0.4));
    c.params.tangential_added_mass = Scalar(0.3);
    out.push_back(c);
  }
  {
    // The line crosses the surface: nodes in air, in the surface band and wet.
    auto c = make_case<Scalar>("surface crossing", 40, Scalar(-1.5), Scalar(3), 0.01, 0.8, 5u);
    c.water.current = Vector3<Scalar>(Scalar(0.4), Scalar(0), Scalar(0));
    for (int i = 0; i <= 40; i += 3) c.x(2, i) = Scalar(-0.004 + 0.0005 * (i % 7));  // in the band
    out.push_back(c);
  }
  {
    // On the seabed with friction, landing and rising, frozen and live friction limits.
    auto c = make_case<Scalar>("seabed", 33, Scalar(3), Scalar(4.2), 0.02, 0.3, 7u);
    c.water.bed = Scalar(4.5);
    c.params.seabed_friction = Scalar(0.6);
    for (int i = 10; i <= 33; ++i) c.x(2, i) = Scalar(4.5 + 0.0004 * ((i * 7) % 9) - 0.0001);
    out.push_back(c);
  }
  {
    // Internal damping with the clamp (slack and contracting segments), and compressive.
    auto c = make_case<Scalar>("damping clamp", 25, Scalar(1), Scalar(2), 0.3, 2.0, 11u);
    c.params.internal_damping = Scalar(200);
    out.push_back(c);
    c.name = "compressive damping";
    c.params.compressive_damping = true;
    out.push_back(c);
  }
  {
    auto c = make_case<Scalar>("bending, Cat = Can", 21, Scalar(1), Scalar(3), 0.05, 0.5, 13u);
    c.params.bending_stiffness = Scalar(0.5);
    c.params.tangential_added_mass = c.params.normal_added_mass;
    out.push_back(c);
  }
  {
    auto c = make_case<Scalar>("coincident nodes, free ends", 12, Scalar(1), Scalar(3), 0.05, 0.5,
                               19u, true);
    c.params.start_mode = kt::EndMode::free;
    c.params.end_mode = kt::EndMode::free;
    c.params.end_point_mass = Scalar(2);
    c.params.internal_damping = Scalar(50);
    out.push_back(c);
  }
  {
    // Stretched hard: every segment taut.
    auto c = make_case<Scalar>("taut", 16, Scalar(1), Scalar(1), 0.0, 0.5, 23u);
    for (int i = 0; i <= 16; ++i) c.x.col(i) = Vector3<Scalar>(Scalar(20.3 * i / 16.0), 0, 1);
    out.push_back(c);
  }
  return out;
}

template <bool WithJacobian, typename Scalar>
void compare(const Case<Scalar>& c, double tol, bool frozen_friction, bool as_expression) {
  const kt::TetherModel<Scalar> model(c.params);
  kt::TetherWorkspace<Scalar> a(model), b(model);
  if (frozen_friction) {
    a.frozen_friction = b.frozen_friction = true;
    for (int i = 0; i < model.nodes(); ++i)
      a.friction_normal(i) = b.friction_normal(i) = Scalar(0.01 * (i % 5));
  }
  if (as_expression)
    kt::compute_forces<WithJacobian>(model, a, c.water, 1.0,
                                     c.x + Matrix3X<Scalar>::Zero(3, c.x.cols()),
                                     c.v.leftCols(c.v.cols()));
  else
    kt::compute_forces<WithJacobian>(model, a, c.water, 1.0, c.x, c.v);
  kelp_test::reference_compute_forces<WithJacobian>(model, b, c.water, 1.0, c.x, c.v);
  // Positions and velocities read in place from the rows of a 6 × (N+1) matrix (column stride
  // 6): the same bits as from their own 3 × (N+1) storage.
  {
    Eigen::Matrix<Scalar, 6, Eigen::Dynamic> xv(6, c.x.cols());
    xv.template topRows<3>() = c.x;
    xv.template bottomRows<3>() = c.v;
    kt::TetherWorkspace<Scalar> d(model), e(model);
    d.frozen_friction = e.frozen_friction = a.frozen_friction;
    d.friction_normal = e.friction_normal = a.friction_normal;
    kt::compute_forces<WithJacobian>(model, d, c.water, 1.0, xv.template topRows<3>(),
                                     xv.template bottomRows<3>());
    kt::compute_forces<WithJacobian>(model, e, c.water, 1.0, c.x, c.v);
    INFO(c.name << ": inputs with column stride 6");
    CHECK((d.force.array() == e.force.array()).all());
    CHECK((d.tension.array() == e.tension.array()).all());
  }
  INFO(c.name << (WithJacobian ? " with Jacobian" : "")
              << (frozen_friction ? ", frozen friction" : "")
              << (as_expression ? ", expression inputs" : ""));
  // The node force: relative to its largest term (the tension), as the passes add the same
  // terms in another order.
  const double force_scale = std::max(
      {1.0, double(b.force.cwiseAbs().maxCoeff()), double(b.tension.cwiseAbs().maxCoeff())});
  CHECK(double((a.force - b.force).cwiseAbs().maxCoeff()) / force_scale <= tol);
  CHECK(field_error(a.tangent, b.tangent) <= tol);
  CHECK(field_error(a.mass_iso, b.mass_iso) <= tol);
  CHECK(field_error(a.mass_tan, b.mass_tan) <= tol);
  // The inverse mass terms the integrators use (the reference did not store them).
  CHECK(field_error(a.mass_iso_inv, b.mass_iso.cwiseInverse()) <= tol);
  CHECK(field_error(a.mass_tan_ratio, b.mass_tan.cwiseQuotient(b.mass_iso + b.mass_tan)) <= tol);
  CHECK(field_error(a.submerged, b.submerged) <= tol);
  CHECK(field_error(a.seabed_force, b.seabed_force) <= tol);
  CHECK(field_error(a.direction, b.direction) <= tol);
  CHECK(field_error(a.tension, b.tension) <= tol);
  CHECK(field_error(a.stretched_length, b.stretched_length) <= tol);
  if (c.params.bending_stiffness > Scalar(0)) CHECK(field_error(a.bending, b.bending) <= tol);
  if constexpr (WithJacobian) {
    CHECK(field_error(a.seg_k_uu, b.seg_k_uu) <= tol);
    CHECK(field_error(a.seg_k_perp, b.seg_k_perp) <= tol);
    CHECK(field_error(a.seg_c_uu, b.seg_c_uu) <= tol);
    CHECK(field_error(a.seg_rate, b.seg_rate) <= tol);
    CHECK(field_error(a.node_dv, b.node_dv) <= tol);
    CHECK(field_error(a.node_kz, b.node_kz) <= tol);
  }
}

template <typename Scalar>
void compare_all(double tol) {
  for (const auto& c : cases<Scalar>())
    for (bool frozen : {false, true})
      for (bool expr : {false, true}) {
        compare<false>(c, tol, frozen, expr);
        compare<true>(c, tol, frozen, expr);
      }
}

}  // namespace

TEST_CASE("vectorised force passes reproduce the scalar evaluation (double, 1e-12)",
          "[tether][forces][simd]") {
  compare_all<double>(1e-12);
}

TEST_CASE("vectorised force passes reproduce the scalar evaluation (float)",
          "[tether][forces][simd]") {
  compare_all<float>(1e-5);
}

TEST_CASE("the equivalence check can fail: a changed drag coefficient is seen",
          "[tether][forces][simd]") {
  auto c = cases<double>()[7];  // N = 20 in still water
  const kt::TetherModel<double> model(c.params);
  auto changed = c.params;
  changed.normal_drag *= 1.0 + 1e-8;
  const kt::TetherModel<double> other(changed);
  kt::TetherWorkspace<double> a(model), b(model);
  kt::compute_forces(other, a, c.water, 1.0, c.x, c.v);
  kelp_test::reference_compute_forces(model, b, c.water, 1.0, c.x, c.v);
  const double scale = std::max(
      {1.0, double(b.force.cwiseAbs().maxCoeff()), double(b.tension.cwiseAbs().maxCoeff())});
  CHECK(double((a.force - b.force).cwiseAbs().maxCoeff()) / scale > 1e-12);
}

namespace {

using kelp_test::same_bits;

// Every field compute_forces writes, bit for bit.
bool same_outputs(const kt::TetherWorkspace<double>& a, const kt::TetherWorkspace<double>& b) {
  return same_bits(a.force, b.force) && same_bits(a.tangent, b.tangent) &&
         same_bits(a.mass_iso, b.mass_iso) && same_bits(a.mass_tan, b.mass_tan) &&
         same_bits(a.mass_iso_inv, b.mass_iso_inv) &&
         same_bits(a.mass_tan_ratio, b.mass_tan_ratio) && same_bits(a.submerged, b.submerged) &&
         same_bits(a.seabed_force, b.seabed_force) && same_bits(a.direction, b.direction) &&
         same_bits(a.tension, b.tension) && same_bits(a.stretched_length, b.stretched_length) &&
         same_bits(a.bending, b.bending) && same_bits(a.seg_k_uu, b.seg_k_uu) &&
         same_bits(a.seg_k_perp, b.seg_k_perp) && same_bits(a.seg_c_uu, b.seg_c_uu) &&
         same_bits(a.seg_rate, b.seg_rate) && same_bits(a.node_dv, b.node_dv) &&
         same_bits(a.node_kz, b.node_kz);
}

// Sets kelp::tether::detail::wide_force_passes for a scope, then restores it.
struct WidePasses {
  explicit WidePasses(bool on) : before(kt::detail::wide_force_passes().exchange(on)) {}
  ~WidePasses() { kt::detail::wide_force_passes() = before; }
  bool before;
};

// A few steps of `step` from `s0`, with the AVX2 build allowed or not.
template <typename Step>
kt::TetherStated run_steps(const kt::TetherModeld& model, const kt::TetherStated& s0, bool wide,
                           int steps, Step&& step) {
  const WidePasses scope(wide);
  CHECK(kt::detail::force_passes_take_avx2() == wide);
  kt::TetherWorkspaced ws(model);
  kt::TetherStated s = s0;
  for (int k = 0; k < steps; ++k) step(ws, s);
  return s;
}

}  // namespace

TEST_CASE("the force passes' AVX2 build gives the baseline build's bits",
          "[tether][forces][simd]") {
#if defined(KELP_X86_DISPATCH)
  if (!__builtin_cpu_supports("avx2")) {
    WARN("this CPU has no AVX2: the baseline build is the only one");
    CHECK_FALSE(kt::detail::force_passes_take_avx2());
    return;
  }
  REQUIRE(kt::detail::force_passes_take_avx2());
  int compared = 0;
  for (const auto& c : cases<double>())
    for (int variant = 0; variant < 3; ++variant)
      for (bool jacobian : {false, true}) {
        // 0 as built, 1 a winch segment at the start (its own rest length), 2 a parted line.
        const kt::TetherModeld model(c.params);
        kt::TetherWorkspaced a(model), b(model);
        if (variant == 1) a.winch_length = b.winch_length = 0.4 * model.segment_length();
        if (variant == 2) {
          if (model.segments() < 3) continue;
          a.parted.setZero();
          a.parted(model.segments() / 2) = 1;
          a.any_parted = true;
          b.parted = a.parted;
          b.any_parted = true;
        }
        for (bool wide : {true, false}) {
          const WidePasses scope(wide);
          CHECK(kt::detail::force_passes_take_avx2() == wide);
          if (jacobian)
            kt::compute_forces<true>(model, wide ? a : b, c.water, 1.0, c.x, c.v);
          else
            kt::compute_forces(model, wide ? a : b, c.water, 1.0, c.x, c.v);
        }
        INFO(c.name << ", variant " << variant << (jacobian ? ", with Jacobian" : ""));
        CHECK(same_outputs(a, b));
        ++compared;
      }
  CHECK(compared > 60);

  // Whole steps: RK4 (the passes' accelerations) and BDF2 (forces, Jacobian terms, the
  // predictor and the accelerations after each step) on a line
  // swinging through the surface band from a boundary in air.
  auto p = kelp_test::benchmark_line<double>(37);
  p.internal_damping = 30.0;
  const kt::TetherModeld model(p);
  const kelp::environment::Environmentd water;
  const Vector3<double> a(0, 0, -0.3), b(10, 0, 5);
  kt::TetherStated s0 = kt::catenary_initial_state(model, water, a, b);
  for (int i = 0; i < model.nodes(); ++i) s0.velocity.col(i) = Vector3<double>(0.3, 0.2, -0.8);
  const auto bnd = kt::TetherBoundaryd::fixed(a, b);
  const double dt = kt::estimate_stable_dt(model, kt::Integrator::rk4, water.water_density(), 0.5);
  const auto rk4 = [&](kt::TetherWorkspaced& ws, kt::TetherStated& s) {
    kt::step_rk4(model, ws, water, s, bnd, dt);
  };
  const auto bdf2 = [&](kt::TetherWorkspaced& ws, kt::TetherStated& s) {
    kt::step_bdf2(model, ws, water, s, bnd, 0.01);
  };
  const kt::TetherStated r_wide = run_steps(model, s0, true, 200, rk4);
  const kt::TetherStated r_base = run_steps(model, s0, false, 200, rk4);
  CHECK(same_bits(r_wide.position, r_base.position));
  CHECK(same_bits(r_wide.velocity, r_base.velocity));
  CHECK_FALSE(same_bits(r_wide.position, s0.position));
  const kt::TetherStated i_wide = run_steps(model, s0, true, 100, bdf2);
  const kt::TetherStated i_base = run_steps(model, s0, false, 100, bdf2);
  CHECK(same_bits(i_wide.position, i_base.position));
  CHECK(same_bits(i_wide.velocity, i_base.velocity));
  // The implicit steps' own passes (kelp/tether/step_pass_body.hpp: predictor, accelerations)
  // take AVX2 with the force passes: the accelerations the predictor reads agree too.
  REQUIRE(i_wide.has_acceleration);
  CHECK(same_bits(i_wide.acceleration, i_base.acceleration));
  CHECK(i_wide.predict_from_acceleration == i_base.predict_from_acceleration);
  CHECK_FALSE(same_bits(i_wide.position, s0.position));
#else
  WARN("this build does not dispatch at run time: one build of the force passes only");
  CHECK_FALSE(kt::detail::force_passes_take_avx2());
#endif
}

// load3 / store3 of pack type P: the rows of P::lanes columns of a 3 × N matrix, and back.
template <typename P, typename Scalar>
void check_load3_store3() {
  constexpr int lanes = P::lanes;
  Scalar m[3 * lanes], back[3 * lanes], row[3][lanes];
  for (int j = 0; j < 3 * lanes; ++j) m[j] = Scalar(10 * (j % 3) + j / 3 + 1);  // 10 row + col + 1
  P x, y, z;
  P::load3(m, x, y, z);
  x.store(row[0]);
  y.store(row[1]);
  z.store(row[2]);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < lanes; ++i) CHECK(row[k][i] == Scalar(10 * k + i + 1));
  for (Scalar& b : back) b = Scalar(-1);
  P::store3(back, x, y, z);
  for (int j = 0; j < 3 * lanes; ++j) CHECK(back[j] == m[j]);
}

TEST_CASE("packs load and store the rows of 3 × N columns (load3, store3)",
          "[tether][forces][simd]") {
  check_load3_store3<kelp::simd::Pack<double, true>, double>();
  check_load3_store3<kelp::simd::Pack<double, false>, double>();
  check_load3_store3<kelp::simd::Pack<float, true>, float>();
  check_load3_store3<kelp::simd::Pack<float, false>, float>();
#if defined(KELP_X86_DISPATCH)
  if (__builtin_cpu_supports("avx2"))
    check_load3_store3<kelp::simd::detail::avx2::Pack4d, double>();
  else
    WARN("this CPU has no AVX2: its 4-double packs are not checked");
#endif
}

TEST_CASE("the packed interior-node kernel gives the general path's bits",
          "[tether][forces][simd]") {
  // A line with one segment parted far from both ends takes the general path (node_general) at
  // every node; the same line unparted takes the packed kernel (interior_block) at its wholly
  // wet interior nodes off the seabed. Away from the parted segment both must give the same bits:
  // the kernel is the general path's arithmetic for such nodes, not an approximation of it.
  int packed = 0, nodes_compared = 0;
  for (const auto& c : cases<double>())
    for (bool jacobian : {false, true}) {
      const kt::TetherModeld model(c.params);
      const int n = model.segments();
      if (n < 8) continue;
      const int p = n / 2;
      kt::TetherWorkspaced a(model), b(model);
      b.parted.setZero();
      b.parted(p) = 1;
      b.any_parted = true;
      for (kt::TetherWorkspaced* ws : {&a, &b}) {
        if (jacobian)
          kt::compute_forces<true>(model, *ws, c.water, 1.0, c.x, c.v);
        else
          kt::compute_forces(model, *ws, c.water, 1.0, c.x, c.v);
      }
      INFO(c.name << (jacobian ? ", with Jacobian" : ""));
      for (int i = 0; i <= n; ++i) {
        if (i == p || i == p + 1) continue;  // the ends of the parted segment
        INFO("node " << i);
        CHECK(same_bits(a.tangent.col(i), b.tangent.col(i)));
        CHECK(same_bits(a.mass_iso.row(i), b.mass_iso.row(i)));
        CHECK(same_bits(a.mass_tan.row(i), b.mass_tan.row(i)));
        CHECK(same_bits(a.mass_iso_inv.row(i), b.mass_iso_inv.row(i)));
        CHECK(same_bits(a.mass_tan_ratio.row(i), b.mass_tan_ratio.row(i)));
        CHECK(same_bits(a.submerged.row(i), b.submerged.row(i)));
        CHECK(same_bits(a.seabed_force.row(i), b.seabed_force.row(i)));
        if (jacobian) {
          CHECK(same_bits(a.node_dv.col(i), b.node_dv.col(i)));
          CHECK(same_bits(a.node_kz.row(i), b.node_kz.row(i)));
        }
        // The node force adds the neighbours' added-mass rate terms, which differ beside the
        // parted segment (its ends' chords are their own segments there).
        if (i != p - 1 && i != p + 2) CHECK(same_bits(a.force.col(i), b.force.col(i)));
        ++nodes_compared;
      }
      for (int i = 1; i < n; ++i)
        if (a.submerged(i) == 1.0 && a.seabed_force(i) == 0.0) ++packed;
    }
  // Wholly wet interior nodes off the seabed, which the packed kernel computes, were among them.
  CHECK(packed > 200);
  CHECK(nodes_compared > 300);
}

TEST_CASE("the force passes form the implicit step's residual γh F − M (v − v̂) on the free nodes",
          "[tether][forces][implicit]") {
  // Against the residual computed here from the evaluation's own forces, masses and tangents,
  // in the order of operations the implicit step documents: bit for bit on every free node of
  // every case (as built, at a winch, parted), with both builds of the passes; the kinematic
  // ends' columns are left alone, and a non-finite velocity makes the sum non-finite.
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  const double gh = 2.0 / 3.0 * 0.01;
  int compared = 0;
  for (const auto& c : cases<double>())
    for (int variant = 0; variant < 3; ++variant)
      for (bool wide : {true, false}) {
        const kt::TetherModeld model(c.params);
        kt::TetherWorkspaced ws(model);
        if (variant == 1) ws.winch_length = 0.4 * model.segment_length();
        if (variant == 2) {
          if (model.segments() < 3) continue;
          ws.parted.setZero();
          ws.parted(model.segments() / 2) = 1;
          ws.any_parted = true;
        }
        Matrix3X<double> v_hat = c.v;
        for (int i = 0; i < model.nodes(); ++i)
          for (int k = 0; k < 3; ++k) v_hat(k, i) += u(rng);
        const int f0 = model.first_free_node(), f1 = model.last_free_node();
        Matrix3X<double> rhs = Matrix3X<double>::Constant(3, model.nodes(), 12345.0);
        kt::detail::ImplicitResidual<double> res{v_hat.data(), gh, f0, f1, rhs.data()};
        const WidePasses scope(wide);
        kt::detail::evaluate_forces<false>(model, ws, c.water, 1.0, c.x, c.v,
                                           static_cast<double*>(nullptr), &res);
        Matrix3X<double> expected = rhs;
        double r_max = 0.0;
        for (int i = f0; i <= f1; ++i) {
          const Vector3<double> d = c.v.col(i) - v_hat.col(i), q = ws.tangent.col(i);
          const double a = ws.mass_iso(i);
          const double bqd = ws.mass_tan(i) * ((q(0) * d(0) + q(1) * d(1)) + q(2) * d(2));
          for (int k = 0; k < 3; ++k) {
            expected(k, i) = gh * ws.force(k, i) - (a * d(k) + bqd * q(k));
            r_max = std::max(r_max, std::abs(expected(k, i)) * ws.mass_iso_inv(i));
          }
        }
        INFO(c.name << ", variant " << variant << (wide ? ", AVX2 build" : ", baseline build"));
        CHECK(same_bits(rhs, expected));
        CHECK(res.r_max == r_max);
        CHECK((r_max > 0.0) == (f1 >= f0));  // N = 1 with both ends kinematic: none free
        CHECK(std::isfinite(res.sum));
        ++compared;
      }
  CHECK(compared > 60);

  // A NaN velocity at a free node reaches the sum.
  const auto c = cases<double>()[7];
  REQUIRE(c.params.segments == 20);
  const kt::TetherModeld model(c.params);
  kt::TetherWorkspaced ws(model);
  Matrix3X<double> v = c.v, rhs(3, model.nodes());
  v(1, model.nodes() / 2) = std::numeric_limits<double>::quiet_NaN();
  kt::detail::ImplicitResidual<double> res{c.v.data(), gh, model.first_free_node(),
                                           model.last_free_node(), rhs.data()};
  kt::detail::evaluate_forces<false>(model, ws, c.water, 1.0, c.x, v, static_cast<double*>(nullptr),
                                     &res);
  CHECK_FALSE(std::isfinite(res.sum));
}

TEST_CASE("compute_forces refuses a non-finite position or velocity at any node, on either build",
          "[tether][forces][bad_input]") {
  // The input check runs in the pass that moves x and v into the pass buffer: its packets, the
  // last packet that overlaps the one before, and the node-by-node copy of a strided input. A
  // NaN or an Inf at any coordinate is refused and named before any output is written; finite
  // values whose sum overflows are refused as such.
  const double bad_values[] = {std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(),
                               -std::numeric_limits<double>::infinity()};
  int refused = 0;
  for (int n : {9, 10, 11, 12}) {
    const kt::TetherModeld model(kelp_test::benchmark_line<double>(n));
    kt::TetherWorkspaced ws(model);
    const kelp_test::TestWater<double> water;
    const kt::TetherStated s = kt::catenary_initial_state(model, water, Vector3<double>(0, 0, 1),
                                                          Vector3<double>(15, 0, 6));
    for (bool wide : {false, true}) {
      const WidePasses scope(wide);
      kt::compute_forces(model, ws, water, 0.0, s.position, s.velocity);
      const Matrix3X<double> good = ws.force;
      for (bool strided : {false, true})
        for (int i = 0; i <= n; ++i)
          for (int k = 0; k < 3; ++k)
            for (double bad : bad_values)
              for (bool in_x : {true, false}) {
                INFO("N " << n << (wide ? ", AVX2 allowed" : ", baseline")
                          << (strided ? ", strided" : "") << ", node " << i << ", row " << k << ", "
                          << bad << " in " << (in_x ? "x" : "v"));
                Matrix3X<double> x = s.position, v = s.velocity;
                (in_x ? x : v)(k, i) = bad;
                // A strided copy: 4 rows per column, the passes read it with a column stride of 4.
                Eigen::MatrixXd x4 = Eigen::MatrixXd::Zero(4, n + 1), v4 = x4;
                x4.topRows(3) = x;
                v4.topRows(3) = v;
                const auto stride = Eigen::OuterStride<>(4);
                const Eigen::Map<const Matrix3X<double>, 0, Eigen::OuterStride<>> xs(x4.data(), 3,
                                                                                     n + 1, stride),
                    vs(v4.data(), 3, n + 1, stride);
                const auto call = [&] {
                  if (strided)
                    kt::compute_forces(model, ws, water, 0.0, xs, vs);
                  else
                    kt::compute_forces(model, ws, water, 0.0, x, v);
                };
                REQUIRE_THROWS_WITH(call(),
                                    Catch::Contains(in_x ? "compute_forces: x must be finite"
                                                         : "compute_forces: v must be finite"));
                REQUIRE(same_bits(ws.force, good));
                ++refused;
              }
      Matrix3X<double> x = s.position;
      x(0, n) = x(1, n) = 1.5e308;
      REQUIRE_THROWS_WITH(kt::compute_forces(model, ws, water, 0.0, x, s.velocity),
                          Catch::Contains("compute_forces: x and v overflow"));
      kt::compute_forces(model, ws, water, 0.0, s.position, s.velocity);
      REQUIRE(same_bits(ws.force, good));
    }
  }
  // Every node of each line, with both builds, both inputs, 3 rows and 3 values, in x and in v.
  CHECK(refused == 2 * 2 * 3 * 3 * 2 * (10 + 11 + 12 + 13));
}
