// The tether's winding angle about an obstacle (kelp/tether/winding.hpp) and the entanglement
// monitor (kelp/sim/entanglement.hpp): 0 for a line that passes by, 2π after one wrap, back to 0
// after unwrapping, continuous in between, unchanged by a node inserted on a segment; the
// `entangled` event at the orbit angle where the chord leaves the pile; `pinned` only while
// the line sticks at the contact with a tension difference across it.
#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/sim/entanglement.hpp"
#include "kelp/tether/winding.hpp"

namespace kt = kelp::tether;
namespace ksim = kelp::sim;
using V3 = kelp::Vector3<double>;

namespace {

const double kPi = kelp::pi;
// A vertical pile at the origin (NED: from the seabed at 20 m up to 1 m above the surface);
// its axis points up, so a positive angle turns from north towards west.
const V3 kFrom(0, 0, 20), kTo(0, 0, -1);
const double kRadius = 0.5;

// The point at angle a about the pile's axis (right-handed about "up"), radius r, depth z.
V3 around(double a, double r, double z) { return V3(r * std::cos(a), -r * std::sin(a), z); }

// A straight line of n segments from a to b, sagging by `sag` at its middle.
Eigen::Matrix3Xd straight(const V3& a, const V3& b, int n, double sag = 1.0) {
  Eigen::Matrix3Xd p(3, n + 1);
  for (int i = 0; i <= n; ++i) {
    const double s = double(i) / n;
    p.col(i) = a + s * (b - a) + V3(0, 0, 4 * sag * s * (1 - s));
  }
  return p;
}

// The boat (node 0) 20 m north of the pile at the surface; the line runs to the pile, round it
// on a circle of radius 0.6 m from angle 0 to the ROV's angle phi (either way), and out to the
// ROV at radius 3 m, 10 m deep: a line that follows a ROV orbiting the pile.
Eigen::Matrix3Xd orbit_line(double phi) {
  std::vector<V3> pts;
  const V3 boat(20, 0, 0);
  for (int i = 0; i < 20; ++i) pts.push_back(boat + (around(0, 0.6, 10) - boat) * (i / 20.0));
  const int arc = std::max(1, int(std::ceil(std::abs(phi) / (5 * kPi / 180))));
  for (int i = 0; i <= arc; ++i) pts.push_back(around(phi * i / arc, 0.6, 10));
  for (int i = 1; i <= 5; ++i) pts.push_back(around(phi, 0.6 + 2.4 * i / 5.0, 10));
  Eigen::Matrix3Xd p(3, pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) p.col(Eigen::Index(i)) = pts[i];
  return p;
}

double winding(const Eigen::Matrix3Xd& p) {
  return kt::winding_angle(p, kFrom, kTo, kRadius).angle;
}

// Distance from the axis (in the horizontal plane) to the chord boat → ROV at orbit angle phi.
double chord_distance(double phi) {
  const Eigen::Vector2d a(20, 0), b = around(phi, 3, 0).head<2>();
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp(-a.dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + s * ab).norm();
}

}  // namespace

TEST_CASE("winding: a line that passes by reads 0", "[sim][entanglement]") {
  const V3 boat(-30, 0, 0);
  // The ROV flies past the pile, 2 m to its east, from 10 m south to 10 m north.
  for (double x = -10; x <= 10; x += 0.5) {
    const Eigen::Matrix3Xd p = straight(boat, V3(x, 2, 10), 30);
    CHECK(std::abs(winding(p)) < 1e-9);
  }
  // A line pressed against the pile's side and bent round it a little, its chord outside it.
  Eigen::Matrix3Xd bent(3, 3);
  bent << -30, 0, 30,     //
      -0.9, -0.55, -0.9,  //
      5, 5, 5;
  const kt::Winding w = kt::winding_angle(bent, kFrom, kTo, kRadius);
  CHECK(std::abs(w.swept) > 0.05);  // the line does turn about the axis...
  CHECK(std::abs(w.angle) < 1e-9);  // ...but no more than its chord
}

TEST_CASE("winding: one wrap reads 2 pi, either way, and a node inserted changes nothing",
          "[sim][entanglement]") {
  const double sign = GENERATE(1.0, -1.0);
  const Eigen::Matrix3Xd p = orbit_line(sign * 2 * kPi);
  const double w = winding(p);
  INFO("winding " << w);
  CHECK(std::abs(w - sign * 2 * kPi) < 0.05);
  // A winch inserts a node in the middle of segment 0 (the boat's end).
  Eigen::Matrix3Xd q(3, p.cols() + 1);
  q.col(0) = p.col(0);
  q.col(1) = 0.5 * (p.col(0) + p.col(1));
  q.rightCols(p.cols() - 1) = p.rightCols(p.cols() - 1);
  CHECK(std::abs(winding(q) - w) < 1e-12);
  // Two wraps.
  CHECK(std::abs(winding(orbit_line(sign * 4 * kPi)) - sign * 4 * kPi) < 0.05);
}

