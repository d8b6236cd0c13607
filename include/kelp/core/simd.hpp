/// \file
/// \brief A small value type over Eigen's SIMD packets, so that a kernel is written once as
/// scalar-looking code and runs on as many lanes as the compiler flags give (SSE2: 2 doubles or
/// 4 floats; AVX: 4 or 8; one lane for types Eigen does not vectorise).
///
/// Built on Eigen's packet primitives (Eigen/src/Core/GenericPacketMath.h, the layer Eigen's own
/// expressions are evaluated with): each lane gets the IEEE operation the scalar code would do,
/// so a kernel gives the same bits in every lane as the same kernel on one scalar (as long as
/// the compiler does not contract multiply–adds differently, e.g. with FMA enabled).
#pragma once

#include <Eigen/Core>
#include <type_traits>

#include "kelp/core/compiler_checks.hpp"

// Packet types carry vector attributes that GCC drops (and warns about) when they are template
// arguments, as Eigen's own headers do (Eigen/src/Core/util/DisableStupidWarnings.h).
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"
#endif

namespace kelp::simd {

/// \brief True when Eigen vectorises `Scalar` with the current compiler flags.
/// \tparam Scalar the lane type (double and float vectorise on x86-64).
template <typename Scalar>
constexpr bool vectorized = bool(Eigen::internal::packet_traits<Scalar>::Vectorizable) &&
                            (Eigen::internal::packet_traits<Scalar>::size > 1);

namespace detail {
/// Packets of at most 32 bytes: the kernels gather their operands from 3-component columns, and
/// 64-byte (AVX-512) gathers cost more than the wider arithmetic saves (measured: a tether force
/// evaluation about 2× slower with 8 doubles per packet than with 4).
template <typename P, bool = (sizeof(P) > 32)>
struct AtMost32Bytes {
  using type = P;
};
template <typename P>
struct AtMost32Bytes<P, true> {
  using type = typename AtMost32Bytes<typename Eigen::internal::unpacket_traits<P>::half>::type;
};
template <typename Scalar, bool Wide>
struct RawPack {
  using type = Scalar;
};
template <typename Scalar>
struct RawPack<Scalar, true> {
  using type = typename AtMost32Bytes<typename Eigen::internal::packet_traits<Scalar>::type>::type;
};
}  // namespace detail

/// \brief `lanes` values of `Scalar` processed together: the widest Eigen packet of at most 32
/// bytes when `Wide`, a plain scalar otherwise (the same code then handles remainders and odd
/// cases).
///
/// \tparam Scalar the lane type (double or float vectorise; any other type, e.g. ceres::Jet,
/// gives one lane).
/// \tparam Wide true for the widest packet, false for one lane (the remainder of a loop).
template <typename Scalar, bool Wide>
struct Pack {
  /// The storage: an Eigen packet type (e.g. `Packet4d`), or `Scalar` itself for one lane.
  using Raw = typename detail::RawPack<Scalar, Wide && vectorized<Scalar>>::type;
  /// Number of `Scalar` values in the pack (1 when not `Wide` or not vectorised).
  static constexpr int lanes = Eigen::internal::unpacket_traits<Raw>::size;
  Raw r;  ///< The lanes (read them with store() or sum(), not by indexing).

