/// \file
/// \brief Scalar policy: how kelp reads the value of a `double`, a `float` or a `ceres::Jet`, and
/// the finiteness / positivity checks used on user input.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>

#include <Eigen/Core>

#include "kelp/core/error.hpp"

namespace kelp {

/// \brief Wraps a type so that a function parameter of type `identity_t<T>` is not used for
/// template argument deduction (a non-deduced context).
///
/// Step functions take `dt` as `identity_t<Scalar>`: `Scalar` is deduced from the model alone, and
/// a literal such as `0.01` (a `double`) converts to `float` for a float model instead of making
/// the deduction conflict.
/// \tparam T any type.
template <class T>
struct identity {
  using type = T;  ///< The wrapped type, unchanged.
};

/// \brief `T` in a non-deduced context; see `kelp::identity`.
/// \tparam T any type.
template <class T>
using identity_t = typename identity<T>::type;

/// \brief The value part of a scalar as a double: the number itself for arithmetic types, the
/// real part `x.a` (recursively) for automatic-differentiation types such as `ceres::Jet`.
/// \tparam Scalar an arithmetic type or a type with a value member `a`.
/// \param x the scalar. \return its value part.
template <typename Scalar>
constexpr double value_of(const Scalar& x) {
  if constexpr (std::is_arithmetic_v<Scalar>) {
    return static_cast<double>(x);
  } else {
    return value_of(x.a);
  }
}

/// \brief True when the value part of `x` is finite (neither NaN nor ±Inf).
/// \tparam Scalar as value_of. \param x the scalar. \return whether value_of(x) is finite.
template <typename Scalar>
bool is_finite(const Scalar& x) {
  return std::isfinite(value_of(x));
}

/// \brief True when every coefficient of an Eigen expression has a finite value part.
/// \tparam Derived an Eigen expression type (any shape; empty gives true).
/// \param m the matrix or vector.
/// \return whether no coefficient is NaN or ±Inf.
template <typename Derived>
bool all_finite(const Derived& m) {
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      if (!is_finite(m(i, j))) return false;
  return true;
}

/// \brief Throws `kelp::invalid_argument` naming `field` unless `x` is finite.
/// \tparam Scalar as value_of.
/// \param x the value checked.
/// \param field the name the message gives (e.g. "TetherParameters::length").
/// \throws kelp::invalid_argument "<field> must be finite".
template <typename Scalar>
void check_finite(const Scalar& x, const char* field) {
  if (!is_finite(x)) detail::throw_invalid_argument(std::string(field) + " must be finite");
}

/// \brief Throws `kelp::invalid_argument` naming `field` unless every coefficient is finite.
/// \tparam Derived an Eigen expression type.
/// \param m the matrix or vector checked.
/// \param field the name the message gives (e.g. "TetherParameters::length").
/// \throws kelp::invalid_argument "<field> must be finite".
template <typename Derived>
void check_all_finite(const Derived& m, const char* field) {
  if (!all_finite(m)) detail::throw_invalid_argument(std::string(field) + " must be finite");
}

/// \brief Throws `kelp::invalid_argument` naming `field` unless `x` is finite and > 0.
/// \tparam Scalar as value_of.
/// \param x the value checked.
/// \param field the name the message gives (e.g. "TetherParameters::length").
/// \throws kelp::invalid_argument "<field> must be finite and > 0".
template <typename Scalar>
void check_positive(const Scalar& x, const char* field) {
  if (!(is_finite(x) && value_of(x) > 0.0))
    detail::throw_invalid_argument(std::string(field) + " must be finite and > 0");
}

/// \brief Throws `kelp::invalid_argument` naming `field` unless `x` is finite and >= 0.
/// \tparam Scalar as value_of.
/// \param x the value checked.
/// \param field the name the message gives (e.g. "TetherParameters::length").
/// \throws kelp::invalid_argument "<field> must be finite and >= 0".
template <typename Scalar>
void check_non_negative(const Scalar& x, const char* field) {
  if (!(is_finite(x) && value_of(x) >= 0.0))
    detail::throw_invalid_argument(std::string(field) + " must be finite and >= 0");
}

/// \brief Throws `kelp::invalid_argument` naming `field` and the bound unless `x` ≤ `bound`
/// (NaN fails). For parameters whose finite but absurd values would overflow what is computed
/// from them; the bound is part of the documented contract of the parameter.
/// \tparam Scalar as value_of.
/// \param x the value checked.
/// \param bound the largest value allowed (in the unit of `x`).
/// \param field the name the message gives (e.g. "TetherParameters::length").
/// \throws kelp::invalid_argument "<field> must be <= <bound> (got <x>)".
template <typename Scalar>
void check_at_most(const Scalar& x, double bound, const char* field) {
  if (!(value_of(x) <= bound)) {
    char text[96];
    std::snprintf(text, sizeof text, " must be <= %g (got %g)", bound, value_of(x));
    detail::throw_invalid_argument(std::string(field) + text);
  }
}

/// \brief Throws `kelp::invalid_argument` naming `field` and the bound unless `x` ≥ `bound`
/// (NaN fails).
/// \tparam Scalar as value_of.
/// \param x the value checked.
/// \param bound the smallest value allowed (in the unit of `x`).
/// \param field the name the message gives (e.g. "TetherParameters::length").
/// \throws kelp::invalid_argument "<field> must be >= <bound> (got <x>)".
template <typename Scalar>
void check_at_least(const Scalar& x, double bound, const char* field) {
  if (!(value_of(x) >= bound)) {
    char text[96];
    std::snprintf(text, sizeof text, " must be >= %g (got %g)", bound, value_of(x));
    detail::throw_invalid_argument(std::string(field) + text);
  }
}

}  // namespace kelp
