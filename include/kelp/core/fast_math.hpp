/// \file
/// \brief Branch-free double-precision sin/cos and exp written so that loops over them
/// auto-vectorise (plain SSE2 is enough): with kelp/core/simd.hpp, kelp's one SIMD layer. Used by
/// the wave kinematics kernel and the wind and current variations.
///
/// Accuracy: |error| ≲ 1e-15 relative for exp on [−700, 0] and ≲ 1e-15 absolute for sin/cos
/// with |x| ≤ 10 rad, ≲ 1e-11 with |x| ≤ 1e5 rad (Cody–Waite reduction by multiples of π with a
/// two-part split and near-minimax polynomials on [−π/2, π/2]; Cody–Waite reduction by ln 2 and
/// a near-minimax polynomial on [−ln2/2, ln2/2] for exp).
/// The tests compare them against `std::sin`, `std::cos` and `std::exp`.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "kelp/core/compiler_checks.hpp"
#include "kelp/core/error.hpp"

#if defined(__GNUC__) || defined(__clang__)
/// Forces inlining, so that the math inlines into kernels compiled for a wider instruction set.
#define KELP_ALWAYS_INLINE __attribute__((always_inline))
#else
#define KELP_ALWAYS_INLINE
#endif

namespace kelp::simd {

/// Round to nearest (ties to even) for |x| < 2^51 without a branch or an intrinsic: adding and
/// subtracting 1.5·2^52 pushes the fraction out of the mantissa. A translation unit compiled with
/// -ffast-math (-fassociative-math) may fold this away; kelp's kernels must not be built so.
/// \param x the value, |x| < 2^51 (larger values come back wrong, not rounded).
/// \return the integer nearest to x, as a double.
KELP_ALWAYS_INLINE inline double round_nearest(double x) {
  constexpr double magic = 6755399441055744.0;  // 1.5 * 2^52
  return (x + magic) - magic;
}

/// sin and cos of x (|x| ≤ 1e5 for full accuracy) up to a common sign: sin x = ±s, cos x = ±c,
/// with the sign bit of ± in `sign` (0 or 2^63, to be applied by XOR, see `flip_sign`). A
/// caller that multiplies both by one factor applies the sign once, to that factor.
/// \param x the angle [rad]; accurate for |x| ≤ 1e5, see kFastSinCosLimit.
/// \param[out] s ±sin x.
/// \param[out] c ±cos x (the same sign as `s`).
/// \param[out] sign 0 when s and c are sin x and cos x, 2^63 (the sign bit) when they are
/// −sin x and −cos x.
KELP_ALWAYS_INLINE inline void fast_sincos_unsigned(double x, double& s, double& c,
                                                    std::uint64_t& sign) {
  constexpr double inv_pi = 0.318309886183790671538;
  // π ≈ p1 + p2 (twice fdlibm's pio2_1, pio2_2; the remainder is 4.1e-21): p1 has 33
  // significant bits, so n·p1 is exact for |n| < 2^20.
  constexpr double p1 = 3.14159265346825122833e+00;
  constexpr double p2 = 1.21542010126079319532e-10;
  // n = round(x/π) by the 1.5·2^52 trick; the lowest mantissa bit of `biased` is then the
  // parity of n. x = r + nπ with |r| ≤ π/2, and (sin x, cos x) = (−1)^n (sin r, cos r): one sign
  // flip instead of fdlibm's quadrant swap (fewer operations in a vector loop).
  constexpr double magic = 6755399441055744.0;
  const double biased = x * inv_pi + magic;
  const double n = biased - magic;
  // The third term n·p3 (≤ 2e-16 for |n| ≤ 3e4) is below the kernels' error: left out.
  const double r = (x - n * p1) - n * p2;
  const double r2 = r * r;
  // Polynomials in r² on |r| ≤ π/2: Chebyshev interpolants (near-minimax) of
  // (sin r / r − 1)/r² (degree 7 in r², error 3e-19) and (cos r − 1 + r²/2)/r⁴ (degree 6,
  // error 1e-17), computed in 50-digit arithmetic (mpmath.chebyfit) and rounded to double.
  constexpr double s1 = -0.16666666666666666, s2 = 0.008333333333333316,
                   s3 = -0.00019841269841254974, s4 = 2.7557319219163234e-06,
                   s5 = -2.5052107616996182e-08, s6 = 1.6058977312464087e-10,
                   s7 = -7.643970296798572e-13, s8 = 2.7314447669863995e-15;
  constexpr double c2 = 0.04166666666666666, c3 = -0.0013888888888884767,
                   c4 = 2.480158729891355e-05, c5 = -2.7557318573366175e-07,
                   c6 = 2.0876681558867395e-09, c7 = -1.1466252259718479e-11,
                   c8 = 4.6464359591124806e-14;
  // Horner form (the fewest operations; the loops around this function supply the
  // parallelism).
  const double ps =
      s1 + r2 * (s2 + r2 * (s3 + r2 * (s4 + r2 * (s5 + r2 * (s6 + r2 * (s7 + r2 * s8))))));
  const double pc = c2 + r2 * (c3 + r2 * (c4 + r2 * (c5 + r2 * (c6 + r2 * (c7 + r2 * c8)))));
  s = r + (r * r2) * ps;
  c = 1.0 + r2 * (-0.5 + r2 * pc);
  std::uint64_t q;
  std::memcpy(&q, &biased, sizeof q);
  sign = q << 63;  // the parity of n in the sign bit
}

/// x with its sign bit XORed with `sign` (0 or 2^63): x or −x without a branch.
/// \param x the value.
/// \param sign 0 (keep) or 2^63 (negate), as given by fast_sincos_unsigned().
/// \return x or −x (NaN and zeros included: only the sign bit changes).
KELP_ALWAYS_INLINE inline double flip_sign(double x, std::uint64_t sign) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  b ^= sign;
  std::memcpy(&x, &b, sizeof x);
  return x;
}

