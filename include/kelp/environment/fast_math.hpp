/// \file
/// \brief Branch-free double-precision sin/cos and exp written so that loops over them
/// auto-vectorise (plain SSE2 is enough); used by the wave kinematics kernel.
///
/// Accuracy: |error| ≲ 1e-15 relative for exp on [−700, 0] and ≲ 1e-15 absolute for sin/cos
/// with |x| ≤ 1e5 rad (Cody–Waite reduction with a three-part π/2 split, as in fdlibm; Taylor
/// polynomials on [−π/4, π/4] and [−ln2/2, ln2/2] truncated where the remainder is below 1e-16).
/// The tests compare them against std::sin/std::cos/std::exp.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace kelp {
namespace environment {
namespace detail {

/// Round to nearest (ties to even) for |x| < 2^51 without a branch or an intrinsic: adding and
/// subtracting 1.5·2^52 pushes the fraction out of the mantissa. A translation unit compiled with
/// -ffast-math (-fassociative-math) may fold this away; kelp's kernels must not be built so.
inline double round_nearest(double x) {
  constexpr double magic = 6755399441055744.0;  // 1.5 * 2^52
  return (x + magic) - magic;
}

/// sin and cos of x (|x| ≤ 1e5 for full accuracy).
inline void fast_sincos(double x, double& s, double& c) {
  constexpr double two_over_pi = 0.636619772367581343076;
  // π/2 = p1 + p2 + p3 (fdlibm's pio2_1, pio2_2, pio2_2t): p1 has 33 significant bits, so n·p1 is
  // exact for |n| < 2^20.
  constexpr double p1 = 1.57079632673412561417e+00;
  constexpr double p2 = 6.07710050630396597660e-11;
  constexpr double p3 = 2.02226624879595063154e-21;
  const double n = round_nearest(x * two_over_pi);
  const double r = ((x - n * p1) - n * p2) - n * p3;
  const double r2 = r * r;
  // Taylor series of sin and cos on |r| ≤ π/4 (remainders < 5e-17).
  const double sp =
      r + r * r2 *
              (-1.0 / 6 +
               r2 * (1.0 / 120 +
                     r2 * (-1.0 / 5040 +
                           r2 * (1.0 / 362880 +
                                 r2 * (-1.0 / 39916800 + r2 * (1.0 / 6227020800.0 +
                                                               r2 * (-1.0 / 1307674368000.0)))))));
  const double cp =
      1.0 +
      r2 * (-0.5 +
            r2 * (1.0 / 24 +
                  r2 * (-1.0 / 720 +
                        r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 +
                                                  r2 * (1.0 / 479001600.0 +
                                                        r2 * (-1.0 / 87178291200.0 +
                                                              r2 * (1.0 / 20922789888000.0))))))));
  // cos(nπ/2), sin(nπ/2) without integer arithmetic: n = 2f + e with e ∈ {−1, 0, 1};
  // (−1)^f = 1 − 2g² with g = f − 2 round(f/2) ∈ {−1, 0, 1}.
  const double f = round_nearest(0.5 * n);
  const double e = n - 2.0 * f;
  const double g = f - 2.0 * round_nearest(0.5 * f);
  const double p = 1.0 - 2.0 * g * g;
  const double cn = (1.0 - e * e) * p;
  const double sn = e * p;
  s = sp * cn + cp * sn;
  c = cp * cn - sp * sn;
}

/// e^x for x ≤ 0 (x below −700 is treated as −700, giving ≈ 1e-304 instead of a subnormal).
inline double fast_exp_nonpositive(double x) {
  constexpr double log2e = 1.44269504088896340736;
  constexpr double ln2_hi = 6.93147180369123816490e-01;  // fdlibm's ln2_hi / ln2_lo split
  constexpr double ln2_lo = 1.90821492927058770002e-10;
  // max(x, −700) written with fabs: GCC (without -ffast-math) does not if-convert a compare here,
  // and a branch would stop the loop around this function from vectorising.
  // For x ≥ −700 the correction is exactly zero, so x passes unchanged.
  x += 0.5 * (std::fabs(x + 700.0) - (x + 700.0));
  const double n = round_nearest(x * log2e);
  const double r = (x - n * ln2_hi) - n * ln2_lo;
  // Taylor series of e^r on |r| ≤ ln2/2 to r^12 (remainder < 2e-16).
  const double pr =
      1.0 +
      r * (1.0 +
           r * (1.0 / 2 +
                r * (1.0 / 6 +
                     r * (1.0 / 24 +
                          r * (1.0 / 120 +
                               r * (1.0 / 720 +
                                    r * (1.0 / 5040 +
                                         r * (1.0 / 40320 +
                                              r * (1.0 / 362880 +
                                                   r * (1.0 / 3628800 +
                                                        r * (1.0 / 39916800 +
                                                             r * (1.0 / 479001600.0))))))))))));
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

}  // namespace detail
}  // namespace environment
}  // namespace kelp
