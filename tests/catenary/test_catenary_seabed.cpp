// Seabed contact in the 3-D helper: two catenaries with their vertices on a flat frictionless
// seabed and a straight grounded part between them.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/tether/catenary.hpp"

using kelp::tether::catenary_between;
using kelp::tether::CatenaryOptions;
using kelp::tether::CatenaryStatus;
using V3 = kelp::Vector3<double>;

namespace {

CatenaryOptions<double> seabed_at(double depth) {
  CatenaryOptions<double> o;
  o.seabed_depth = depth;
  return o;
}

// Independent solve of the symmetric case (both ends h above the seabed): L − D = 2(s − x) with
// s = sqrt(h² + 2ah), x = a acosh(1 + h/a), by bisection on ln a in long double.
long double symmetric_grounded_a(long double D, long double L, long double h) {
  long double lo = std::log(1e-9L), hi = std::log(1e9L);
  for (int i = 0; i < 200; ++i) {
    const long double mid = 0.5L * (lo + hi), a = std::exp(mid);
    const long double s = std::sqrt(h * h + 2 * a * h), x = a * std::acosh(1 + h / a);
    if (2 * (s - x) > L - D)
      lo = mid;
    else
      hi = mid;
  }
  return std::exp(0.5L * (lo + hi));
}

}  // namespace

TEST_CASE("seabed: symmetric grounded line against an independent solve", "[catenary][seabed]") {
  // Ends 3 m above a seabed at 13 m depth, 12 m apart, 16 m of tether: the free catenary would sag
  // ~4.5 m below the ends, so part of the line rests on the seabed (L − D = 4 < h1 + h2 = 6, so
  // the suspended parts keep a horizontal tension).
  const V3 start(0, 0, 10), end(12, 0, 10);
  const double w = 0.5, L = 16;
  const auto free_line = catenary_between(start, end, L, w);
  REQUIRE(free_line.lowest_point().z() > 13.0);
  const auto shape = catenary_between(start, end, L, w, seabed_at(13.0));
  REQUIRE(shape.status() == CatenaryStatus::converged);
  REQUIRE(shape.on_seabed());
  const double a_ref = double(symmetric_grounded_a(12, 16, 3));
  CHECK(shape.result().a == Approx(a_ref).epsilon(1e-12));
  CHECK(shape.horizontal_tension() == Approx(w * a_ref).epsilon(1e-12));
  // Grounded length from the same independent numbers: L_b = L − 2 s.
  const double s = std::sqrt(9.0 + 6.0 * a_ref);
  CHECK(shape.grounded_length() == Approx(L - 2 * s).epsilon(1e-10));
  // Ends carry the weight of their suspended parts; the seabed carries w L_b.
  const V3 fs = shape.force_on_start(), fe = shape.force_on_end();
  CHECK(fs.z() == Approx(w * s).epsilon(1e-10));
  CHECK(fs.z() + fe.z() + w * shape.grounded_length() == Approx(w * L).epsilon(1e-12));
  CHECK((fs.head<2>() + fe.head<2>()).norm() < 1e-12);
  CHECK(fs.x() == Approx(shape.horizontal_tension()));
}