/// sin and cos of x (|x| ≤ 1e5 for full accuracy).
/// \param x the angle [rad]; see kFastSinCosLimit for the range.
/// \param[out] s sin x.
/// \param[out] c cos x.
KELP_ALWAYS_INLINE inline void fast_sincos(double x, double& s, double& c) {
  std::uint64_t sign;
  fast_sincos_unsigned(x, s, c, sign);
  s = flip_sign(s, sign);
  c = flip_sign(c, sign);
}

/// x reduced to [−π, π] by subtracting the nearest multiple of 2π: x − 2πn, n = round(x/2π)
/// (|x| ≤ kWrapTwoPiLimit for an exact result; garbage beyond 2^51 rad, see `reduce_phase`).
/// Cody–Waite reduction with 2π split in three parts (26 + 26 + 53 bits): n·h1 and
/// n·h2 are exact for |n| < 2^27 (|x| < 8e8 rad), so the reduced phase carries only the rounding
/// of x itself and ≲ 1e-16 rad of its own. Used to bring a wave phase φ − ω t (formed in double)
/// into the range where `fast_sincos` and a single-precision cast are accurate, however large t.
/// \param x the angle [rad], |x| ≤ kWrapTwoPiLimit.
/// \return the equivalent angle in [−π, π] [rad].
KELP_ALWAYS_INLINE inline double wrap_two_pi(double x) {
  constexpr double inv_two_pi = 0.15915494309189535;
  constexpr double h1 = 6.283185243606567;       // 26 significant bits
  constexpr double h2 = 6.357301884918343e-08;   // next 26 bits
  constexpr double h3 = 2.4492935982947064e-16;  // the rest, rounded
  const double n = round_nearest(x * inv_two_pi);
  return ((x - n * h1) - n * h2) - n * h3;
}

/// Largest |x| [rad] for which `wrap_two_pi` is exact to the rounding of x: n = round(x/2π)
/// stays below 2^27 (so n·h1 and n·h2 are exact) with a margin, about 2.5 years of a 10 rad/s
/// component. Callers check |φ| + ω_max |t| against it ONCE per query and take
/// `reduce_phase_exact` beyond it.
inline constexpr double kWrapTwoPiLimit = 8.0e8;

/// Largest |x| [rad] for which `fast_sincos` is accurate (≲ 1e-10 absolute, most of it the
/// rounding of x itself): n = round(x/π) stays below 2^20, where n·p1 is exact. Beyond it the
/// reduction loses accuracy, and past 2^51 rad the result is garbage (not even in [−1, 1]).
inline constexpr double kFastSinCosLimit = 1.0e6;

/// x reduced to [−π, π] for any finite x, as accurately as the C library's own sin and cos
/// (which reduce by a many-digit 2π, Payne–Hanek): atan2(sin x, cos x). Slow (three library
/// calls): the fallback of `wrap_two_pi` beyond `kWrapTwoPiLimit`, e.g. t = 1e17 s. NaN or ±Inf
/// give NaN (callers reject non-finite times before).
/// \param x the angle [rad], any finite value.
/// \return the equivalent angle in [−π, π] [rad].
inline KELP_COLD double reduce_phase_exact(double x) {
  return std::atan2(std::sin(x), std::cos(x));
}