  Pack() = default;
  /// \brief Wraps a raw packet (or, for one lane, a scalar) without conversion.
  /// \param raw the lane values.
  explicit Pack(Raw raw) : r(raw) {}
  /// \brief All lanes set to `s`.
  /// \param s the value of every lane.
  /// \return the broadcast pack.
  static Pack all(Scalar s) { return Pack(Eigen::internal::pset1<Raw>(s)); }
  /// \brief Lanes from `p[0], p[stride], p[2 stride], …`.
  /// \param p the first value; `p[(lanes - 1) stride]` must be readable.
  /// \param stride distance between lanes in elements (3 for one component of a column-major
  /// 3×N matrix).
  /// \return the gathered pack.
  static Pack gather(const Scalar* p, Eigen::Index stride) {
    if constexpr (lanes == 1)
      return Pack(*p);
    else
      return Pack(Eigen::internal::pgather<Scalar, Raw>(p, stride));
  }
  /// \brief Lanes from `p[0], p[1], …` (no alignment needed).
  /// \param p the first of `lanes` consecutive readable values.
  /// \return the loaded pack.
  static Pack load(const Scalar* p) {
    if constexpr (lanes == 1)
      return Pack(*p);
    else
      return Pack(Eigen::internal::ploadu<Raw>(p));
  }
  /// \brief Stores the lanes to `p[0], p[stride], …`.
  /// \param p where lane 0 goes; `p[(lanes - 1) stride]` must be writable.
  /// \param stride distance between lanes in elements.
  void scatter(Scalar* p, Eigen::Index stride) const {
    if constexpr (lanes == 1)
      *p = r;
    else
      Eigen::internal::pscatter<Scalar, Raw>(p, r, stride);
  }
  /// \brief The three rows of `lanes` consecutive columns of a column-major 3×N matrix:
  /// x from `p[0], p[3], …`, y from `p[1], p[4], …`, z from `p[2], p[5], …` (three gathers of
  /// stride 3; on SSE2 three loads and three shuffles).
  /// \param p the first column; `p[3 lanes − 1]` must be readable.
  /// \param x out: the first row's lanes.
  /// \param y out: the second row's lanes.
  /// \param z out: the third row's lanes.
  static void load3(const Scalar* p, Pack& x, Pack& y, Pack& z) {
    if constexpr (lanes == 1) {
      x = Pack(p[0]);
      y = Pack(p[1]);
      z = Pack(p[2]);
#if defined(EIGEN_VECTORIZE_SSE2)
    } else if constexpr (std::is_same_v<Raw, Eigen::internal::Packet2d>) {
      // [x0 y0] [z0 x1] [y1 z1] → [x0 x1] [y0 y1] [z0 z1]
      const __m128d a = _mm_loadu_pd(p), b = _mm_loadu_pd(p + 2), c = _mm_loadu_pd(p + 4);
      x = Pack(_mm_shuffle_pd(a, b, 2));
      y = Pack(_mm_shuffle_pd(a, c, 1));
      z = Pack(_mm_shuffle_pd(b, c, 2));
#endif
    } else {
      x = gather(p, 3);
      y = gather(p + 1, 3);
      z = gather(p + 2, 3);
    }
  }
  /// \brief Stores x, y, z as the three rows of `lanes` consecutive columns of a column-major
  /// 3×N matrix (the inverse of load3()).
  /// \param p the first column; `p[3 lanes − 1]` must be writable.
  /// \param x the first row's lanes.
  /// \param y the second row's lanes.
  /// \param z the third row's lanes.
  static void store3(Scalar* p, Pack x, Pack y, Pack z) {
    if constexpr (lanes == 1) {
      p[0] = x.r;
      p[1] = y.r;
      p[2] = z.r;
#if defined(EIGEN_VECTORIZE_SSE2)
    } else if constexpr (std::is_same_v<Raw, Eigen::internal::Packet2d>) {
      _mm_storeu_pd(p, _mm_shuffle_pd(x.r, y.r, 0));
      _mm_storeu_pd(p + 2, _mm_shuffle_pd(z.r, x.r, 2));
      _mm_storeu_pd(p + 4, _mm_shuffle_pd(y.r, z.r, 3));
#endif
    } else {
      x.scatter(p, 3);
      y.scatter(p + 1, 3);
      z.scatter(p + 2, 3);
    }
  }
  /// \brief Stores the lanes to `p[0], p[1], …` (no alignment needed).
  /// \param p the first of `lanes` consecutive writable values.
  void store(Scalar* p) const {
    if constexpr (lanes == 1)
      *p = r;
    else
      Eigen::internal::pstoreu<Scalar, Raw>(p, r);
  }

