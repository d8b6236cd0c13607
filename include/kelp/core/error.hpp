/// \file
/// \brief kelp's exceptions and its two checking macros.
///
/// The split follows manif's `MANIF_CHECK` / `MANIF_ASSERT`: `KELP_CHECK` guards user input (sizes,
/// finiteness, positivity) and is always on; `KELP_ASSERT` guards internal invariants and compiles
/// away under `NDEBUG`. Geometry that is physically possible is reported by status values, not
/// exceptions (see `tether/catenary.hpp`).
#pragma once

#include <cassert>
#include <stdexcept>
#include <string>

#include "kelp/core/compiler_checks.hpp"

#if defined(__GNUC__) || defined(__clang__)
#define KELP_COLD __attribute__((cold, noinline))
#else
#define KELP_COLD
#endif

namespace kelp {

/// \brief Base of every exception kelp throws.
class error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief A caller passed a value kelp cannot use (NaN, a negative mass, an empty tether...).
/// The message names the offending field.
class invalid_argument : public error {
 public:
  using error::error;
};

/// \brief A computation could not proceed from a valid input (e.g. a simulation step produced a
/// non-finite state). The state it was given is left unchanged.
class numerical_error : public error {
 public:
  using error::error;
};

namespace detail {
/// Kept out of line and cold so that the check itself stays a single well-predicted branch.
[[noreturn]] inline KELP_COLD void throw_invalid_argument(const char* what) {
  throw ::kelp::invalid_argument(what);
}
[[noreturn]] inline KELP_COLD void throw_invalid_argument(const std::string& what) {
  throw ::kelp::invalid_argument(what);
}
[[noreturn]] inline KELP_COLD void throw_numerical_error(const std::string& what) {
  throw ::kelp::numerical_error(what);
}
}  // namespace detail

}  // namespace kelp

/// \brief Always-on check of user input: throws `kelp::invalid_argument(message)` when `cond` is
/// false. `message` may be a `const char*` or a `std::string` expression; it is built only on
/// failure.
#define KELP_CHECK(cond, message)                                 \
  do {                                                            \
    if (!(cond)) ::kelp::detail::throw_invalid_argument(message); \
  } while (false)

/// \brief Debug-only check of an internal invariant (compiled out with `NDEBUG`).
#define KELP_ASSERT(cond) assert(cond)
