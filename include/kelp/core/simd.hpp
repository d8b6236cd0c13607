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

/// \brief `Lanes` values of `Scalar` processed together: the widest Eigen packet of at most 32
/// bytes when `Wide`, a plain scalar otherwise (the same code then handles remainders and odd
/// cases).
template <typename Scalar, bool Wide>
struct Pack {
  using Raw = typename detail::RawPack<Scalar, Wide && vectorized<Scalar>>::type;
  static constexpr int lanes = Eigen::internal::unpacket_traits<Raw>::size;
  Raw r;

  Pack() = default;
  explicit Pack(Raw raw) : r(raw) {}
  /// All lanes set to `s`.
  static Pack all(Scalar s) { return Pack(Eigen::internal::pset1<Raw>(s)); }
  /// Lanes from `p[0], p[stride], p[2 stride], …`.
  static Pack gather(const Scalar* p, Eigen::Index stride) {
    if constexpr (lanes == 1)
      return Pack(*p);
    else
      return Pack(Eigen::internal::pgather<Scalar, Raw>(p, stride));
  }
  /// Lanes from `p[0], p[1], …` (no alignment needed).
  static Pack load(const Scalar* p) {
    if constexpr (lanes == 1)
      return Pack(*p);
    else
      return Pack(Eigen::internal::ploadu<Raw>(p));
  }
  /// Stores the lanes to `p[0], p[stride], …`.
  void scatter(Scalar* p, Eigen::Index stride) const {
    if constexpr (lanes == 1)
      *p = r;
    else
      Eigen::internal::pscatter<Scalar, Raw>(p, r, stride);
  }
  /// Stores the lanes to `p[0], p[1], …` (no alignment needed).
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
  Pack& operator+=(Pack b) { return *this = *this + b; }
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
  /// Sum of the lanes.
  Scalar sum() const {
    if constexpr (lanes == 1)
      return r;
    else
      return Eigen::internal::predux(r);
  }
  /// Largest lane.
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
template <typename Scalar, typename F>
void for_each_pack(Eigen::Index begin, Eigen::Index end, F&& f) {
  using Wide = Pack<Scalar, true>;
  Eigen::Index j = begin;
  for (; j + Wide::lanes <= end; j += Wide::lanes) f(Wide(), j);
  for (; j < end; ++j) f(Pack<Scalar, false>(), j);
}

/// \brief Lane-wise comparison result.
template <typename Scalar, bool Wide>
struct Mask {
  using P = Pack<Scalar, Wide>;
  typename P::Raw m;  // all bits set where true (packets), or 1/0 (scalar)
  bool scalar_value = false;
};

/// \brief a > b lane-wise (false where either is NaN).
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
template <typename Scalar, bool Wide>
Pack<Scalar, Wide> select(Mask<Scalar, Wide> k, Pack<Scalar, Wide> a, Pack<Scalar, Wide> b) {
  if constexpr (Pack<Scalar, Wide>::lanes == 1)
    return k.scalar_value ? a : b;
  else
    return Pack<Scalar, Wide>(
        Eigen::internal::por(Eigen::internal::pand(a.r, k.m), Eigen::internal::pandnot(b.r, k.m)));
}

/// \brief Lane-wise logical and.
/// \param a, b Masks of the same pack type.
/// \return A mask true in the lanes where both are true.
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
template <typename Scalar, bool Wide>
Mask<Scalar, Wide> less(Pack<Scalar, Wide> a, Pack<Scalar, Wide> b) {
  return greater(b, a);
}

/// \brief Lane-wise logical or.
/// \param a, b Masks of the same pack type.
/// \return A mask true in the lanes where either is true.
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