  friend Pack operator+(Pack a, Pack b) { return Pack(Eigen::internal::padd(a.r, b.r)); }
  friend Pack operator-(Pack a, Pack b) { return Pack(Eigen::internal::psub(a.r, b.r)); }
  friend Pack operator*(Pack a, Pack b) { return Pack(Eigen::internal::pmul(a.r, b.r)); }
  friend Pack operator/(Pack a, Pack b) { return Pack(Eigen::internal::pdiv(a.r, b.r)); }
  friend Pack operator-(Pack a) { return Pack(Eigen::internal::pnegate(a.r)); }
  /// \brief Lane-wise `*this = *this + b`.
  /// \param b the pack added.
  /// \return `*this`.
  Pack& operator+=(Pack b) { return *this = *this + b; }
  /// \brief Lane-wise `*this = *this - b`.
  /// \param b the pack subtracted.
  /// \return `*this`.
  Pack& operator-=(Pack b) { return *this = *this - b; }
  friend Pack sqrt(Pack a) {
    if constexpr (lanes == 1) {
      using std::sqrt;
      return Pack(sqrt(a.r));
    } else {
      return Pack(Eigen::internal::psqrt(a.r));
    }
  }
  // Lane-wise maximum (the second operand where either is NaN, as SSE's maxpd). Kept out of the
  // API reference: Doxygen 1.9.4 lists this friend but writes no entry for it (a broken link).
  /// \cond PRIVATE
  friend Pack max(Pack a, Pack b) {
    if constexpr (lanes == 1)
      return Pack(a.r > b.r ? a.r : b.r);
    else
      return Pack(Eigen::internal::pmax(a.r, b.r));
  }
  /// \endcond
  /// \brief Sum of the lanes.
  /// \return the sum (its rounding follows Eigen's reduction order, not left to right).
  Scalar sum() const {
    if constexpr (lanes == 1)
      return r;
    else
      return Eigen::internal::predux(r);
  }
  /// \brief Largest lane.
  /// \return the largest value (NaN handling as Eigen's `predux_max`).
  Scalar max_lane() const {
    if constexpr (lanes == 1)
      return r;
    else
      return Eigen::internal::predux_max(r);
  }
  friend Pack abs(Pack a) {
    if constexpr (lanes == 1) {
      using std::abs;
      return Pack(abs(a.r));
    } else {
      return Pack(Eigen::internal::pabs(a.r));
    }
  }
};

/// \brief Calls `f(Pack<Scalar, true>(), j)` for j = begin, begin + lanes, … while a whole packet
/// fits before `end`, then `f(Pack<Scalar, false>(), j)` for each remaining j: a loop body
/// written once for both widths.
///
/// \tparam Scalar the lane type.
/// \tparam F a callable taking `(Pack<Scalar, W>, Eigen::Index j)` for both W; the pack
/// argument carries only its type (the lanes are j, j + 1, …, j + lanes − 1).
/// \param begin first index.
/// \param end one past the last index (nothing is done when `end <= begin`).
/// \param f the loop body.
template <typename Scalar, typename F>
void for_each_pack(Eigen::Index begin, Eigen::Index end, F&& f) {
  using Wide = Pack<Scalar, true>;
  Eigen::Index j = begin;
  for (; j + Wide::lanes <= end; j += Wide::lanes) f(Wide(), j);
  for (; j < end; ++j) f(Pack<Scalar, false>(), j);
}

/// \brief Lane-wise comparison result.
/// \tparam Scalar the lane type of the packs compared.
/// \tparam Wide the width of the packs compared (see Pack).
template <typename Scalar, bool Wide>
struct Mask {
  using P = Pack<Scalar, Wide>;  ///< The pack type this mask selects lanes of.
  typename P::Raw m;  ///< Packets: all bits set in the lanes that are true (unused for one lane).
  bool scalar_value = false;  ///< One lane: the result (unused for packets).
};

/// \brief a > b lane-wise (false where either is NaN).
/// \param a left operand.
/// \param b right operand.
/// \return the mask of the lanes where a > b.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
Mask<Scalar, Wide> greater(Pack<Scalar, Wide> a, Pack<Scalar, Wide> b) {
  Mask<Scalar, Wide> k;
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    k.scalar_value = a.r > b.r;
  else
    k.m = Eigen::internal::pcmp_lt(b.r, a.r);
  return k;
}

/// \brief a >= b lane-wise (false where either is NaN).
/// \param a left operand.
/// \param b right operand.
/// \return the mask of the lanes where a >= b.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
Mask<Scalar, Wide> greater_equal(Pack<Scalar, Wide> a, Pack<Scalar, Wide> b) {
  Mask<Scalar, Wide> k;
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    k.scalar_value = a.r >= b.r;
  else
    k.m = Eigen::internal::pcmp_le(b.r, a.r);
  return k;
}

/// \brief Lane-wise `k ? a : b`.
/// \param k the mask (from greater(), less(), …).
/// \param a lanes taken where `k` is true.
/// \param b lanes taken where `k` is false.
/// \return the blended pack.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
Pack<Scalar, Wide> select(Mask<Scalar, Wide> k, Pack<Scalar, Wide> a, Pack<Scalar, Wide> b) {
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    return k.scalar_value ? a : b;
  else
    return Pack<Scalar, Wide>(
        Eigen::internal::por(Eigen::internal::pand(a.r, k.m), Eigen::internal::pandnot(b.r, k.m)));
}

/// \brief Lane-wise logical and.
/// \param a first mask.
/// \param b second mask.
/// \return true in the lanes where both are true.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
Mask<Scalar, Wide> operator&&(Mask<Scalar, Wide> a, Mask<Scalar, Wide> b) {
  Mask<Scalar, Wide> k;
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    k.scalar_value = a.scalar_value && b.scalar_value;
  else
    k.m = Eigen::internal::pand(a.m, b.m);
  return k;
}

/// \brief a < b lane-wise (false where either is NaN).
/// \param a left operand.
/// \param b right operand.
/// \return the mask of the lanes where a < b.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
Mask<Scalar, Wide> less(Pack<Scalar, Wide> a, Pack<Scalar, Wide> b) {
  return greater(b, a);
}

/// \brief Lane-wise logical or.
/// \param a first mask.
/// \param b second mask.
/// \return true in the lanes where either is true.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
Mask<Scalar, Wide> operator||(Mask<Scalar, Wide> a, Mask<Scalar, Wide> b) {
  Mask<Scalar, Wide> k;
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    k.scalar_value = a.scalar_value || b.scalar_value;
  else
    k.m = Eigen::internal::por(a.m, b.m);
  return k;
}

/// \brief True when any lane is true.
/// \param k the mask.
/// \return whether at least one lane of `k` is true.
/// \tparam Scalar the lane type.
/// \tparam Wide the pack width (see Pack).
template <typename Scalar, bool Wide>
bool any(Mask<Scalar, Wide> k) {
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    return k.scalar_value;
  else
    return Eigen::internal::predux_any(k.m);
}

}  // namespace kelp::simd

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
