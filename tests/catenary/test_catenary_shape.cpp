// The 3-D helper: shape by arc length, lowest point, tensions and force balance in NED.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/tether/catenary.hpp"

using kelp::tether::catenary_between;
using kelp::tether::CatenaryStatus;
using V3 = kelp::Vector3<double>;

// Every public class for every supported plain scalar (the Jet instantiations are in
// test_catenary_jet.cpp).
template class kelp::tether::CatenaryShape<double>;
template class kelp::tether::CatenaryShape<float>;
template struct kelp::tether::CatenaryResult<float>;
template struct kelp::tether::CatenaryOptions<float>;

namespace {
// docs/equations.md (benchmark line): d = 8 mm, 0.07 kg/m, rho = 1025, g = 9.81 -> w = 0.181268
// N/m.
const double kPi = 3.14159265358979323846;
const double kW = (0.07 - 1025.0 * kPi * 0.004 * 0.004) * 9.81;

// Independent of the solver: a of the paper's equations from 2a sinh(D/2a) = sqrt(L² − dz²) by
// bisection on u = D/(2a) in long double, then c = D/2 − a atanh(dz/L).
void independent_catenary(long double D, long double dz, long double L, long double& a,
                          long double& c) {
  const long double target = std::sqrt(L * L - dz * dz) / D;  // sinh(u)/u
  long double lo = 0.0L, hi = 100.0L;
  for (int i = 0; i < 200; ++i) {
    const long double u = 0.5L * (lo + hi);
    if (std::sinh(u) / u > target)
      hi = u;
    else
      lo = u;
  }
  a = D / (lo + hi);  // D / (2u)
  c = 0.5L * D - a * std::atanh(dz / L);
}
}  // namespace

TEST_CASE("3-D reference case: H, V and |T| at both ends to 6 digits", "[catenary][shape]") {
  // Start (ASV end) at the surface, end 10 m away horizontally (direction N-E) and 5 m higher.
  const V3 start(1.0, 2.0, 0.0);
  const V3 dir(0.6, 0.8, 0.0);
  const V3 end = start + 10.0 * dir + V3(0, 0, -5.0);
  const auto shape = catenary_between(start, end, 20.0, kW);
  REQUIRE(shape.status() == CatenaryStatus::converged);
  CHECK(kW == Approx(0.181268).epsilon(3e-6));
  CHECK(shape.horizontal_tension() == Approx(0.427536).epsilon(2e-6));
  const V3 fs = shape.force_on_start(), fe = shape.force_on_end();
  // Upper end (the end point): V = 2.279101, |T| = 2.318855; lower: V = 1.346259, |T| = 1.412516.
  CHECK(fe.z() == Approx(2.279101).epsilon(2e-6));
  CHECK(fe.norm() == Approx(2.318855).epsilon(2e-6));
  CHECK(fs.z() == Approx(1.346259).epsilon(2e-6));
  CHECK(fs.norm() == Approx(1.412516).epsilon(2e-6));
  // Horizontal parts point along the plane, toward the other end.
  CHECK(fs.head<2>().dot(dir.head<2>()) == Approx(shape.horizontal_tension()));
  CHECK((fs.head<2>() + fe.head<2>()).norm() < 1e-14);
  CHECK((shape.point_at(0.0) - start).norm() < 1e-12);
  CHECK((shape.point_at(20.0) - end).norm() < 1e-12);
}

