// Obstacles (kelp/environment/obstacles.hpp) and the tether's contact with them
// (kelp/tether/contact.hpp): closest-point queries against hand-worked values, the broad phase
// against brute force, the height-field file's errors, the contact blocks of the whole Jacobian
// against finite differences of compute_forces, no tunnelling through a thin cylinder at the
// default step, and the capstan relation T1/T2 = e^{μθ} of a line sliding over a cylinder.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/jacobian.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace ke = kelp::environment;
namespace kt = kelp::tether;
using Eigen::Vector3d;
using kelp::Matrix3X;

namespace {

ke::Cylinder cylinder(const Vector3d& a, const Vector3d& b, double r, double mu = 0.0) {
  ke::Cylinder c;
  c.name = "pile";
  c.from = a;
  c.to = b;
  c.radius = r;
  c.contact.friction = mu;
  return c;
}

}  // namespace

TEST_CASE("segment-segment and segment-capsule closest points match hand-worked values",
          "[obstacles]") {
  // Crossing segments 1 m apart: x axis at z = 0, y axis at z = 1.
  const auto sp = ke::closest_segment_segment<double>(Vector3d(-1, 0, 0), Vector3d(1, 0, 0),
                                                      Vector3d(0, -1, 1), Vector3d(0, 1, 1));
  CHECK(sp.s == Approx(0.5));
  CHECK(sp.t == Approx(0.5));
  CHECK(sp.distance2 == Approx(1.0));
  // Parallel, offset along their length: the end of one against the other.
  const auto par = ke::closest_segment_segment<double>(Vector3d(0, 0, 0), Vector3d(1, 0, 0),
                                                       Vector3d(2, 0, 3), Vector3d(3, 0, 3));
  CHECK(par.s == Approx(1.0));
  CHECK(par.t == Approx(0.0));
  CHECK(par.distance2 == Approx(1.0 + 9.0));
  // A vertical pile of radius 0.5 from z = 0 to 10 at the origin; a segment from (2, -1, 4) to
  // (2, 3, 4): closest at y = 0 (t = 1/4), 2 m from the axis, 1.5 m from the surface.
  const ke::Cylinder pile = cylinder(Vector3d(0, 0, 0), Vector3d(0, 0, 10), 0.5);
  const auto pr = ke::segment_capsule<double>(Vector3d(2, -1, 4), Vector3d(2, 3, 4), pile);
  CHECK(pr.distance == Approx(1.5));
  CHECK(pr.t == Approx(0.25));
  CHECK((pr.normal - Vector3d(1, 0, 0)).norm() < 1e-12);
  CHECK((pr.on_obstacle - Vector3d(0, 0, 4)).norm() < 1e-12);
  // Beyond the pile's end: the hemispherical cap (capsule), from the end point (0, 0, 10).
  const auto cap = ke::point_capsule<double>(Vector3d(3, 0, 14), pile);
  CHECK(cap.distance == Approx(5.0 - 0.5));
  // Inclined cylinder: from (0,0,0) to (10,0,10); the point (10, 0, 0) is √50 from the axis.
  const ke::Cylinder inclined = cylinder(Vector3d(0, 0, 0), Vector3d(10, 0, 10), 1.0);
  CHECK(ke::point_capsule<double>(Vector3d(10, 0, 0), inclined).distance ==
        Approx(std::sqrt(50.0) - 1.0));
  // Float queries of the same geometry.
  const auto prf =
      ke::segment_capsule<float>(Eigen::Vector3f(2, -1, 4), Eigen::Vector3f(2, 3, 4), pile);
  CHECK(prf.distance == Approx(1.5f));
}

