/// \file
/// \brief The CPU-specific part of the wave field (kelp/environment/waves.hpp): the batch kernel
/// that sums the Airy components' elevation, orbital velocity and acceleration (and, for one
/// point, the velocity gradient and surface slope) over blocks of points, written on the
/// vectorisable math of kelp/core/fast_math.hpp, and AVX2 + FMA and AVX-512 builds of the same
/// code on x86-64, chosen at run time (kelp/core/kernel_path.hpp: the widest the CPU runs, or the
/// path the process or the wave field pins). Internal: the public interface is `WaveField`.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "kelp/core/fast_math.hpp"
#include "kelp/core/kernel_path.hpp"

namespace kelp {
namespace environment {

namespace detail {

/// Per-component constants of a wave field, as plain arrays (see `WaveField`).
struct WaveComponentsView {
  const double *omega, *k, *amp, *phase, *kx, *ky, *aw, *aw2, *awc, *aws, *aw2c, *aw2s, *q, *e2h;
  /// k a ω times cos²β, cos β sin β, sin²β, cos β, sin β: the velocity gradient's constants.
  const double *gcc, *gcs, *gss, *gc, *gs;
  std::size_t n;
  double two_h;  ///< twice the water depth (finite depth only)
  /// A depth no trough reaches: (Σ a_j)(1 + 1e-9) ≥ |ζ| with room for rounding. The batch
  /// kernel does not sum the elevation of points at least this deep (they are always wet).
  double trough_bound;
};

/// Points per block of the batch kernel.
inline constexpr int kWaveBlock = 32;

/// One block of points in structure-of-arrays form (on the stack) and its accumulators.
struct WaveBlock {
  double x[kWaveBlock], y[kWaveBlock], z[kWaveBlock];
  double ze[kWaveBlock];  ///< depth clamped to [0, h]
  double zeta[kWaveBlock], vx[kWaveBlock], vy[kWaveBlock], vz[kWaveBlock], ax[kWaveBlock],
      ay[kWaveBlock], az[kWaveBlock];
  /// Sum the elevation of every point (else only of points that may be above a trough).
  bool need_zeta = false;
  /// Velocity gradient ∂v_i/∂x_k of a single-point query (point 0): xx, xy, yy, xz, yz
  /// (symmetric; zz = −xx − yy).
  double gxx, gxy, gyy, gxz, gyz;
  /// Surface slope (∂ζ/∂x, ∂ζ/∂y) of a single-point query (point 0).
  double sx, sy;
};

/// Accumulators of elevation, velocity and acceleration for kLanes lanes.
template <int kLanes>
struct WaveLanes {
  double zeta[kLanes] = {}, vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {}, ax[kLanes] = {},
         ay[kLanes] = {}, az[kLanes] = {};
  double gxx[kLanes] = {}, gxy[kLanes] = {}, gyy[kLanes] = {}, gxz[kLanes] = {}, gyz[kLanes] = {};
  double sx[kLanes] = {}, sy[kLanes] = {};
};

/// \brief Put before a loop over a wave kernel's lanes: vectorise that loop as written.
///
/// The lane loops are written for the vectoriser: GCC unrolls them and packs the lanes into
/// vector registers; Clang unrolls them first and then leaves most of the arithmetic scalar (its
/// AVX2 kernel ran 2.8× slower than GCC's) unless told to vectorise the loop itself. Empty for
/// other compilers. Where Clang cannot vectorise (with -fsanitize=undefined, whose checks stay in
/// the loop) the loop stays scalar, as without the pragma, and its -Wpass-failed warning (44 per
/// unit that instantiates the kernels) is silenced from here to the end of this header, where
/// the warning lands once the loops are inlined into the kernels: it says nothing a user can act
/// on.
#if defined(__clang__)
#define KELP_VECTORIZE_LANES _Pragma("clang loop unroll(disable) vectorize(enable)")
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wpass-failed"
#else
#define KELP_VECTORIZE_LANES
#endif

/// Adds component j's contribution at (x, y, −nze), phase alpha = φ_j − ω_j t, to lane l of
/// `acc`: the Airy sums of the file comment, with F_h, F_v written with decaying exponentials only
/// and the direction cosines folded into the per-component constants (a ω cos β, a ω sin β,
/// a ω² cos β, a ω² sin β). The common sign of (sin θ, cos θ) is applied once, to the depth
/// factor. Without kZeta the elevation is not summed (the caller knows every
/// lane is below any trough). With kGrad the velocity gradient is summed too: for one component
/// (c = cos θ, s = sin θ) ∂v/∂x_k = a ω k [−F_h s cos²β, −F_h s cos β sin β, −F_v c cos β; ·,
/// −F_h s sin²β, −F_v c sin β; ·, ·, F_h s] (symmetric: the flow is irrotational; trace-free:
/// incompressible), using ∂F_h/∂z = −k F_v and ∂F_v/∂z = −k F_h; and so is the surface slope,
/// ∂ζ/∂x = −Σ a k_x sin θ, ∂ζ/∂y = −Σ a k_y sin θ (the sines are already there).
template <bool kFinite, bool kZeta, int kLanes, bool kGrad = false>
KELP_ALWAYS_INLINE inline void wave_term(const WaveComponentsView& c, std::size_t j, double alpha,
                                         double x, double y, double nze, WaveLanes<kLanes>& acc,
                                         int l) {
  double sn, cs;
  std::uint64_t sign;
  // Grouped so that the per-component constant alpha = φ − ω t is the addend of a fused
  // multiply-add.
  simd::fast_sincos_unsigned(c.kx[j] * x + (c.ky[j] * y + alpha), sn, cs, sign);
  // k·ze ≤ 700 by the caller; e carries the sign of (sin θ, cos θ).
  const double e = simd::flip_sign(simd::fast_exp_nonpositive_unchecked<false>(c.k[j] * nze), sign);
  double fh = e, fv = e;
  if constexpr (kFinite) {
    // e^{−k(2h − z)} = e^{−2kh} / e^{−kz}: a division instead of a second exponential (e ≠ 0
    // because the caller clamps k z ≤ 700; e^{−2kh} ≤ e² may underflow to 0, which is right).
    // Both terms carry the sign of e.
    const double e2 = c.e2h[j] / e;
    fh = (e + e2) * c.q[j];
    fv = (e - e2) * c.q[j];
  }
  if constexpr (kZeta) acc.zeta[l] += c.amp[j] * simd::flip_sign(cs, sign);
  const double hc = fh * cs, hs = fh * sn;  // F_h cos θ, F_h sin θ
  acc.vx[l] += c.awc[j] * hc;
  acc.vy[l] += c.aws[j] * hc;
  acc.ax[l] += c.aw2c[j] * hs;
  acc.ay[l] += c.aw2s[j] * hs;
  if constexpr (kFinite) {
    acc.vz[l] -= c.aw[j] * (fv * sn);
    acc.az[l] += c.aw2[j] * (fv * cs);
  } else {  // F_v = F_h in deep water
    acc.vz[l] -= c.aw[j] * hs;
    acc.az[l] += c.aw2[j] * hc;
  }
  if constexpr (kGrad) {
    const double fvc = kFinite ? fv * cs : hc;
    acc.gxx[l] -= c.gcc[j] * hs;
    acc.gxy[l] -= c.gcs[j] * hs;
    acc.gyy[l] -= c.gss[j] * hs;
    acc.gxz[l] -= c.gc[j] * fvc;
    acc.gyz[l] -= c.gs[j] * fvc;
    const double as = c.amp[j] * simd::flip_sign(sn, sign);  // a sin θ
    acc.sx[l] -= c.kx[j] * as;
    acc.sy[l] -= c.ky[j] * as;
  }
}

/// Components per chunk of the batch kernel: the phases φ_j − ω_j t of a chunk are computed
/// once per call into a stack array.
inline constexpr std::size_t kWaveChunk = 128;

/// Adds components [j0, j0 + nj) (phases `alpha`) to points [i0, min(i0 + kLanes, m)) of the
/// block (the first chunk, j0 = 0, writes the sums instead): points go in lanes (a compile-time
/// width the compiler maps onto vector registers; a short group is padded with copies of its first
/// point) and the lane accumulators stay in registers across the loop over components.
template <bool kFinite, int kLanes>
KELP_ALWAYS_INLINE inline void wave_group(const WaveComponentsView& c, const double* alpha,
                                          std::size_t j0, std::size_t nj, WaveBlock& b, int i0,
                                          int m) {
  double x[kLanes], y[kLanes], nze[kLanes];
  bool below_troughs = !b.need_zeta;  // every lane deeper than the lowest possible trough
  for (int l = 0; l < kLanes; ++l) {
    const int i = i0 + l < m ? i0 + l : i0;
    x[l] = b.x[i];
    y[l] = b.y[i];
    nze[l] = -b.ze[i];
    below_troughs = below_troughs && b.z[i] >= c.trough_bound;
  }
  WaveLanes<kLanes> acc;
  // The elevation only decides whether a point is above the free surface; none of these is.
  if (below_troughs) {
    for (std::size_t j = 0; j < nj; ++j) {
      KELP_VECTORIZE_LANES
      for (int l = 0; l < kLanes; ++l)
        wave_term<kFinite, false>(c, j0 + j, alpha[j], x[l], y[l], nze[l], acc, l);
    }
  } else {
    for (std::size_t j = 0; j < nj; ++j) {
      KELP_VECTORIZE_LANES
      for (int l = 0; l < kLanes; ++l)
        wave_term<kFinite, true>(c, j0 + j, alpha[j], x[l], y[l], nze[l], acc, l);
    }
  }
  if (j0 == 0) {  // the first chunk writes the block's sums (no zeroing pass before the kernel)
    for (int l = 0; l < kLanes && i0 + l < m; ++l) {
      const int i = i0 + l;
      b.zeta[i] = acc.zeta[l];
      b.vx[i] = acc.vx[l];
      b.vy[i] = acc.vy[l];
      b.vz[i] = acc.vz[l];
      b.ax[i] = acc.ax[l];
      b.ay[i] = acc.ay[l];
      b.az[i] = acc.az[l];
    }
  } else {
    for (int l = 0; l < kLanes && i0 + l < m; ++l) {
      const int i = i0 + l;
      b.zeta[i] += acc.zeta[l];
      b.vx[i] += acc.vx[l];
      b.vy[i] += acc.vy[l];
      b.vz[i] += acc.vz[l];
      b.ax[i] += acc.ax[l];
      b.ay[i] += acc.ay[l];
      b.az[i] += acc.az[l];
    }
  }
}

/// Writes every component's elevation, velocity and acceleration sums into the block.
/// Several points: groups of kWide points in lanes (`wave_group`), the rest in groups of 8 and
/// a last one of 4 (less padding). One point: the components go in lanes instead, and the lanes are
/// summed at the end. Neither inner loop has a branch or a call, so both vectorise. The components
/// are taken in chunks whose phases at time t are computed first.
template <bool kFinite, int kWide>
KELP_ALWAYS_INLINE inline void wave_accumulate_impl(const WaveComponentsView& c, WaveBlock& b,
                                                    int m, double t) {
  constexpr int kLanes = 8;
  alignas(64) double alpha[kWaveChunk];
  for (std::size_t j0 = 0; j0 < c.n; j0 += kWaveChunk) {
    const std::size_t nj = std::min(kWaveChunk, c.n - j0);
    // φ − ω t in double, reduced to [−π, π]: exact to double rounding for any t.
    for (std::size_t j = 0; j < nj; ++j)
      alpha[j] = simd::wrap_two_pi(c.phase[j0 + j] - c.omega[j0 + j] * t);
    if (m == 1) {
      WaveLanes<kLanes> acc;
      const double x = b.x[0], y = b.y[0], nze = -b.ze[0];
      std::size_t j = 0;
      for (; j + kLanes <= nj; j += kLanes) {
        KELP_VECTORIZE_LANES
        for (int l = 0; l < kLanes; ++l)
          wave_term<kFinite, true, kLanes, true>(c, j0 + j + l, alpha[j + l], x, y, nze, acc, l);
      }
      for (; j < nj; ++j)
        wave_term<kFinite, true, kLanes, true>(c, j0 + j, alpha[j], x, y, nze, acc, 0);
      if (j0 == 0) {
        b.zeta[0] = b.vx[0] = b.vy[0] = b.vz[0] = b.ax[0] = b.ay[0] = b.az[0] = 0.0;
        b.gxx = b.gxy = b.gyy = b.gxz = b.gyz = 0.0;
        b.sx = b.sy = 0.0;
      }
      for (int l = 0; l < kLanes; ++l) {
        b.zeta[0] += acc.zeta[l];
        b.vx[0] += acc.vx[l];
        b.vy[0] += acc.vy[l];
        b.vz[0] += acc.vz[l];
        b.ax[0] += acc.ax[l];
        b.ay[0] += acc.ay[l];
        b.az[0] += acc.az[l];
        b.gxx += acc.gxx[l];
        b.gxy += acc.gxy[l];
        b.gyy += acc.gyy[l];
        b.gxz += acc.gxz[l];
        b.gyz += acc.gyz[l];
        b.sx += acc.sx[l];
        b.sy += acc.sy[l];
      }
      continue;
    }
    int i0 = 0;
    if constexpr (kWide > kLanes)
      for (; m - i0 > kLanes; i0 += kWide) wave_group<kFinite, kWide>(c, alpha, j0, nj, b, i0, m);
    for (; m - i0 > kLanes / 2; i0 += kLanes)
      wave_group<kFinite, kLanes>(c, alpha, j0, nj, b, i0, m);
    if (i0 < m) wave_group<kFinite, kLanes / 2>(c, alpha, j0, nj, b, i0, m);  // ≤ 4 left
  }
}

// The kernels below are function templates (of a placeholder type, `double` by default) rather
// than inline functions, so that a unit compiles their several instruction sets only when it
// instantiates them: a compiled layer on kelp (kelp::sim) instantiates them once
// (`extern template`) instead of in every one of its units.

/// The kernel for the baseline instruction set of the build.
template <typename Instance = double>
void wave_accumulate_baseline(const WaveComponentsView& c, WaveBlock& b, int m, double t,
                              bool finite) {
  if (finite)
    wave_accumulate_impl<true, 8>(c, b, m, t);
  else
    wave_accumulate_impl<false, 8>(c, b, m, t);
}

#ifdef KELP_X86_DISPATCH
/// The same kernel compiled for AVX2 + FMA (4 doubles per instruction), chosen at run time when
/// the CPU has them. Results differ from the baseline only by FMA rounding (≲ 1e-15 relative).
template <typename Instance = double>
__attribute__((target("avx2,fma"))) void wave_accumulate_avx2(const WaveComponentsView& c,
                                                              WaveBlock& b, int m, double t,
                                                              bool finite) {
  if (finite)
    wave_accumulate_impl<true, 8>(c, b, m, t);
  else
    wave_accumulate_impl<false, 8>(c, b, m, t);
}

#if defined(__clang__)
#define KELP_ENV_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx2,fma")))
#else  // GCC keeps 256-bit vectors for AVX-512 unless told otherwise
#define KELP_ENV_TARGET_AVX512 \
  __attribute__((target("avx512f,avx512dq,avx2,fma,prefer-vector-width=512")))
#endif
/// The same kernel compiled for AVX-512 (8 doubles per instruction).
template <typename Instance = double>
KELP_ENV_TARGET_AVX512 void wave_accumulate_avx512(const WaveComponentsView& c, WaveBlock& b, int m,
                                                   double t, bool finite) {
  if (finite)
    wave_accumulate_impl<true, 16>(c, b, m, t);
  else
    wave_accumulate_impl<false, 16>(c, b, m, t);
}
#endif

#ifdef KELP_X86_DISPATCH
// The portable path's wide builds: the baseline's operations, wider. Without FMA enabled the
// compiler cannot contract a multiply–add, every other operation is IEEE-rounded lane by lane,
// each point's (or lane's) sum keeps its order, and no reassociation is allowed (kelp refuses
// -fassociative-math): the same bits as the baseline build (tested), 2–4× faster.
/// The baseline kernel compiled for AVX2 without FMA (`target("avx2")` enables no FMA).
template <typename Instance = double>
__attribute__((target("avx2"))) void wave_accumulate_avx2_exact(const WaveComponentsView& c,
                                                                WaveBlock& b, int m, double t,
                                                                bool finite) {
  if (finite)
    wave_accumulate_impl<true, 8>(c, b, m, t);
  else
    wave_accumulate_impl<false, 8>(c, b, m, t);
}
#if KELP_PORTABLE_AVX512
/// The baseline kernel compiled for AVX-512 with contraction off (GCC's AVX-512 enables FMA, so
/// `optimize("fp-contract=off")` forbids fusing; clang has no such attribute: not built there).
template <typename Instance = double>
__attribute__((target("avx512f,avx512dq,avx2,prefer-vector-width=512"),
               optimize("fp-contract=off"))) void
wave_accumulate_avx512_exact(const WaveComponentsView& c, WaveBlock& b, int m, double t,
                             bool finite) {
  if (finite)
    wave_accumulate_impl<true, 16>(c, b, m, t);
  else
    wave_accumulate_impl<false, 16>(c, b, m, t);
}
#endif
#endif

/// The wave kernel on instruction path `path` (a concrete one, supported by the CPU: see
/// `simd::resolve_kernel`). `portable` runs the baseline kernel's operations on the widest vectors
/// the CPU has without FMA (`simd::detail::portable_build()`), the same bits as the baseline build;
/// in a build without run-time dispatch every path is the baseline kernel.
inline void wave_accumulate(const WaveComponentsView& c, WaveBlock& b, int m, double t, bool finite,
                            simd::KernelPath path) {
#ifdef KELP_X86_DISPATCH
  if (path == simd::KernelPath::avx512) return wave_accumulate_avx512<>(c, b, m, t, finite);
  if (path == simd::KernelPath::avx2) return wave_accumulate_avx2<>(c, b, m, t, finite);
  const int build = simd::detail::portable_build();
#if KELP_PORTABLE_AVX512
  if (build == 2) return wave_accumulate_avx512_exact<>(c, b, m, t, finite);
#endif
  if (build >= 1) return wave_accumulate_avx2_exact<>(c, b, m, t, finite);
#else
  (void)path;
#endif
  wave_accumulate_baseline<>(c, b, m, t, finite);
}

}  // namespace detail

}  // namespace environment
}  // namespace kelp