TEST_CASE("seabed: shape, continuity and force balance over many geometries",
          "[catenary][seabed]") {
  const double w = 0.3, L = 25;
  int grounded = 0, grounded_with_tension = 0;
  for (double depth : {8.0, 12.0, 20.0}) {
    for (double z_end : {0.0, 3.0, 7.5}) {
      for (double D : {0.0, 2.0, 9.0, 16.0}) {
        const V3 start(1, -2, 0.5);
        const V3 end = start + V3(D * 0.8, D * 0.6, z_end - 0.5);
        const auto shape = catenary_between(start, end, L, w, seabed_at(depth));
        INFO("depth " << depth << " z_end " << z_end << " D " << D);
        REQUIRE((shape.status() == CatenaryStatus::converged ||
                 shape.status() == CatenaryStatus::vertical));
        grounded += shape.on_seabed();
        grounded_with_tension += shape.on_seabed() && shape.horizontal_tension() > 0;
        // Ends reproduced, no point below the seabed, polyline length -> L, unit-speed curve.
        CHECK((shape.point_at(0.0) - start).norm() < 1e-9);
        CHECK((shape.point_at(L) - end).norm() < 1e-9);
        double polyline = 0;
        const int n = 4000;
        V3 prev = shape.point_at(0.0);
        for (int i = 1; i <= n; ++i) {
          const V3 p = shape.point_at(L * i / n);
          CHECK(p.z() <= depth + 1e-9);
          polyline += (p - prev).norm();
          prev = p;
        }
        if (!shape.on_seabed() || shape.horizontal_tension() > 0) {
          CHECK(polyline == Approx(L).epsilon(1e-5));
        }
        const V3 fs = shape.force_on_start(), fe = shape.force_on_end();
        CHECK(fs.z() + fe.z() + w * shape.grounded_length() == Approx(w * L).epsilon(1e-10));
        CHECK((fs.head<2>() + fe.head<2>()).norm() < 1e-10);
        if (shape.on_seabed()) {
          CHECK(shape.lowest_point().z() == Approx(depth));
          CHECK(shape.grounded_length() >= 0);
          CHECK(shape.tension_at(0) == Approx(fs.norm()).epsilon(1e-10));
          CHECK(shape.tension_at(L) == Approx(fe.norm()).epsilon(1e-10));
        }
      }
    }
  }
  // The grid exercises free lines, grounded lines with tension and slack on the seabed.
  CHECK(grounded >= 10);
  CHECK(grounded_with_tension >= 4);
}

TEST_CASE("seabed: contact begins continuously", "[catenary][seabed]") {
  // Put the seabed just above the free line's lowest point: the grounded solution must be a small
  // perturbation of the free one (a, end forces), and just below it nothing changes.
  const V3 start(0, 0, 0), end(10, 0, -5);
  const double w = 0.181268, L = 20;
  const auto free_line = catenary_between(start, end, L, w);
  const double bottom = free_line.lowest_point().z();
  const auto below = catenary_between(start, end, L, w, seabed_at(bottom + 1e-6));
  CHECK_FALSE(below.on_seabed());
  CHECK(below.force_on_end() == free_line.force_on_end());
  const auto touching = catenary_between(start, end, L, w, seabed_at(bottom - 1e-6));
  REQUIRE(touching.on_seabed());
  CHECK(touching.grounded_length() < 1e-2);
  CHECK(touching.result().a == Approx(free_line.result().a).epsilon(1e-3));
  CHECK((touching.force_on_end() - free_line.force_on_end()).norm() < 1e-3);
}

TEST_CASE("seabed: slack on the seabed, vertical drops and invalid ends", "[catenary][seabed]") {
  // L >= h1 + h2 + D: H = 0, each end holds the weight of its vertical drop.
  const V3 start(0, 0, 2), end(3, 0, 4);
  const auto shape = catenary_between(start, end, 20.0, 0.5, seabed_at(10.0));
  REQUIRE(shape.on_seabed());
  CHECK(shape.horizontal_tension() == 0.0);
  CHECK(shape.force_on_start().z() == Approx(0.5 * 8));
  CHECK(shape.force_on_end().z() == Approx(0.5 * 6));
  CHECK(shape.grounded_length() == Approx(20.0 - 8 - 6));
  CHECK(shape.point_at(8.0).z() == Approx(10.0));
  CHECK((shape.point_at(20.0) - end).norm() < 1e-12);
  // Vertically aligned ends over the seabed.
  const auto vert = catenary_between(V3(0, 0, 1), V3(0, 0, 5), 30.0, 0.5, seabed_at(10.0));
  CHECK(vert.status() == CatenaryStatus::vertical);
  CHECK(vert.on_seabed());
  CHECK(vert.grounded_length() == Approx(30.0 - 9 - 5));
  // An end below the seabed is invalid input; a buoyant line never grounds.
  CHECK(catenary_between(V3(0, 0, 1), V3(5, 0, 11), 30.0, 0.5, seabed_at(10.0)).status() ==
        CatenaryStatus::invalid_input);
  CHECK_FALSE(catenary_between(start, end, 20.0, -0.5, seabed_at(10.0)).on_seabed());
}