TEST_CASE("point-box and segment-box queries match hand-worked values", "[obstacles]") {
  ke::Box box;
  box.center = Vector3d(10, 0, 5);
  box.half_extents = Vector3d(2, 1, 0.5);
  box.yaw = kelp::pi / 2;  // the box's x axis points east
  // In NED the box spans north 9..11, east −2..2, down 4.5..5.5.
  const auto face = ke::point_box<double>(Vector3d(13, 0.5, 5), box);
  CHECK(face.distance == Approx(2.0));
  CHECK((face.normal - Vector3d(1, 0, 0)).norm() < 1e-12);
  const auto corner = ke::point_box<double>(Vector3d(12, 3, 3.5), box);
  CHECK(corner.distance == Approx(std::sqrt(1.0 + 1.0 + 1.0)));
  CHECK((corner.on_obstacle - Vector3d(11, 2, 4.5)).norm() < 1e-12);
  // Inside, 0.2 m under the top face (z = 4.5): distance −0.2, normal up (−z).
  const auto inside = ke::point_box<double>(Vector3d(10.3, 0.1, 4.7), box);
  CHECK(inside.distance == Approx(-0.2));
  CHECK((inside.normal - Vector3d(0, 0, -1)).norm() < 1e-12);
  // A segment passing over the top at height 0.3 m above it: least distance 0.3 at its middle.
  const auto over = ke::segment_box<double>(Vector3d(5, -6, 4.2), Vector3d(15, 6, 4.2), box);
  CHECK(over.distance == Approx(0.3));
  CHECK(over.t > 0.3);
  CHECK(over.t < 0.7);
  CHECK((over.normal - Vector3d(0, 0, -1)).norm() < 1e-9);
  // A segment past a vertical edge (north 11, east 2), diagonal to it: distance to the edge.
  const auto edge = ke::segment_box<double>(Vector3d(13, 2, 3), Vector3d(11, 4, 6), box);
  CHECK(edge.distance == Approx(std::sqrt(2.0)).epsilon(1e-9));
  // A segment through the box, 0.1 m under its top face along its whole length inside: the
  // deepest point is at least 0.1 m in (the least depth over the faces along the segment).
  const auto through = ke::segment_box<double>(Vector3d(10, -5, 4.6), Vector3d(10, 5, 4.6), box);
  CHECK(through.distance == Approx(-0.1));
  CHECK((through.normal - Vector3d(0, 0, -1)).norm() < 1e-12);
  // Brute force: the least sampled distance never beats the exact minimum.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const Vector3d a = box.center + Vector3d(4 * u(rng), 4 * u(rng), 2 * u(rng));
    const Vector3d b = box.center + Vector3d(4 * u(rng), 4 * u(rng), 2 * u(rng));
    const double exact = ke::segment_box<double>(a, b, box).distance;
    double sampled = 1e9;
    for (int k = 0; k <= 2000; ++k)
      sampled = std::min(sampled, ke::point_box<double>(a + (b - a) * (k / 2000.0), box).distance);
    CHECK(exact <= sampled + 1e-12);
    CHECK(exact >= sampled - 5e-3);
  }
}

TEST_CASE("height field: bilinear depth, slope and normal, edge depth outside", "[obstacles]") {
  ke::HeightField hf;
  hf.origin = Eigen::Vector2d(0, 0);
  hf.spacing = Eigen::Vector2d(10, 20);
  hf.rows = 2;
  hf.cols = 2;
  hf.depth = {10, 12, 14, 20};  // (0,0) 10, (0,20) 12, (10,0) 14, (10,20) 20
  const auto s = ke::sample_heightfield<double>(hf, 5.0, 10.0);
  CHECK(s.depth == Approx(0.25 * (10 + 12 + 14 + 20)));
  CHECK(s.slope_north == Approx(0.5 * ((14 - 10) + (20 - 12)) / 10.0));
  CHECK(s.slope_east == Approx(0.5 * ((12 - 10) + (20 - 14)) / 20.0));
  CHECK(s.normal.norm() == Approx(1.0));
  CHECK(s.normal.z() < 0);
  // Outside the grid: the nearest edge's depth.
  CHECK(ke::sample_heightfield<double>(hf, -50.0, 0.0).depth == Approx(10.0));
  CHECK(ke::sample_heightfield<double>(hf, 100.0, 100.0).depth == Approx(20.0));
  // A point 1 m above a flat part: distance 1 along the normal.
  ke::HeightField flat = hf;
  flat.depth = {30, 30, 30, 30};
  const auto p = ke::point_heightfield<double>(Vector3d(3, 4, 29), flat);
  CHECK(p.distance == Approx(1.0));
  CHECK((p.normal - Vector3d(0, 0, -1)).norm() < 1e-12);
}