/// \brief The double-precision wave kernels of this build (one per instruction set), for a
/// compiled layer that instantiates them once: `KELP_WAVE_KERNEL_INSTANCES(template)` in one
/// unit, `KELP_WAVE_KERNEL_INSTANCES(extern template)` wherever they are used (kelp::sim does:
/// kelp/sim/instantiation.hpp). `prefix` may carry attributes after `template`.
#define KELP_WAVE_KERNEL_INSTANCE(prefix, name)                                                    \
  prefix void kelp::environment::detail::name<double>(                                             \
      const kelp::environment::detail::WaveComponentsView&, kelp::environment::detail::WaveBlock&, \
      int, double, bool);
#ifdef KELP_X86_DISPATCH
#if KELP_PORTABLE_AVX512
#define KELP_WAVE_KERNEL_INSTANCES_AVX512_EXACT(prefix) \
  KELP_WAVE_KERNEL_INSTANCE(prefix, wave_accumulate_avx512_exact)
#else
#define KELP_WAVE_KERNEL_INSTANCES_AVX512_EXACT(prefix)
#endif
#define KELP_WAVE_KERNEL_INSTANCES(prefix)                      \
  KELP_WAVE_KERNEL_INSTANCE(prefix, wave_accumulate_baseline)   \
  KELP_WAVE_KERNEL_INSTANCE(prefix, wave_accumulate_avx2)       \
  KELP_WAVE_KERNEL_INSTANCE(prefix, wave_accumulate_avx512)     \
  KELP_WAVE_KERNEL_INSTANCE(prefix, wave_accumulate_avx2_exact) \
  KELP_WAVE_KERNEL_INSTANCES_AVX512_EXACT(prefix)
#else
/// \brief The double-precision wave kernels of this build, instantiated with `prefix`
/// (`template` or `extern template`): here only the portable one (no x86 dispatch).
#define KELP_WAVE_KERNEL_INSTANCES(prefix) \
  KELP_WAVE_KERNEL_INSTANCE(prefix, wave_accumulate_baseline)
#endif

#if defined(__clang__)
#pragma clang diagnostic pop  // -Wpass-failed, silenced at KELP_VECTORIZE_LANES
#endif
