// kelp/core/angles.hpp: the two angle wraps land in (−π, π], keep angles already there (the
// exact one bit for bit), agree with the copies they replaced bit for bit (the controllers'
// fmod wrap and the tether winding's remainder wrap), at ±π and around; heading_of is the yaw
// of the ZYX Euler angles.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/rotation.hpp"

namespace test_angles {

constexpr double pi = kelp::pi;

// The copies the helpers replaced, as they were (control/controllers.hpp, tether/winding.hpp).
double old_control_wrap(double a) {
  a = std::fmod(a + kelp::pi, 2.0 * kelp::pi);
  if (a <= 0.0) a += 2.0 * kelp::pi;
  return a - kelp::pi;
}
double old_winding_wrap(double a) {
  a = std::remainder(a, 2.0 * kelp::pi);
  return a <= -kelp::pi ? a + 2.0 * kelp::pi : a;
}

bool same_bits(double a, double b) {
  std::uint64_t x, y;
  std::memcpy(&x, &a, sizeof x);
  std::memcpy(&y, &b, sizeof y);
  return x == y;
}

// Edge cases and a spread of values: ±π and their neighbours, multiples of π, zeros, tiny and
// huge values.
std::vector<double> inputs() {
  std::vector<double> v = {0.0,    -0.0,    1e-300, -1e-300, 1e-20,  -1e-20,     0.1,
                           -0.1,   1.0,     -1.0,   3.0,     -3.0,   pi,         -pi,
                           2 * pi, -2 * pi, 3 * pi, -3 * pi, 4 * pi, -4 * pi,    100.0,
                           -100.0, 1e6,     -1e6,   1e15,    -1e15,  7 * pi / 2, -7 * pi / 2};
  for (double c : {pi, -pi, 2 * pi, -2 * pi, 3 * pi, -3 * pi}) {
    double up = c, down = c;
    for (int i = 0; i < 4; ++i) {
      up = std::nextafter(up, 1e300);
      down = std::nextafter(down, -1e300);
      v.push_back(up);
      v.push_back(down);
    }
  }
  std::uint64_t s = 0x9e3779b97f4a7c15ull;  // fixed LCG over [−50, 50]
  for (int i = 0; i < 2000; ++i) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    v.push_back(static_cast<double>(s >> 11) * 0x1.0p-53 * 100.0 - 50.0);
  }
  return v;
}

}  // namespace test_angles

TEST_CASE("wrap_angle and wrap_angle_exact: bit for bit the copies they replaced",
          "[core][angles]") {
  using namespace test_angles;
  for (double a : inputs()) {
    INFO("a = " << a);
    CHECK(same_bits(kelp::wrap_angle(a), old_control_wrap(a)));
    CHECK(same_bits(kelp::wrap_angle_exact(a), old_winding_wrap(a)));
  }
}