TEST_CASE("obstacles refuse bad input with kelp::invalid_argument", "[obstacles]") {
  ke::ObstacleSet set;
  CHECK_THROWS_AS(set.add(cylinder(Vector3d(0, 0, 0), Vector3d(0, 0, 0), 1.0)),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(set.add(cylinder(Vector3d(0, 0, 0), Vector3d(0, 0, 1), -1.0)),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(set.add(cylinder(Vector3d(0, 0, NAN), Vector3d(0, 0, 1), 1.0)),
                  kelp::invalid_argument);
  ke::Cylinder c = cylinder(Vector3d(0, 0, 0), Vector3d(0, 0, 1), 1.0);
  c.contact.friction = -0.1;
  CHECK_THROWS_AS(set.add(c), kelp::invalid_argument);
  ke::Box b;
  b.half_extents = Vector3d(1, 0, 1);
  CHECK_THROWS_AS(set.add(b), kelp::invalid_argument);
  ke::HeightField hf;
  hf.rows = 2;
  hf.cols = 2;
  hf.depth = {1, 2, 3};
  CHECK_THROWS_AS(set.set_seabed(hf), kelp::invalid_argument);
  CHECK(set.empty());
}

TEST_CASE("broad phase: each obstacle whose box overlaps the query, once, as brute force finds",
          "[obstacles]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  ke::ObstacleSet set;
  for (int k = 0; k < 60; ++k) {
    const Vector3d a(200 * u(rng), 200 * u(rng), 50 * u(rng));
    set.add(cylinder(a, a + Vector3d(10 * u(rng) - 5, 30 * u(rng) - 15, 20 * u(rng) + 0.1),
                     0.2 + u(rng)));
    ke::Box b;
    b.center = Vector3d(200 * u(rng), 200 * u(rng), 50 * u(rng));
    b.half_extents = Vector3d(0.5 + 5 * u(rng), 0.5 + 5 * u(rng), 0.5 + 2 * u(rng));
    b.yaw = 6 * u(rng);
    set.add(b);
  }
  for (int trial = 0; trial < 300; ++trial) {
    ke::Aabb q;
    q.lo = Vector3d(220 * u(rng) - 10, 220 * u(rng) - 10, 60 * u(rng) - 5);
    q.hi = q.lo + Vector3d(20 * u(rng), 20 * u(rng), 20 * u(rng));
    std::vector<int> seen(std::size_t(set.size()), 0);
    set.for_each_near(
        q, [&](ke::ObstacleRef r) { ++seen[std::size_t(kt::detail::flat_index(set, r))]; });
    for (int o = 0; o < set.size(); ++o) {
      const ke::ObstacleRef r =
          o < int(set.cylinders().size())
              ? ke::ObstacleRef{ke::ObstacleRef::cylinder, o}
              : ke::ObstacleRef{ke::ObstacleRef::box, o - int(set.cylinders().size())};
      CHECK(seen[std::size_t(o)] == (set.bounds(r).overlaps(q) ? 1 : 0));
    }
  }
}

namespace {

// A short line (10 segments of 0.2 m, d 2 cm) for the Jacobian checks.
kt::TetherParameters<double> jacobian_line() {
  kt::TetherParameters<double> p;
  p.segments = 10;
  p.length = 2.0;
  p.diameter = 0.02;
  p.mass_per_length = 0.3;
  p.axial_stiffness = 2e3;
  p.internal_damping = 5.0;
  p.seabed_stiffness = 1e5;
  p.seabed_damping = 1e4;
  p.seabed_damping_depth = 0.01;
  p.seabed_friction = 0.4;
  p.friction_velocity = 0.05;
  return p;
}

// Whole Jacobian (kelp/tether/jacobian.hpp) against central differences of compute_forces.
// Returns the largest error over tolerance, ∞ if no contact is in play.
double jacobian_error(const ke::Environment<double>& env, const Matrix3X<double>& x,
                      const Matrix3X<double>& v, std::string& where) {
  const kt::TetherModel<double> model(jacobian_line());
  kt::TetherWorkspace<double> ws(model);
  const int nodes = model.nodes(), m = 3 * nodes;
  kt::compute_forces<true>(model, ws, env, 0.0, x, v);
  if (!ws.any_contact) return std::numeric_limits<double>::infinity();
  kt::ForceJacobian<double> jac(model);
  kt::force_jacobian(model, ws, env, x, v, Matrix3X<double>::Zero(3, nodes).eval(), jac);
  const auto dense = [&](const Eigen::Matrix<double, 9, Eigen::Dynamic>& store) {
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m, m);
    for (int i = 0; i < nodes; ++i)
      for (int j = std::max(0, i - 2); j <= std::min(nodes - 1, i + 2); ++j)
        a.block<3, 3>(3 * i, 3 * j) =
            Eigen::Map<const Eigen::Matrix3d>(store.col(kt::detail::band_block_index(i, j)).data());
    return a;
  };
  const Eigen::MatrixXd ax = dense(jac.dfdx), av = dense(jac.dfdv);
  const double h = 1e-7;
  double worst = 0;
  for (int which = 0; which < 2; ++which)
    for (int c = 0; c < m; ++c) {
      Matrix3X<double> xx = x, vv = v;
      Matrix3X<double>& z = which == 0 ? xx : vv;
      z(c % 3, c / 3) += h;
      kt::compute_forces(model, ws, env, 0.0, xx, vv);
      const Matrix3X<double> fp = ws.force;
      z(c % 3, c / 3) -= 2 * h;
      kt::compute_forces(model, ws, env, 0.0, xx, vv);
      const Matrix3X<double> fm = ws.force;
      const Eigen::Map<const Eigen::VectorXd> a(fp.data(), m), b(fm.data(), m);
      const Eigen::VectorXd fd = (a - b) / (2 * h);
      const Eigen::MatrixXd& an = which == 0 ? ax : av;
      const double col = fd.cwiseAbs().maxCoeff();
      for (int i = 0; i < m; ++i) {
        const double tol = 1e-3 + 1e-4 * std::abs(fd(i)) + 1e-6 * col;
        const double e = std::abs(an(i, c) - fd(i)) / tol;
        if (e > worst) {
          worst = e;
          where = std::string(which == 0 ? "dF/dx" : "dF/dv") + " row " + std::to_string(i) +
                  " col " + std::to_string(c) + ": analytic " + std::to_string(an(i, c)) + ", fd " +
                  std::to_string(fd(i));
        }
      }
    }
  return worst;
}

// A straight line of 11 nodes along north at depth z, with a small random wave, sliding.
void line_state(double z, unsigned seed, Matrix3X<double>& x, Matrix3X<double>& v) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  x.resize(3, 11);
  v.resize(3, 11);
  for (int i = 0; i <= 10; ++i) {
    x.col(i) = Vector3d(-1.0 + 0.2 * i + 0.01 * u(rng), 0.03 * u(rng), z + 0.004 * u(rng));
    v.col(i) = Vector3d(0.3 + 0.1 * u(rng), 0.2 * u(rng), 0.05 * u(rng));
  }
}

}  // namespace

