/// \file
/// \brief Packs of 4 doubles in AVX registers for kelp's run-time dispatched tether force passes
/// (kelp/tether/force_pass_body.hpp), with the interface of kelp/core/simd.hpp's `Pack`; and the
/// `KELP_AVX2_BEGIN` / `KELP_AVX2_END` pair that compiles the functions defined between them for
/// AVX2 (without FMA).
///
/// Defined only where kelp dispatches at run time (`KELP_X86_DISPATCH`: GCC or clang on x86-64,
/// a baseline below AVX2). Every operation is the lane-wise IEEE operation the baseline's SSE2
/// packets do (add, subtract, multiply, divide, square root, compare, select: one rounding each,
/// no fused multiply–add, as no FMA is enabled), so code written over these packs gives the same
/// bits as the same code over SSE2 packets or over one scalar.
///
/// Why a region and not attributes on each function: a function template takes the target of
/// the place it is defined, and an always-inline AVX operation cannot be inlined into a template
/// compiled for the baseline, even one that is itself inlined into AVX code later (GCC and clang
/// both refuse). So a kernel meant for both is defined twice, once inside the region.
#pragma once

#include "kelp/core/kernel_path.hpp"
#include "kelp/core/simd.hpp"

#if defined(KELP_X86_DISPATCH)

#if defined(__clang__)
#define KELP_AVX2_BEGIN \
  _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define KELP_AVX2_END _Pragma("clang attribute pop")
#else
#define KELP_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define KELP_AVX2_END _Pragma("GCC pop_options")
#endif

KELP_AVX2_BEGIN
namespace kelp::simd::detail::avx2 {

// GCC's and clang's vector extensions and the builtins their <immintrin.h> is written with, not
// <immintrin.h> itself: that header costs every unit that includes kelp/tether/forces.hpp ~0.8 CPU
// s and ~95 MB (GCC 12), for the dozen operations used here.
typedef double V4d __attribute__((vector_size(32)));
typedef unsigned long long V4i __attribute__((vector_size(32)));
typedef double V4du __attribute__((vector_size(32), aligned(8), may_alias));  // unaligned
inline constexpr int kCmpLtOs = 0x01;  // _CMP_LT_OS: cmpltpd's predicate
inline constexpr int kCmpLeOs = 0x02;  // _CMP_LE_OS: cmplepd's predicate

/// 4 doubles in an AVX register: kelp::simd::Pack's interface (the operations the force
/// kernels use), each the instruction Eigen's SSE2 packet uses, on 4 lanes.
struct Pack4d {
  using Raw = V4d;
  static constexpr int lanes = 4;
  V4d r;

