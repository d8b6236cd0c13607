/// \file
/// \brief Branch-free double-precision sin/cos and exp written so that loops over them
/// auto-vectorise (plain SSE2 is enough); used by the wave kinematics kernel.
///
/// Accuracy: |error| ≲ 1e-14 relative for exp on [−700, 0] and ≲ 1e-15 absolute for sin/cos
/// with |x| ≤ 10 rad, ≲ 1e-11 with |x| ≤ 1e5 rad (Cody–Waite reduction with a two-part π/2 split
/// and fdlibm's minimax kernels on [−π/4, π/4]; a Taylor polynomial on [−ln2/2, ln2/2] for exp).
/// The tests compare them against std::sin/std::cos/std::exp.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__GNUC__) || defined(__clang__)
/// Forces inlining, so that the math inlines into kernels compiled for a wider instruction set.
#define KELP_ENV_ALWAYS_INLINE __attribute__((always_inline))
#else
#define KELP_ENV_ALWAYS_INLINE
#endif

namespace kelp {
namespace environment {
namespace detail {

/// Round to nearest (ties to even) for |x| < 2^51 without a branch or an intrinsic: adding and
/// subtracting 1.5·2^52 pushes the fraction out of the mantissa. A translation unit compiled with
/// -ffast-math (-fassociative-math) may fold this away; kelp's kernels must not be built so.
KELP_ENV_ALWAYS_INLINE inline double round_nearest(double x) {
  constexpr double magic = 6755399441055744.0;  // 1.5 * 2^52
  return (x + magic) - magic;
}

/// sin and cos of x (|x| ≤ 1e5 for full accuracy).
KELP_ENV_ALWAYS_INLINE inline void fast_sincos(double x, double& s, double& c) {
  constexpr double two_over_pi = 0.636619772367581343076;
  // π/2 ≈ p1 + p2 (fdlibm's pio2_1, pio2_2; the remainder pio2_2t is 2.0e-21): p1 has 33
  // significant bits, so n·p1 is exact for |n| < 2^20.
  constexpr double p1 = 1.57079632673412561417e+00;
  constexpr double p2 = 6.07710050630396597660e-11;
  // n = round(x·2/π) by the 1.5·2^52 trick; the low mantissa bits of `biased` then hold n in
  // two's complement, so n mod 4 (the quadrant) is read from them directly.
  constexpr double magic = 6755399441055744.0;
  const double biased = x * two_over_pi + magic;
  const double n = biased - magic;
  // The third term n·p3 (≤ 2e-16 for |n| ≤ 1e5) is below the kernels' error: left out.
  const double r = (x - n * p1) - n * p2;
  const double r2 = r * r;
  // Minimax polynomials of fdlibm's __kernel_sin / __kernel_cos (Sun Microsystems, 1993) on
  // |r| ≤ π/4, error below 2^-58.
  constexpr double s1 = -1.66666666666666324348e-01, s2 = 8.33333333332248946124e-03,
                   s3 = -1.98412698298579493134e-04, s4 = 2.75573137070700676789e-06,
                   s5 = -2.50507602534068634195e-08, s6 = 1.58969099521155010221e-10;
  constexpr double c1 = 4.16666666666666019037e-02, c2 = -1.38888888888741095749e-03,
                   c3 = 2.48015872894767294178e-05, c4 = -2.75573143513906633035e-07,
                   c5 = 2.08757232129817482790e-09, c6 = -1.13596475577881948265e-11;
  const double r4 = r2 * r2;
  // Estrin-style split of the Horner chains for more instruction-level parallelism.
  const double ps = (s1 + r2 * s2) + r4 * ((s3 + r2 * s4) + r4 * (s5 + r2 * s6));
  const double pc = (c1 + r2 * c2) + r4 * ((c3 + r2 * c4) + r4 * (c5 + r2 * c6));
  const double sp = r + r * r2 * ps;
  const double cp = (1.0 - 0.5 * r2) + r4 * pc;
  // Quadrant q = n mod 4: x = r + qπ/2, so (sin x, cos x) = (sp, cp), (cp, −sp), (−sp, −cp),
  // (−cp, sp) for q = 0..3. Select and flip signs with bit masks (vectorises as integer SIMD).
  std::uint64_t q, sb, cb;
  std::memcpy(&q, &biased, sizeof q);
  std::memcpy(&sb, &sp, sizeof sb);
  std::memcpy(&cb, &cp, sizeof cb);
  const std::uint64_t swap = std::uint64_t(0) - (q & 1u);  // all ones when q is odd
  std::uint64_t so = (cb & swap) | (sb & ~swap);
  std::uint64_t co = (sb & swap) | (cb & ~swap);
  so ^= (q & 2u) << 62;         // sin < 0 in quadrants 2, 3
  co ^= ((q + 1u) & 2u) << 62;  // cos < 0 in quadrants 1, 2
  std::memcpy(&s, &so, sizeof s);
  std::memcpy(&c, &co, sizeof c);
}

/// e^x for −708 ≤ x ≤ 0 (no range check: the caller guarantees the range).
KELP_ENV_ALWAYS_INLINE inline double fast_exp_nonpositive_unchecked(double x) {
  constexpr double log2e = 1.44269504088896340736;
  constexpr double ln2_hi = 6.93147180369123816490e-01;  // fdlibm's ln2_hi / ln2_lo split
  constexpr double ln2_lo = 1.90821492927058770002e-10;
  constexpr double magic = 6755399441055744.0;
  const double n = (x * log2e + magic) - magic;
  const double r = (x - n * ln2_hi) - n * ln2_lo;
  // Taylor series of e^r on |r| ≤ ln2/2 to r^11 (remainder < 7e-15 relative), split for
  // instruction-level parallelism.
  const double r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
  const double p01 = 1.0 + r, p23 = 1.0 / 2 + r * (1.0 / 6), p45 = 1.0 / 24 + r * (1.0 / 120),
               p67 = 1.0 / 720 + r * (1.0 / 5040), p89 = 1.0 / 40320 + r * (1.0 / 362880),
               pab = 1.0 / 3628800 + r * (1.0 / 39916800);
  const double pr = (p01 + r2 * p23) + r4 * (p45 + r2 * p67) + r8 * (p89 + r2 * pab);
  // 2^n: put n + 1023 into the low mantissa bits of a double (adding 2^52), then shift them
  // into the exponent field.
  const double biased = n + (1023.0 + 4503599627370496.0);
  std::uint64_t bits;
  std::memcpy(&bits, &biased, sizeof bits);
  bits <<= 52;
  double two_n;
  std::memcpy(&two_n, &bits, sizeof two_n);
  return pr * two_n;
}

/// e^x for x ≤ 0 (x below −700 is treated as −700, giving ≈ 1e-304 instead of a subnormal).
KELP_ENV_ALWAYS_INLINE inline double fast_exp_nonpositive(double x) {
  // max(x, −700) written with fabs: GCC (without -ffast-math) does not if-convert a compare here,
  // and a branch would stop the loop around this function from vectorising. For x ≥ −700 the
  // correction is exactly zero, so x passes unchanged.
  x += 0.5 * (std::fabs(x + 700.0) - (x + 700.0));
  return fast_exp_nonpositive_unchecked(x);
}

}  // namespace detail
}  // namespace environment
}  // namespace kelp