TEST_CASE("contact blocks of the whole Jacobian match finite differences", "[obstacles]") {
  std::string where;
  SECTION("segment against a horizontal capsule, normal and sliding friction") {
    ke::ObstacleSet set;
    ke::Cylinder c = cylinder(Vector3d(0.13, -2, 5.3), Vector3d(0.1, 2, 5.3), 0.3, 0.5);
    c.contact.stiffness = 1e5;
    c.contact.damping = 1e3;
    set.add(c);
    ke::Environment<double> env;
    env.set_obstacles(set);
    for (unsigned seed : {1u, 2u, 3u}) {
      Matrix3X<double> x, v;
      line_state(5.0 + 0.005, seed, x, v);  // 5 mm into the capsule (r 0.3 + d/2 0.01)
      const double e = jacobian_error(env, x, v, where);
      INFO(where);
      CHECK(e < 1.0);
    }
  }
  SECTION("segment against a turned box, normal and friction") {
    ke::ObstacleSet set;
    ke::Box b;
    b.center = Vector3d(0.05, 0.0, 5.5);
    b.half_extents = Vector3d(0.4, 0.6, 0.5);
    b.yaw = 0.3;
    b.pitch = 0.05;
    b.contact.stiffness = 1e5;
    b.contact.damping = 1e3;
    b.contact.friction = 0.3;
    set.add(b);
    ke::Environment<double> env;
    env.set_obstacles(set);
    for (unsigned seed : {4u, 5u}) {
      Matrix3X<double> x, v;
      line_state(5.0 + 0.006, seed, x, v);
      const double e = jacobian_error(env, x, v, where);
      INFO(where);
      CHECK(e < 1.0);
    }
  }
  SECTION("nodes against a sloping height field, normal and friction") {
    ke::ObstacleSet set;
    ke::HeightField hf;
    hf.origin = Eigen::Vector2d(-2, -2);
    hf.spacing = Eigen::Vector2d(1.0, 2.0);
    hf.rows = 5;
    hf.cols = 3;
    hf.depth = {5.2, 5.3, 5.1, 5.0, 5.05, 5.1, 4.95, 5.0, 5.02, 5.1, 5.0, 4.9, 5.2, 5.1, 5.0};
    set.set_seabed(hf);
    ke::Environment<double> env;
    env.set_obstacles(set);
    for (unsigned seed : {6u, 7u}) {
      Matrix3X<double> x, v;
      line_state(5.1, seed, x, v);
      const double e = jacobian_error(env, x, v, where);
      INFO(where);
      CHECK(e < 1.0);
    }
  }
}