  Pack4d() = default;
  explicit Pack4d(V4d raw) : r(raw) {}
  static Pack4d all(double s) { return Pack4d(V4d{s, s, s, s}); }
  static Pack4d gather(const double* p, Eigen::Index stride) {
    return Pack4d(V4d{p[0], p[stride], p[2 * stride], p[3 * stride]});
  }
  static Pack4d load(const double* p) { return Pack4d(*reinterpret_cast<const V4du*>(p)); }
  void scatter(double* p, Eigen::Index stride) const {
    p[0] = r[0];
    p[stride] = r[1];
    p[2 * stride] = r[2];
    p[3 * stride] = r[3];
  }
  void store(double* p) const { *reinterpret_cast<V4du*>(p) = r; }
  /// Four columns of a column-major 3×N matrix as its three rows: 3 loads, 3 lane-pair
  /// permutes and 3 shuffles instead of 3 gathers of 4 scalars.
  /// [x0 y0 | z0 x1] [y1 z1 | x2 y2] [z2 x3 | y3 z3] → [x0 y0 | x2 y2] [z0 x1 | z2 x3]
  /// [y1 z1 | y3 z3] → [x0 x1 x2 x3] [y0 y1 y2 y3] [z0 z1 z2 z3].
  static void load3(const double* p, Pack4d& x, Pack4d& y, Pack4d& z) {
    const V4d a = *reinterpret_cast<const V4du*>(p), b = *reinterpret_cast<const V4du*>(p + 4),
              c = *reinterpret_cast<const V4du*>(p + 8);
    const V4d m1 = __builtin_ia32_vperm2f128_pd256(a, b, 0x30);
    const V4d m2 = __builtin_ia32_vperm2f128_pd256(a, c, 0x21);
    const V4d m3 = __builtin_ia32_vperm2f128_pd256(b, c, 0x30);
    x = Pack4d(__builtin_ia32_shufpd256(m1, m2, 0xA));
    y = Pack4d(__builtin_ia32_shufpd256(m1, m3, 0x5));
    z = Pack4d(__builtin_ia32_shufpd256(m2, m3, 0xA));
  }
  /// The inverse of load3(): x, y, z as the rows of four columns, three whole stores.
  static void store3(double* p, Pack4d x, Pack4d y, Pack4d z) {
    const V4d m1 = __builtin_ia32_shufpd256(x.r, y.r, 0x0);  // [x0 y0 | x2 y2]
    const V4d m2 = __builtin_ia32_shufpd256(z.r, x.r, 0xA);  // [z0 x1 | z2 x3]
    const V4d m3 = __builtin_ia32_shufpd256(y.r, z.r, 0xF);  // [y1 z1 | y3 z3]
    *reinterpret_cast<V4du*>(p) = __builtin_ia32_vperm2f128_pd256(m1, m2, 0x20);
    *reinterpret_cast<V4du*>(p + 4) = __builtin_ia32_vperm2f128_pd256(m3, m1, 0x30);
    *reinterpret_cast<V4du*>(p + 8) = __builtin_ia32_vperm2f128_pd256(m2, m3, 0x31);
  }
  Pack4d& operator+=(Pack4d b) {
    r += b.r;
    return *this;
  }
  Pack4d& operator-=(Pack4d b) {
    r -= b.r;
    return *this;
  }
  /// The lanes' sum, (r0 + r1) + (r2 + r3) (the implicit steps' finiteness sum,
  /// kelp/tether/step_pass_body.hpp).
  double sum() const { return (r[0] + r[1]) + (r[2] + r[3]); }
};

// Free functions, not friends defined in the class: GCC does not give those the region's target.
inline Pack4d operator+(Pack4d a, Pack4d b) { return Pack4d(a.r + b.r); }
inline Pack4d operator-(Pack4d a, Pack4d b) { return Pack4d(a.r - b.r); }
inline Pack4d operator*(Pack4d a, Pack4d b) { return Pack4d(a.r * b.r); }
inline Pack4d operator/(Pack4d a, Pack4d b) { return Pack4d(a.r / b.r); }
inline V4i sign_bits() {
  constexpr unsigned long long sign = 0x8000000000000000ull;
  return V4i{sign, sign, sign, sign};
}
inline Pack4d sqrt(Pack4d a) { return Pack4d(__builtin_ia32_sqrtpd256(a.r)); }
// Lane-wise maximum: maxpd's operand order as Eigen's SSE2 pmax (the same lane for NaN).
inline Pack4d max(Pack4d a, Pack4d b) { return Pack4d(__builtin_ia32_maxpd256(b.r, a.r)); }
inline Pack4d abs(Pack4d a) { return Pack4d(V4d(V4i(a.r) & ~sign_bits())); }

/// Lane-wise comparison result of Pack4d (all bits set in the true lanes).
struct Mask4d {
  V4d m;
};
// The predicates of SSE2's cmpltpd / cmplepd (ordered, signalling), so that the flags raised match.
inline Mask4d greater(Pack4d a, Pack4d b) { return {__builtin_ia32_cmppd256(b.r, a.r, kCmpLtOs)}; }
inline Mask4d greater_equal(Pack4d a, Pack4d b) {
  return {__builtin_ia32_cmppd256(b.r, a.r, kCmpLeOs)};
}
inline Mask4d less(Pack4d a, Pack4d b) { return greater(b, a); }
inline Mask4d operator&&(Mask4d a, Mask4d b) { return {V4d(V4i(a.m) & V4i(b.m))}; }
inline Mask4d operator||(Mask4d a, Mask4d b) { return {V4d(V4i(a.m) | V4i(b.m))}; }
inline Pack4d select(Mask4d k, Pack4d a, Pack4d b) {
  return Pack4d(__builtin_ia32_blendvpd256(b.r, a.r, k.m));
}
inline bool any(Mask4d k) { return __builtin_ia32_movmskpd256(k.m) != 0; }

/// The pack of this namespace for a lane type and width: Pack4d for wide doubles; otherwise
/// kelp::simd's (one lane, or a lane type this namespace has no pack for).
template <typename Scalar, bool Wide>
struct PackOf {
  using type = ::kelp::simd::Pack<Scalar, Wide>;
};
template <>
struct PackOf<double, true> {
  using type = Pack4d;
};
template <typename Scalar, bool Wide>
using Pack = typename PackOf<Scalar, Wide>::type;

template <typename Scalar>
constexpr bool vectorized = std::is_same_v<Scalar, double> || ::kelp::simd::vectorized<Scalar>;

// kelp::simd's operations for the packs this namespace takes from it.
using ::kelp::simd::any;
using ::kelp::simd::greater;
using ::kelp::simd::greater_equal;
using ::kelp::simd::less;
using ::kelp::simd::select;

}  // namespace kelp::simd::detail::avx2
KELP_AVX2_END

#endif  // KELP_X86_DISPATCH