TEST_CASE("winding: an orbit winds continuously to 2 pi and unwinds back to 0",
          "[sim][entanglement]") {
  // 0.1° steps out to one full orbit and back.
  const int n = 3600;
  double last = winding(orbit_line(0));
  CHECK(std::abs(last) < 1e-9);
  double max_step = 0;
  for (int k = 1; k <= 2 * n; ++k) {
    const int j = k <= n ? k : 2 * n - k;
    const double w = winding(orbit_line(2 * kPi * j / n));
    max_step = std::max(max_step, std::abs(w - last));
    last = w;
    if (k == n) CHECK(std::abs(w - 2 * kPi) < 0.05);
  }
  INFO("largest change in one 0.1 deg step " << max_step);
  // Continuous: the chord's blend spreads the 2π change over the pile's width (at 3 m orbit
  // radius, ~0.03 rad per 0.1°); without it the winding would jump by 2π.
  CHECK(max_step < 0.1);
  CHECK(std::abs(last) < 1e-9);
}

TEST_CASE("entanglement monitor: `entangled` fires once, where the chord leaves the pile",
          "[sim][entanglement]") {
  ksim::EntanglementAxis pile;
  pile.name = "pile";
  pile.from = kFrom;
  pile.to = kTo;
  pile.radius = kRadius;
  ksim::EntanglementMonitor m({pile});
  const int n = 3600;
  for (int k = 0; k <= n; ++k) {
    const Eigen::Matrix3Xd p = orbit_line(2 * kPi * k / n);
    m.update(double(k), p, Eigen::Matrix3Xd::Zero(3, p.cols()), Eigen::VectorXd());
  }
  REQUIRE(m.events().size() == 1);
  const ksim::EntanglementEvent& e = m.events()[0];
  CHECK(e.kind == ksim::EntanglementEvent::Kind::entangled);
  CHECK(std::string(ksim::event_name(e.kind)) == "entangled");
  // Expected: the first orbit angle past π where the chord is a radius clear of the axis.
  double expected = -1;
  for (int k = n / 2; k <= n; ++k)
    if (chord_distance(2 * kPi * k / n) >= kRadius) {
      expected = k;
      break;
    }
  INFO("event at step " << e.time << ", expected " << expected);
  CHECK(std::abs(e.time - expected) <= 1.0);
  CHECK(m.obstacle(0).max_abs_winding == Approx(2 * kPi).margin(0.05));
  CHECK(m.most_wound() == 0);
}

TEST_CASE("entanglement monitor: `pinned` needs sticking and a tension difference",
          "[sim][entanglement]") {
  ksim::EntanglementAxis cable;
  cable.name = "mooring";
  cable.from = V3(0, -5, 20);
  cable.to = V3(0, 5, 0);
  cable.radius = 0.02;
  ksim::EntanglementSettings s;
  s.pin_hold_time = 0.5;
  ksim::EntanglementMonitor m({cable}, s, 0.004);
  // A line across the cable (east-west... north-south), touching it at its middle node.
  const Eigen::Matrix3Xd p = straight(V3(-10, 0, 10 - 0.024), V3(10, 0, 10 - 0.024), 20, 0.0);
  const double speed = GENERATE(0.0, 0.1);
  const double difference = GENERATE(5.0, 30.0);
  Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, p.cols());
  v.row(0).setConstant(speed);  // along the line
  Eigen::VectorXd tension = Eigen::VectorXd::Constant(20, 50.0);
  tension.tail(10).array() += difference;  // the ROV's side (the far end) pulls harder
  for (int k = 0; k <= 100; ++k) m.update(0.01 * k, p, v, tension);
  CHECK(m.obstacle(0).contact_nodes >= 1);
  const bool expect = speed == 0.0 && difference > s.pin_tension_difference;
  INFO("speed " << speed << " difference " << difference);
  CHECK(m.obstacle(0).pinned == expect);
  CHECK(m.events().size() == (expect ? 1u : 0u));
  if (expect) CHECK(m.events()[0].time == Approx(0.5).margin(0.011));
}
