/// \file
/// \brief Refuses, at compile time, the floating-point flags under which kelp computes wrong
/// results. kelp is header-only, so its code is compiled with the user's flags.
///
/// - `-ffast-math` (also implied by `-Ofast`): its `-fassociative-math` lets the compiler fold
///   `(x + 1.5·2^52) − 1.5·2^52` to `x`, the rounding step of the vectorised sin/cos/exp
///   (kelp/core/fast_math.hpp), so the wave phases are no longer reduced (with GCC 12 -O2
///   -ffast-math the moderate sea's surface elevation at a point is the same at every time); and
///   its `-ffinite-math-only` removes the NaN and infinity checks kelp's bad-input contract rests
///   on.
/// - `-ffinite-math-only` alone: the checks again (`std::isfinite(x)` may compile to `true`).
/// - `-fassociative-math` alone (GCC defines `__ASSOCIATIVE_MATH__`): the rounding step again.
/// - MSVC `/fp:fast` (`_M_FP_FAST`): the same reassociation.
///
/// GCC and clang define `__FAST_MATH__` and `__FINITE_MATH_ONLY__` (GCC manual, "Common Predefined
/// Macros"). Included by kelp/core/error.hpp, so by every header that checks its input.
#pragma once

#if defined(__FAST_MATH__)
#error \
    "kelp does not support -ffast-math (or -Ofast, which implies it): it breaks kelp's wave, wind and current kernels (the rounding in kelp/core/fast_math.hpp is folded away) and its NaN checks. Compile the files that include kelp without -ffast-math (e.g. add -fno-fast-math after it)."
#elif defined(__FINITE_MATH_ONLY__) && __FINITE_MATH_ONLY__
#error \
    "kelp does not support -ffinite-math-only: kelp refuses NaN and infinite input with checks that this flag lets the compiler remove. Compile the files that include kelp without it (-fno-finite-math-only)."
#elif defined(__ASSOCIATIVE_MATH__)
#error \
    "kelp does not support -fassociative-math: it folds away the rounding in kelp/core/fast_math.hpp that the wave, wind and current kernels rely on. Compile the files that include kelp without it (-fno-associative-math)."
#elif defined(_M_FP_FAST)
#error \
    "kelp does not support /fp:fast: it reassociates the rounding in kelp/core/fast_math.hpp that the wave, wind and current kernels rely on. Use /fp:precise for the files that include kelp."
#endif