TEST_CASE("force balance and shape over many geometries", "[catenary][shape]") {
  // The cable's weight w L must be carried by the two ends (sum of the NED z forces on the
  // attachments = w L) and the horizontal forces cancel; both for hanging and buoyant lines.
  for (double w : {kW, -0.3}) {
    for (double dz_ned : {-8.0, -1.0, 0.0, 3.0, 9.0}) {
      for (double D : {0.5, 4.0, 11.0}) {
        const double L = 20.0;
        const V3 start(0.0, 0.0, 5.0);
        const V3 end = start + V3(D * std::cos(0.3), D * std::sin(0.3), dz_ned);
        const auto shape = catenary_between(start, end, L, w);
        REQUIRE(shape.status() == CatenaryStatus::converged);
        const V3 fs = shape.force_on_start(), fe = shape.force_on_end();
        CHECK(fs.z() + fe.z() == Approx(w * L).epsilon(1e-11));
        CHECK((fs.head<2>() + fe.head<2>()).norm() < 1e-12 * (1 + fs.norm()));
        CHECK(fs.head<2>().norm() == Approx(std::abs(w) * shape.result().a).epsilon(1e-12));
        // Ends reproduced; consecutive points are one arc-length step apart (chord <= arc);
        // the polyline length converges to L.
        CHECK((shape.point_at(0.0) - start).norm() < 1e-9);
        CHECK((shape.point_at(L) - end).norm() < 1e-9);
        double polyline = 0.0;
        const int n = 2000;
        for (int i = 0; i < n; ++i) {
          const double step = (shape.point_at(L * (i + 1) / n) - shape.point_at(L * i / n)).norm();
          CHECK(step <= L / n * (1 + 1e-9));
          polyline += step;
        }
        CHECK(polyline == Approx(L).epsilon(1e-5));
        // Tension at the ends equals the end force magnitude.
        CHECK(shape.tension_at(0.0) == Approx(fs.norm()).epsilon(1e-10));
        CHECK(shape.tension_at(L) == Approx(fe.norm()).epsilon(1e-10));
        // The lowest point is no shallower than any sampled point (hanging) or is an end (buoyant).
        const V3 low = shape.lowest_point();
        for (int i = 0; i <= 50; ++i) CHECK(shape.point_at(L * i / 50).z() <= low.z() + 1e-9);
        if (w < 0) CHECK(((low - start).norm() < 1e-12 || (low - end).norm() < 1e-12));
      }
    }
  }
}

TEST_CASE("a buoyant line is the mirror image of a hanging one", "[catenary][shape]") {
  const V3 start(0, 0, 10.0), end(6.0, 0.0, 7.0);
  const auto hang = catenary_between(start, end, 12.0, 0.5);
  // Mirror the geometry about z = 10 and flip the weight.
  const V3 end_m(6.0, 0.0, 13.0);
  const auto buoy = catenary_between(start, end_m, 12.0, -0.5);
  REQUIRE(buoy.status() == CatenaryStatus::converged);
  for (double s : {0.0, 3.0, 6.5, 12.0}) {
    const V3 p = hang.point_at(s), q = buoy.point_at(s);
    CHECK(q.x() == Approx(p.x()).epsilon(1e-12));
    CHECK(q.z() - 10.0 == Approx(-(p.z() - 10.0)).epsilon(1e-12));
  }
  CHECK(buoy.force_on_start().z() == Approx(-hang.force_on_start().z()).epsilon(1e-12));
  CHECK(buoy.horizontal_tension() == Approx(hang.horizontal_tension()).epsilon(1e-12));
  // The buoyant vertex is the highest point of the arch.
  CHECK(buoy.vertex().z() < std::min(start.z(), end_m.z()));
  // ... at the height an independent solve gives: in the mirrored plane (D = 6, dz' = 3, L = 12)
  // the vertex lies a(cosh(c/a) − 1) beyond the start, i.e. that much above it for w < 0.
  long double a = 0, c = 0;
  independent_catenary(6, 3, 12, a, c);
  REQUIRE(c > 0);  // the vertex lies on the cable, between the ends
  REQUIRE(c < 6);
  const double top = double(10.0L - a * (std::cosh(c / a) - 1.0L));
  CHECK(buoy.vertex().z() == Approx(top).epsilon(1e-12));
  CHECK(buoy.vertex().x() == Approx(double(c)).epsilon(1e-12));
  // No point of the cable is above the top of the arch, and the cable reaches it.
  double highest = start.z();
  for (int i = 0; i <= 1200; ++i) {
    const double z = buoy.point_at(12.0 * i / 1200).z();
    CHECK(z >= top - 1e-12);
    highest = std::min(highest, z);
  }
  CHECK(highest == Approx(top).epsilon(1e-6));
}