TEST_CASE("the check can fail: contact blocks left out of the whole Jacobian are seen",
          "[obstacles]") {
  // The same comparison against a Jacobian without contact terms (the environment without
  // obstacles for the analytic part) must report a large error.
  ke::ObstacleSet set;
  ke::Cylinder c = cylinder(Vector3d(0.13, -2, 5.3), Vector3d(0.1, 2, 5.3), 0.3, 0.5);
  c.contact.stiffness = 1e5;
  c.contact.damping = 1e3;
  set.add(c);
  ke::Environment<double> with, without;
  with.set_obstacles(set);
  Matrix3X<double> x, v;
  line_state(5.005, 1, x, v);
  const kt::TetherModel<double> model(jacobian_line());
  kt::TetherWorkspace<double> ws(model);
  kt::ForceJacobian<double> jac(model), bare(model);
  kt::compute_forces<true>(model, ws, with, 0.0, x, v);
  kt::force_jacobian(model, ws, with, x, v, Matrix3X<double>::Zero(3, 11).eval(), jac);
  kt::force_jacobian(model, ws, without, x, v, Matrix3X<double>::Zero(3, 11).eval(), bare);
  REQUIRE(ws.any_contact);
  CHECK((jac.dfdx - bare.dfdx).cwiseAbs().maxCoeff() > 100.0);  // k d l ~ 400 N/m
}

TEST_CASE("no obstacles: the forces are those of an environment without any", "[obstacles]") {
  const kt::TetherModel<double> model(jacobian_line());
  kt::TetherWorkspace<double> a(model), b(model);
  Matrix3X<double> x, v;
  line_state(5.0, 9, x, v);
  ke::Environment<double> env, far;
  ke::ObstacleSet set;
  set.add(cylinder(Vector3d(100, 0, 0), Vector3d(100, 0, 10), 1.0, 0.5));
  far.set_obstacles(set);
  kt::compute_forces<true>(model, a, env, 0.0, x, v);
  kt::compute_forces<true>(model, b, far, 0.0, x, v);
  CHECK(a.force == b.force);
  CHECK(!b.any_contact);
  CHECK(b.contact_force.isZero(0.0));
  env.set_obstacles(ke::ObstacleSet{});
  CHECK(env.obstacles() == nullptr);
}

