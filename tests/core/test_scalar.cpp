#include <catch2/catch.hpp>

#include <type_traits>

#include "kelp/core/scalar.hpp"

namespace {

// A step-like function: Scalar is deduced from the state only, dt converts.
template <typename Scalar>
Scalar advance(const Scalar& x, kelp::identity_t<Scalar> dt) {
  return x + dt;
}

}  // namespace

TEST_CASE("identity_t is the wrapped type and blocks deduction", "[core][scalar]") {
  STATIC_REQUIRE(std::is_same_v<kelp::identity_t<float>, float>);
  STATIC_REQUIRE(std::is_same_v<kelp::identity_t<double>, double>);
  // A float state with a double literal compiles and stays float.
  const float xf = 1.0F;
  const auto yf = advance(xf, 0.01);
  STATIC_REQUIRE(std::is_same_v<std::remove_const_t<decltype(yf)>, float>);
  CHECK(yf == 1.0F + 0.01F);
  const auto yd = advance(1.0, 0.01F);
  STATIC_REQUIRE(std::is_same_v<std::remove_const_t<decltype(yd)>, double>);
  CHECK(yd == 1.0 + static_cast<double>(0.01F));
}