TEST_CASE("iteration limit: end forces, H and tensions agree (last iterate)", "[catenary][shape]") {
  // A solve stopped by the iteration limit reports the shape of its last iterate; its horizontal
  // tension, end forces and tension_at must describe that same iterate (H = a·|w| everywhere).
  kelp::tether::CatenaryOptions<double> opt;
  opt.max_iterations = 1;
  opt.tolerance = 0.0;  // never satisfied unless the residual is exactly zero
  for (double w : {kW, -0.3}) {
    const double L = 20.0;
    const V3 start(1.0, 2.0, 0.0);
    const V3 end = start + 10.0 * V3(0.6, 0.8, 0.0) + V3(0, 0, -5.0);
    const auto shape = catenary_between(start, end, L, w, opt);
    REQUIRE(shape.status() == CatenaryStatus::max_iterations);
    const double a = shape.result().a;
    REQUIRE(std::isfinite(a));
    REQUIRE(a > 0);
    CHECK(shape.horizontal_tension() == Approx(std::abs(w) * a).epsilon(1e-15));
    const V3 fs = shape.force_on_start(), fe = shape.force_on_end();
    CHECK(fs.head<2>().norm() == Approx(shape.horizontal_tension()).epsilon(1e-12));
    CHECK((fs.head<2>() + fe.head<2>()).norm() < 1e-12);
    CHECK(shape.tension_at(0.0) == Approx(fs.norm()).epsilon(1e-12));
    CHECK(shape.tension_at(L) == Approx(fe.norm()).epsilon(1e-12));
    // The ends carry the weight of the iterate's arc length, L(1 + R2/L): within its residual.
    CHECK(std::abs(fs.z() + fe.z() - w * L) <= std::abs(w) * L * (shape.result().residual + 1e-14));
  }
}

TEST_CASE("taut, vertical and invalid 3-D lines", "[catenary][shape]") {
  const V3 start(0, 0, 0);
  // Taut: straight line, EA tension along the chord plus half the weight at each end.
  kelp::tether::CatenaryOptions<double> opt;
  opt.EA = 2e4;
  const V3 end(3, 0, 4);  // chord 5
  auto taut = catenary_between(start, end, 4.99, 0.2, opt);
  REQUIRE(taut.status() == CatenaryStatus::taut);
  CHECK((taut.point_at(4.99 / 2) - V3(1.5, 0, 2)).norm() < 1e-12);
  const double T = 2e4 * 0.01 / 4.99;
  CHECK((taut.force_on_start() - (T * V3(0.6, 0, 0.8) + V3(0, 0, 0.1 * 4.99))).norm() < 1e-9);
  CHECK(taut.force_on_start().z() + taut.force_on_end().z() == Approx(0.2 * 4.99));
  // Vertical hanging line: end 4 m below the start, L = 10 -> the slack 6 m hangs as a loop whose
  // bottom is (10 - (-4))/2 = 7 m below the start (z up), i.e. NED z = 7.
  const auto vert = catenary_between(start, V3(0, 0, 4), 10.0, 0.5);
  REQUIRE(vert.status() == CatenaryStatus::vertical);
  CHECK(vert.lowest_point().z() == Approx(7.0));
  CHECK(vert.point_at(7.0).z() == Approx(7.0));
  CHECK(vert.point_at(10.0).z() == Approx(4.0));
  CHECK(vert.force_on_start().z() == Approx(0.5 * 7.0));
  CHECK(vert.force_on_end().z() == Approx(0.5 * 3.0));
  CHECK(vert.horizontal_tension() == 0.0);
  // Invalid inputs never throw.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(catenary_between(start, V3(nan, 0, 0), 10.0, 0.5).status() ==
        CatenaryStatus::invalid_input);
  CHECK(catenary_between(start, end, -1.0, 0.5).status() == CatenaryStatus::invalid_input);
  CHECK(std::isnan(catenary_between(start, end, 10.0, nan).force_on_start().x()));
}