TEST_CASE("a node driven at speed toward a thin cylinder at the default step does not pass it",
          "[obstacles]") {
  // A slack line (3.2 m, 32 segments) lying across at 10 m depth between ends 2.9 m apart, both
  // ends carried north at 3 m/s into a pile of radius 3 cm that stands between two nodes: a
  // node moves by the pile's radius in each 10 ms step. The segments see the pile wherever they
  // cross it, so the line wraps it instead of passing through. The pile's contact properties are
  // the defaults (MoorDyn's stiffness 3e6 Pa/m); when this was written the closest segment's axis
  // came within 31.3 mm of the pile's axis (pile radius 30 mm, line radius 4 mm).
  kt::TetherParameters<double> p;
  p.segments = 32;
  p.length = 3.2;
  p.diameter = 0.008;
  p.normal_drag = 0.0;  // the line coasts into the pile at full speed
  p.tangential_drag = 0.0;
  const kt::TetherModel<double> model(p);
  kt::TetherWorkspace<double> ws(model);
  kt::TetherState<double> st(model);
  const double pile_x = 0.3, pile_y = 0.045, speed = 3.0, dt = 0.01, half = 1.45;
  ke::ObstacleSet set;
  ke::Cylinder pile = cylinder(Vector3d(pile_x, pile_y, 0), Vector3d(pile_x, pile_y, 20), 0.03);
  set.add(pile);
  ke::Environment<double> env;
  env.set_obstacles(set);
  for (int i = 0; i <= 32; ++i) {
    st.position.col(i) = Vector3d(0, -half + 2 * half * i / 32.0, 10);
    st.velocity.col(i) = Vector3d(speed, 0, 0);
  }
  kt::TetherBoundary<double> b;
  double least = 1e9;
  bool touched = false;
  for (int k = 0; k < 25; ++k) {
    const double t = k * dt;
    b.start.position = Vector3d(speed * t, -half, 10);
    b.start.velocity = Vector3d(speed, 0, 0);
    b.end.position = Vector3d(speed * t, half, 10);
    b.end.velocity = Vector3d(speed, 0, 0);
    kt::step(model, ws, env, st, b, dt);
    touched = touched || ws.any_contact;
    for (int s = 0; s < 32; ++s) {
      const auto pr = ke::segment_capsule<double>(st.position.col(s), st.position.col(s + 1), pile);
      least = std::min(least, pr.distance + pile.radius);  // from the pile's axis
    }
  }
  INFO("least distance of a segment from the pile's axis " << least << " m");
  CHECK(least > 0.5 * pile.radius);
  // The nodes beside the pile stayed south of it; the ends went on 0.4 m past it.
  for (int i : {16, 17}) CHECK(st.position(0, i) < pile_x);
  CHECK(st.position(0, 0) > pile_x + 0.4);
  CHECK(touched);
}

