// kelp's error policy: checks throw kelp::invalid_argument naming the field; both derive from
// kelp::error.
#include <catch2/catch.hpp>
#include <limits>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

TEST_CASE("checks name the field and throw kelp::invalid_argument", "[core][errors]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(kelp::check_positive(-1.0, "mass"), Catch::Contains("mass"));
  CHECK_THROWS_AS(kelp::check_positive(0.0, "mass"), kelp::invalid_argument);
  CHECK_THROWS_AS(kelp::check_positive(nan, "mass"), kelp::error);
  CHECK_THROWS_AS(kelp::check_finite(inf, "length"), kelp::invalid_argument);
  CHECK_NOTHROW(kelp::check_non_negative(0.0, "damping"));
  CHECK_THROWS_WITH(kelp::check_non_negative(-1e-9, "damping"), Catch::Contains("damping"));
  kelp::Vector3<double> v(1, 2, nan);
  CHECK_THROWS_WITH(kelp::check_all_finite(v, "r_g"), Catch::Contains("r_g"));
  CHECK_FALSE(kelp::all_finite(v));
  const auto check = [](int n) { KELP_CHECK(n > 1, "n must exceed 1"); };
  CHECK_THROWS_WITH(check(1), "n must exceed 1");
  CHECK_NOTHROW(check(2));
  // kelp::error is a std::runtime_error, so generic handlers catch it.
  CHECK_THROWS_AS(kelp::check_positive(-1.0f, "x"), std::runtime_error);
}

TEST_CASE("value_of reads arithmetic scalars", "[core]") {
  CHECK(kelp::value_of(2.5f) == 2.5);
  CHECK(kelp::value_of(3) == 3.0);
}