TEST_CASE("CatenaryShape works in float", "[catenary][shape]") {
  const kelp::Vector3<float> start(0, 0, 0), end(10, 0, -5);
  const auto s = catenary_between(start, end, 20.0f, float(kW));
  REQUIRE(s.status() == CatenaryStatus::converged);
  CHECK(s.horizontal_tension() == Approx(0.427536).epsilon(1e-5));
  CHECK(s.force_on_end().norm() == Approx(2.318855).epsilon(1e-5));
  CHECK((s.point_at(20.0f) - end).norm() < 1e-4f);
}

TEST_CASE("the 3-D helper does not allocate", "[catenary][shape]") {
  kelp::tether::CatenaryOptions<double> opt;
  opt.seabed_depth = 6.0;
  const V3 start(0, 0, 0), end(10, 0, 4);
  Eigen::internal::set_is_malloc_allowed(false);
  const auto free_line = catenary_between(start, end, 20.0, kW);
  const auto grounded = catenary_between(start, end, 20.0, kW, opt);
  const V3 f = free_line.force_on_end() + grounded.force_on_start() + grounded.point_at(7.0) +
               free_line.point_at(3.0) + free_line.lowest_point();
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(grounded.on_seabed());
  CHECK(std::isfinite(f.sum()));
}

// The probe: point_at(NaN) and tension_at(NaN) returned NaN on a valid shape, silently.
TEMPLATE_TEST_CASE("bad input: a NaN or infinite arc length is refused by the shape's queries",
                   "[catenary][shape][bad_input]", float, double) {
  using S = TestType;
  using V = kelp::Vector3<S>;
  const S nan = std::numeric_limits<S>::quiet_NaN(), inf = std::numeric_limits<S>::infinity();
  const V start(S(0), S(0), S(2)), far_end(S(8), S(6), S(7)), taut_end(S(30), S(0), S(2)),
      below(S(0), S(0), S(12));
  kelp::tether::CatenaryOptions<S> grounded_options;
  grounded_options.seabed_depth = 8.0;
  // One shape of each status: slack (converged), taut, vertical, grounded, invalid input.
  const kelp::tether::CatenaryShape<S> shapes[] = {
      catenary_between(start, far_end, S(20), S(kW)),
      catenary_between(start, taut_end, S(20), S(kW)), catenary_between(start, below, S(20), S(kW)),
      catenary_between(start, far_end, S(20), S(kW), grounded_options),
      catenary_between(start, V(nan, S(0), S(0)), S(20), S(kW))};
  REQUIRE(shapes[0].status() == CatenaryStatus::converged);
  REQUIRE(shapes[1].status() == CatenaryStatus::taut);
  REQUIRE(shapes[2].status() == CatenaryStatus::vertical);
  REQUIRE(shapes[3].on_seabed());
  REQUIRE(shapes[4].status() == CatenaryStatus::invalid_input);
  for (const auto& shape : shapes) {
    INFO("status " << kelp::tether::to_string(shape.status()));
    for (const S s : {nan, inf, -inf}) {
      REQUIRE_THROWS_AS(shape.point_at(s), kelp::invalid_argument);
      REQUIRE_THROWS_AS(shape.tension_at(s), kelp::invalid_argument);
      REQUIRE_THROWS_WITH(shape.tension_at(s), Catch::Contains("arc length"));
    }
    // A finite arc length: finite answers, or NaN only as the invalid shape's status value.
    const bool valid = shape.status() != CatenaryStatus::invalid_input;
    CHECK(kelp::all_finite(shape.point_at(S(10))) == valid);
    CHECK(std::isfinite(shape.tension_at(S(10))) == valid);
  }
}