namespace {

// A weightless line (neutrally buoyant, no drag) draped over a horizontal cylinder of radius R
// (axis along east at depth z0), wrap angle θ: the far end hangs vertically with a point mass M
// (T2 = M g), the start end is pulled at `speed` along the leaving tangent. Returns T1/T2 in
// steady sliding (the tensions of the two straight parts, averaged over the last 3 s).
double capstan_ratio(double mu, double theta) {
  const double R = 0.5, d = 0.01, z0 = 10.0, M = 2.0, speed = 0.02;
  const double rho = kelp::seawater_density;
  const double l = 0.04, hang = 1.2, lead = 1.2;
  const double rho_c = R + 0.5 * d;
  const double arc = rho_c * theta;
  const int n = int(std::round((lead + arc + hang) / l));
  kt::TetherParameters<double> p;
  p.segments = n;
  p.length = n * l;
  p.diameter = d;
  p.mass_per_length = rho * kelp::pi * 0.25 * d * d;  // neutrally buoyant
  p.axial_stiffness = 2e4;
  p.internal_damping = 100.0;
  p.normal_drag = 0.0;
  p.tangential_drag = 0.0;
  p.start_mode = kt::EndMode::kinematic;
  p.end_mode = kt::EndMode::free;
  p.end_point_mass = M;
  const kt::TetherModel<double> model(p);
  kt::TetherWorkspace<double> ws(model);
  kt::TetherState<double> st(model);
  ke::ObstacleSet set;
  ke::Cylinder c = cylinder(Vector3d(0, -1, z0), Vector3d(0, 1, z0), R, mu);
  c.contact.friction_velocity = 1e-3;
  set.add(c);
  ke::Environment<double> env;
  env.set_obstacles(set);
  // Lay the line by arc length from the pulled end: straight lead, arc, vertical drop; each
  // part pre-stretched by the tension it will carry.
  const Vector3d lead_dir(std::sin(theta), 0, -std::cos(theta));  // away from the cylinder
  const Vector3d arc_end(rho_c * -std::cos(theta), 0, z0 - rho_c * std::sin(theta));
  const double T2 = M * kelp::standard_gravity, T1 = T2 * std::exp(mu * theta);
  const auto point_at = [&](double s) -> Vector3d {
    if (s < lead) return arc_end + (lead - s) * lead_dir;
    if (s < lead + arc) {
      const double a = theta - (s - lead) / rho_c;
      return Vector3d(-rho_c * std::cos(a), 0, z0 - rho_c * std::sin(a));
    }
    return Vector3d(-rho_c, 0, z0 + (s - lead - arc));
  };
  double s = 0;
  for (int i = 0; i <= n; ++i) {
    st.position.col(i) = point_at(s);
    const double frac = std::min(1.0, s / (lead + arc + hang));
    s += l * (1.0 + (T1 + (T2 - T1) * frac) / p.axial_stiffness);
  }
  kt::TetherBoundary<double> b;
  const Vector3d start0 = st.position.col(0);
  const double dt = 0.01, ramp = 1.0, duration = 9.0, average_from = 6.0;
  double t1 = 0, t2 = 0;
  int samples = 0;
  for (int k = 0; k * dt < duration; ++k) {
    const double t = k * dt;
    // Speed ramps up over `ramp` seconds: x(t) = v (t − ramp/2) after it.
    const double dist = t < ramp ? speed * t * t / (2 * ramp) : speed * (t - 0.5 * ramp);
    const double vel = t < ramp ? speed * t / ramp : speed;
    b.start.position = start0 + dist * lead_dir;
    b.start.velocity = vel * lead_dir;
    b.start.acceleration = (t < ramp ? speed / ramp : 0.0) * lead_dir;
    kt::step(model, ws, env, st, b, dt);
    if (t >= average_from) {
      t1 += ws.tension(0);
      t2 += ws.tension(n - 1);
      ++samples;
    }
  }
  return (t1 / samples) / (t2 / samples);
}

}  // namespace

TEST_CASE("capstan: a line sliding over a cylinder has T1/T2 = exp(mu theta) within 2 %",
          "[obstacles][capstan]") {
  const double half_pi = 0.5 * kelp::pi;
  for (double mu : {0.1, 0.3, 0.5})
    for (double theta : {half_pi, 0.75 * kelp::pi, kelp::pi}) {
      const double ratio = capstan_ratio(mu, theta), expected = std::exp(mu * theta);
      const double error = ratio / expected - 1.0;
      std::printf("capstan mu %.1f theta %.4f: T1/T2 %.4f, exp(mu theta) %.4f, error %+.2f %%\n",
                  mu, theta, ratio, expected, 100 * error);
      INFO("mu " << mu << " theta " << theta << ": T1/T2 " << ratio << ", e^{mu theta} "
                 << expected);
      CHECK(std::abs(error) < 0.02);
    }
  // Frictionless: the tension passes over unchanged.
  CHECK(capstan_ratio(0.0, kelp::pi) == Approx(1.0).epsilon(0.01));
}

