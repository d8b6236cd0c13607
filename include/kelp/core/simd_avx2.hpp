/// \file
/// \brief Packs of 4 doubles in AVX registers for kelp's run-time dispatched tether force passes
/// (kelp/tether/force_kernels.hpp), with the interface of kelp/core/simd.hpp's `Pack`; and the
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
#include <immintrin.h>

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

/// 4 doubles in an AVX register: kelp::simd::Pack's interface (the operations the force
/// kernels use), each the instruction Eigen's SSE2 packet uses, on 4 lanes.
struct Pack4d {
  using Raw = __m256d;
  static constexpr int lanes = 4;
  __m256d r;

  Pack4d() = default;
  explicit Pack4d(__m256d raw) : r(raw) {}
  static Pack4d all(double s) { return Pack4d(_mm256_set1_pd(s)); }
  static Pack4d gather(const double* p, Eigen::Index stride) {
    return Pack4d(_mm256_set_pd(p[3 * stride], p[2 * stride], p[stride], p[0]));
  }
  static Pack4d load(const double* p) { return Pack4d(_mm256_loadu_pd(p)); }
  void scatter(double* p, Eigen::Index stride) const {
    const __m128d lo = _mm256_castpd256_pd128(r), hi = _mm256_extractf128_pd(r, 1);
    _mm_storel_pd(p, lo);
    _mm_storeh_pd(p + stride, lo);
    _mm_storel_pd(p + 2 * stride, hi);
    _mm_storeh_pd(p + 3 * stride, hi);
  }
  void store(double* p) const { _mm256_storeu_pd(p, r); }
  Pack4d& operator+=(Pack4d b) {
    r = _mm256_add_pd(r, b.r);
    return *this;
  }
  Pack4d& operator-=(Pack4d b) {
    r = _mm256_sub_pd(r, b.r);
    return *this;
  }
};

// Free functions, not friends defined in the class: GCC does not give those the region's target.
inline Pack4d operator+(Pack4d a, Pack4d b) { return Pack4d(_mm256_add_pd(a.r, b.r)); }
inline Pack4d operator-(Pack4d a, Pack4d b) { return Pack4d(_mm256_sub_pd(a.r, b.r)); }
inline Pack4d operator*(Pack4d a, Pack4d b) { return Pack4d(_mm256_mul_pd(a.r, b.r)); }
inline Pack4d operator/(Pack4d a, Pack4d b) { return Pack4d(_mm256_div_pd(a.r, b.r)); }
inline Pack4d operator-(Pack4d a) { return Pack4d(_mm256_xor_pd(a.r, _mm256_set1_pd(-0.0))); }
inline Pack4d sqrt(Pack4d a) { return Pack4d(_mm256_sqrt_pd(a.r)); }
inline Pack4d abs(Pack4d a) { return Pack4d(_mm256_andnot_pd(_mm256_set1_pd(-0.0), a.r)); }

/// Lane-wise comparison result of Pack4d (all bits set in the true lanes).
struct Mask4d {
  __m256d m;
};
// The predicates of SSE2's cmpltpd / cmplepd (ordered, signalling), so that the flags raised match.
inline Mask4d greater(Pack4d a, Pack4d b) { return {_mm256_cmp_pd(b.r, a.r, _CMP_LT_OS)}; }
inline Mask4d greater_equal(Pack4d a, Pack4d b) { return {_mm256_cmp_pd(b.r, a.r, _CMP_LE_OS)}; }
inline Mask4d less(Pack4d a, Pack4d b) { return greater(b, a); }
inline Mask4d operator&&(Mask4d a, Mask4d b) { return {_mm256_and_pd(a.m, b.m)}; }
inline Mask4d operator||(Mask4d a, Mask4d b) { return {_mm256_or_pd(a.m, b.m)}; }
inline Pack4d select(Mask4d k, Pack4d a, Pack4d b) {
  return Pack4d(_mm256_blendv_pd(b.r, a.r, k.m));
}
inline bool any(Mask4d k) { return _mm256_movemask_pd(k.m) != 0; }

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