/// x reduced to [−π, π] for any finite x: `wrap_two_pi` within its exact range (one compare,
/// well predicted), `reduce_phase_exact` beyond it. For one-off reductions; loops hoist the
/// range check out instead.
/// \param x the angle [rad], any finite value.
/// \return the equivalent angle in [−π, π] [rad].
inline double reduce_phase(double x) {
  return std::fabs(x) <= kWrapTwoPiLimit ? wrap_two_pi(x) : reduce_phase_exact(x);
}

/// e^x for −708 ≤ x ≤ 0 (no range check: the caller guarantees the range).
///
/// With kSplitLn2 = false the reduction r = x − n ln2 uses ln 2 rounded to double (one fused
/// multiply-add instead of two): the relative error then grows by |n|·2.3e-17 (≤ 2.3e-14 at
/// x = −700), so the absolute error |x|·1.44·2.3e-17·e^x stays below 1.3e-17 for every x ≤ 0.
/// The wave kernel sums terms a e^{−kz}, for which that absolute bound is what counts.
/// \tparam kSplitLn2 true: ln 2 in two parts (full relative accuracy); false: one part (see
/// above).
/// \param x the exponent, −708 ≤ x ≤ 0; outside it the result is wrong (no check).
/// \return e^x.
template <bool kSplitLn2 = true>
KELP_ALWAYS_INLINE inline double fast_exp_nonpositive_unchecked(double x) {
  constexpr double log2e = 1.44269504088896340736;
  constexpr double ln2_hi = 6.93147180369123816490e-01;  // fdlibm's ln2_hi / ln2_lo split
  constexpr double ln2_lo = 1.90821492927058770002e-10;
  // n = round(x·log2 e) by the 1.5·2^52 trick, with 1023 added to the constant: the low
  // mantissa bits of `biased` then hold n + 1023, the biased exponent of 2^n (used below).
  constexpr double magic = 6755399441055744.0 + 1023.0;
  const double biased = x * log2e + magic;
  const double n = biased - magic;
  double r;
  if constexpr (kSplitLn2) {
    r = (x - n * ln2_hi) - n * ln2_lo;
  } else {
    r = x - n * 0.693147180559945309417;
  }
  // Degree-10 Chebyshev interpolant (near-minimax) of e^r on |r| ≤ ln2/2, error 2.2e-16,
  // computed in 50-digit arithmetic (mpmath.chebyfit) and rounded to double; Horner form (the
  // fewest operations; the loops around this function supply the parallelism).
  constexpr double e0 = 1.0, e1 = 1.0000000000000067, e2 = 0.5000000000000006,
                   e3 = 0.16666666666554406, e4 = 0.04166666666657314, e5 = 0.008333333385667782,
                   e6 = 0.0013888888932488599, e7 = 0.00019841170270440067,
                   e8 = 2.4801504346997686e-05, e9 = 2.764018079620985e-06,
                   e10 = 2.7626357241447223e-07;
  const double pr =
      e0 +
      r * (e1 +
           r * (e2 +
                r * (e3 +
                     r * (e4 + r * (e5 + r * (e6 + r * (e7 + r * (e8 + r * (e9 + r * e10)))))))));
  // 2^n: shift n + 1023 (0 < n + 1023 < 2^11) from the low mantissa bits of `biased` into the
  // exponent field; the higher bits of `biased` fall off the top.
  std::uint64_t bits;
  std::memcpy(&bits, &biased, sizeof bits);
  bits <<= 52;
  double two_n;
  std::memcpy(&two_n, &bits, sizeof two_n);
  return pr * two_n;
}

/// e^x for x ≤ 0 (x below −700 is treated as −700, giving ≈ 1e-304 instead of a subnormal).
/// \param x the exponent, x ≤ 0 (the contract: a positive x is not checked, and passes
/// unchanged to fast_exp_nonpositive_unchecked).
/// \return e^x, at least ≈ 1e-304.
KELP_ALWAYS_INLINE inline double fast_exp_nonpositive(double x) {
  // max(x, −700) written with fabs: GCC (without -ffast-math) does not if-convert a compare here,
  // and a branch would stop the loop around this function from vectorising. For x ≥ −700 the
  // correction is exactly zero, so x passes unchanged.
  x += 0.5 * (std::fabs(x + 700.0) - (x + 700.0));
  return fast_exp_nonpositive_unchecked(x);
}

}  // namespace kelp::simd