TEST_CASE("wrap_angle and wrap_angle_exact: range, known values, periodicity", "[core][angles]") {
  using namespace test_angles;
  for (double a : inputs()) {
    INFO("a = " << a);
    const double w = kelp::wrap_angle(a), x = kelp::wrap_angle_exact(a);
    CHECK(w > -pi);
    CHECK(w <= pi);
    CHECK(x > -pi);
    CHECK(x <= pi);
    // Both are a − 2πk for the same k, up to the rounding of a + π (the fmod one) or an input
    // that sits on ±π within rounding (then the two may pick opposite ends).
    const double d = std::abs(w - x);
    CHECK((d <= 4e-15 * std::max(1.0, std::abs(a)) || std::abs(d - 2 * pi) < 1e-9));
    // Idempotent on its own output, exactly for the exact wrap.
    CHECK(kelp::wrap_angle_exact(x) == x);
    CHECK(kelp::wrap_angle(w) == Approx(w).margin(1e-15));
  }
  // Known values: (−π, π] includes π, excludes −π.
  CHECK(kelp::wrap_angle(pi) == pi);
  CHECK(kelp::wrap_angle(-pi) == pi);
  CHECK(kelp::wrap_angle_exact(pi) == pi);
  CHECK(kelp::wrap_angle_exact(-pi) == pi);
  CHECK(kelp::wrap_angle_exact(3 * pi) == Approx(pi).margin(1e-14));
  CHECK(kelp::wrap_angle_exact(0.0) == 0.0);
  CHECK(kelp::wrap_angle_exact(0.5) == 0.5);
  CHECK(kelp::wrap_angle_exact(-0.5) == -0.5);
  CHECK(kelp::wrap_angle_exact(2 * pi + 0.5) == Approx(0.5).margin(1e-15));
  CHECK(kelp::wrap_angle_exact(-2 * pi - 0.5) == Approx(-0.5).margin(1e-15));
  CHECK(kelp::wrap_angle(2 * pi + 0.5) == Approx(0.5).margin(1e-15));
  CHECK(kelp::wrap_angle(1.5 * pi) == Approx(-0.5 * pi).margin(1e-15));
  CHECK(kelp::wrap_angle(-1.5 * pi) == Approx(0.5 * pi).margin(1e-15));
  CHECK(kelp::wrap_angle(0.0) == 0.0);
  // The documented difference: the fmod wrap rounds a + π, the exact one does not.
  CHECK(kelp::wrap_angle(1e-20) == 0.0);
  CHECK(kelp::wrap_angle_exact(1e-20) == 1e-20);
  // Non-finite input gives NaN.
  CHECK(std::isnan(kelp::wrap_angle(std::numeric_limits<double>::infinity())));
  CHECK(std::isnan(kelp::wrap_angle_exact(std::numeric_limits<double>::quiet_NaN())));
}

TEST_CASE("wrap_angle and wrap_angle_exact in float", "[core][angles]") {
  const float pf = static_cast<float>(kelp::pi);  // rounds up: slightly above π
  for (float a : {0.0f, 0.5f, -0.5f, 3.0f, -3.0f, 7.0f, -7.0f, 100.0f, -100.0f, pf, -pf}) {
    INFO("a = " << a);
    const float w = kelp::wrap_angle(a), x = kelp::wrap_angle_exact(a);
    CHECK(w > -pf);
    CHECK(w <= pf);
    CHECK(x > -pf);
    CHECK(x <= pf);
    // The same angle as the double wrap (modulo 2π: float π is above π, so it wraps to −π).
    CHECK(std::abs(std::remainder(double(w) - kelp::wrap_angle_exact(double(a)), 2 * kelp::pi)) <
          1e-5);
  }
  CHECK(kelp::wrap_angle(7.0f) == Approx(7.0 - 2 * kelp::pi).margin(1e-5));
  CHECK(kelp::wrap_angle_exact(-7.0f) == Approx(-7.0 + 2 * kelp::pi).margin(1e-5));
}

TEST_CASE("heading_of is the yaw of the ZYX Euler angles", "[core][angles]") {
  using test_angles::pi;
  for (double psi : {0.0, 0.3, -0.3, 1.5, -1.5, 3.0, -3.0}) {
    for (double roll : {0.0, 0.2, -0.4}) {
      for (double pitch : {0.0, 0.3, -0.2}) {
        const auto q = kelp::quaternion_from_euler(roll, pitch, psi);
        INFO("roll " << roll << " pitch " << pitch << " psi " << psi);
        CHECK(kelp::heading_of(q) == Approx(psi).margin(1e-12));
        CHECK(kelp::heading_of(q) == kelp::euler_from_quaternion(q).z());  // the same bits
        const auto qf = q.cast<float>();
        CHECK(kelp::heading_of(qf) == Approx(psi).margin(1e-5));
      }
    }
  }
  // Heading of a quarter turn to the east, and of facing south (±π: atan2 gives +π).
  CHECK(kelp::heading_of(kelp::quaternion_from_euler(0.0, 0.0, 0.5 * pi)) ==
        Approx(0.5 * pi).margin(1e-15));
  CHECK(std::abs(kelp::heading_of(kelp::quaternion_from_euler(0.0, 0.0, pi))) ==
        Approx(pi).margin(1e-15));
}