TEST_CASE("steps with obstacles allocate nothing, with the symmetric and the whole Jacobian",
          "[obstacles]") {
  // A slack line lying across a capsule and a box onto a sloping height field.
  kt::TetherParameters<double> p = jacobian_line();
  p.segments = 20;
  p.length = 4.0;
  p.mass_per_length = 1.0;  // sinks (the Jacobian line is slightly buoyant)
  const kt::TetherModel<double> model(p);
  ke::ObstacleSet set;
  set.add(cylinder(Vector3d(-1, -2, 5.3), Vector3d(-1, 2, 5.3), 0.3, 0.4));
  ke::Box b;
  b.center = Vector3d(0.5, 0, 5.6);
  b.half_extents = Vector3d(0.3, 1, 0.3);
  b.contact.friction = 0.2;
  set.add(b);
  ke::HeightField hf;
  hf.origin = Eigen::Vector2d(-5, -5);
  hf.spacing = Eigen::Vector2d(5, 5);
  hf.rows = hf.cols = 3;
  hf.depth = {5.8, 5.9, 6.0, 5.9, 5.95, 6.0, 6.0, 6.05, 6.1};
  set.set_seabed(hf);
  ke::Environment<double> env;
  env.set_obstacles(set);
  for (kt::JacobianKind kind : {kt::JacobianKind::adaptive, kt::JacobianKind::whole}) {
    kt::TetherWorkspace<double> ws(model);
    kt::TetherState<double> st(model);
    for (int i = 0; i <= 20; ++i) st.position.col(i) = Vector3d(-1.8 + 0.18 * i, 0, 4.99);
    const kt::TetherBoundary<double> bnd =
        kt::TetherBoundary<double>::fixed(st.position.col(0), st.position.col(20));
    kt::ImplicitOptions<double> io;
    io.jacobian = kind;
    const kt::StepOptions<double> options(kt::Integrator::bdf2, io);
    kt::step(model, ws, env, st, bnd, 0.01, options);  // first step: BDF2 starts with Euler
    struct NoMalloc {                                  // allowed again however the loop ends
      NoMalloc() { Eigen::internal::set_is_malloc_allowed(false); }
      ~NoMalloc() { Eigen::internal::set_is_malloc_allowed(true); }
    };
    {
      const NoMalloc guard;
      // The line lands on the capsule and flat on the box (impacts: steps split, Newton
      // retried), then rests on them.
      for (int k = 0; k < 100; ++k) kt::step(model, ws, env, st, bnd, 0.01, options);
    }
    CHECK(ws.any_contact);
    CHECK(st.position.allFinite());
    // The node over the box (top at z 5.3) rests on it, not in it.
    CHECK(st.position(2, 12) < 5.3 + 0.005);
  }
}

TEST_CASE("contact forces of a float tether agree with the double one", "[obstacles]") {
  ke::ObstacleSet set;
  ke::Cylinder c = cylinder(Vector3d(0.13, -2, 5.3), Vector3d(0.1, 2, 5.3), 0.3, 0.5);
  c.contact.damping = 1e3;
  set.add(c);
  ke::Box b;
  b.center = Vector3d(0.7, 0, 5.5);
  b.half_extents = Vector3d(0.2, 0.5, 0.5);
  set.add(b);
  ke::Environment<double> env;
  ke::Environment<float> envf;
  env.set_obstacles(set);
  envf.set_obstacles(set);
  Matrix3X<double> x, v;
  line_state(5.005, 1, x, v);
  const kt::TetherModel<double> model(jacobian_line());
  kt::TetherParameters<float> pf;
  const kt::TetherParameters<double> pd = jacobian_line();
  pf.segments = pd.segments;
  pf.length = float(pd.length);
  pf.diameter = float(pd.diameter);
  pf.mass_per_length = float(pd.mass_per_length);
  pf.axial_stiffness = float(pd.axial_stiffness);
  const kt::TetherModel<float> mf(pf);
  kt::TetherWorkspace<double> ws(model);
  kt::TetherWorkspace<float> wsf(mf);
  kt::compute_forces(model, ws, env, 0.0, x, v);
  kt::compute_forces(mf, wsf, envf, 0.0, x.cast<float>().eval(), v.cast<float>().eval());
  REQUIRE(ws.any_contact);
  REQUIRE(wsf.any_contact);
  const double scale = ws.contact_force.cwiseAbs().maxCoeff();
  CHECK((wsf.contact_force.cast<double>() - ws.contact_force).cwiseAbs().maxCoeff() < 1e-3 * scale);
}
