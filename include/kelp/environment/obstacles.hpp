/// \file
/// \brief Obstacles in the water column and on the seabed: finite cylinders (piles, risers,
/// mooring lines; vertical or inclined), boxes (a hull, a quay wall) and a height-field seabed
/// (bathymetry on a regular grid, bilinear), their contact properties, an ObstacleSet with a
/// broad phase (a uniform horizontal grid of cells), and the closest-point queries the tether
/// and the vehicles use: segment–capsule (segment–segment), point/segment–box and
/// point–height-field with its normal.
///
/// Frames and signs: world NED (x north, y east, z down) [m]. Every signed distance is the
/// separation of the query from the obstacle's surface: positive outside, negative inside. The
/// normal of a proximity is the unit vector from the obstacle towards the query point (the
/// direction a contact pushes the query).
///
/// The geometry is stored in double; the queries are templates on the query's Scalar (double or
/// float), so one ObstacleSet serves a tether of either precision. Obstacles are built at setup
/// (adding one allocates and rebuilds the broad phase); the queries allocate nothing.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

namespace kelp {
namespace environment {

/// \brief Contact law of an obstacle, in the form of the tether's seabed contact
/// (tether::TetherParameters: seabed_stiffness, seabed_damping, seabed_friction,
/// friction_velocity, seabed_damping_depth): for a tether segment of diameter d and rest length l
/// penetrating by p with approach speed w, the normal force is
/// N = max(0, (k p + c w min(1, p/p_c)) d l) and the friction −μ N v_t / max(|v_t|, v_f).
struct ContactProperties {
  /// Normal stiffness k [Pa/m] = [N/m³] per unit of projected area d·l (MoorDyn's kBot 3e6).
  double stiffness = 3e6;
  /// Normal damping c [Pa s/m] (MoorDyn's cBot 3e5), ramped in over `damping_depth`.
  double damping = 3e5;
  /// Coulomb friction coefficient μ [-] (0: frictionless).
  double friction = 0.0;
  /// Sliding speed v_f [m/s] below which friction is viscous (its regularisation).
  double friction_velocity = 0.01;
  /// Penetration p_c [m] over which the damping ramps in from zero (continuous normal force).
  double damping_depth = 1e-3;
};

/// \brief Checks contact properties; `where` names the obstacle in the message.
/// \param c Contact law to check.
/// \param where Name of the obstacle, prefixed to the message (e.g. "cylinder 'pile'").
/// \throws kelp::invalid_argument: stiffness finite > 0, damping, friction, damping_depth finite
/// ≥ 0, friction_velocity finite > 0, each at most 1e13 (friction at most 100).
inline void validate(const ContactProperties& c, const std::string& where) {
  const auto ok = [](double x, bool zero_ok, double bound) {
    return std::isfinite(x) && (zero_ok ? x >= 0.0 : x > 0.0) && x <= bound;
  };
  KELP_CHECK(ok(c.stiffness, false, 1e13),
             where + ": contact stiffness must be finite, > 0 and <= 1e13 Pa/m");
  KELP_CHECK(ok(c.damping, true, 1e13),
             where + ": contact damping must be finite, >= 0 and <= 1e13 Pa s/m");
  KELP_CHECK(ok(c.friction, true, 100.0), where + ": friction must be finite in [0, 100]");
  KELP_CHECK(ok(c.friction_velocity, false, 1e3),
             where + ": friction_velocity must be finite in (0, 1000] m/s");
  KELP_CHECK(ok(c.damping_depth, true, 1e5), where + ": damping_depth must be finite and >= 0");
}

/// \brief A finite cylinder from `from` to `to` (NED [m]) of radius `radius` [m]: a pile, a
/// riser, a mooring line, vertical or inclined. Contact treats it as a capsule (its ends
/// rounded by hemispheres of the same radius), whose distance is the segment–segment distance
/// to its axis less the radius.
struct Cylinder {
  std::string name;                                ///< for messages, logs and the replay
  Eigen::Vector3d from = Eigen::Vector3d::Zero();  ///< one end of the axis, NED [m]
  Eigen::Vector3d to = Eigen::Vector3d(0, 0, 1);   ///< the other end, NED [m]
  double radius = 0.5;                             ///< [m], > 0
  ContactProperties contact;                       ///< its contact law
};

/// \brief A box of half extents (a, b, c) [m] along its own axes, centred at `center` (NED [m])
/// and turned by roll, pitch, yaw [rad] (ZYX, Fossen 2021 eq. 2.18: R = Rz(ψ) Ry(θ) Rx(φ), body
/// to NED), as a vehicle is. A hull, a quay wall, a subsea frame.
struct Box {
  std::string name;                                               ///< for messages and the replay
  Eigen::Vector3d center = Eigen::Vector3d::Zero();               ///< NED [m]
  Eigen::Vector3d half_extents = Eigen::Vector3d::Constant(0.5);  ///< [m], each > 0
  double roll = 0.0;                                              ///< [rad]
  double pitch = 0.0;                                             ///< [rad]
  double yaw = 0.0;                                               ///< [rad]
  ContactProperties contact;                                      ///< its contact law

  /// \brief Rotation from the box's axes to NED.
  /// \return R = Rz(yaw) Ry(pitch) Rx(roll), mapping a vector in the box's axes to NED.
  Eigen::Matrix3d rotation() const {
    return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
};

/// \brief A seabed given by depths on a regular grid (bathymetry), interpolated bilinearly.
///
/// Node (i, j), i < rows along north, j < cols along east, lies at north = origin.x() + i·dn,
/// east = origin.y() + j·de and has the seabed at NED z = depth(i, j) [m] (positive down, the
/// water depth there). Outside the grid the depth of the nearest grid edge is used (as MoorDyn
/// does: MoorDyn v2.7 documentation, docs/inputs.rst, "Seafloor/Bathymetry File").
struct HeightField {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();   ///< north, east of node (0, 0) [m]
  Eigen::Vector2d spacing = Eigen::Vector2d::Ones();  ///< dn, de [m], each > 0
  int rows = 0;                                       ///< nodes along north (≥ 2)
  int cols = 0;                                       ///< nodes along east (≥ 2)
  std::vector<double> depth;  ///< rows × cols, row-major (row i = north index) [m]

  /// \brief Depth of node (i, j) [m].
  /// \param i North index, 0 ≤ i < rows (not checked).
  /// \param j East index, 0 ≤ j < cols (not checked).
  /// \return The seabed's NED z at the node [m] (positive down).
  double at(int i, int j) const {
    return depth[std::size_t(i) * std::size_t(cols) + std::size_t(j)];
  }
  /// \brief Shallowest and deepest node [m].
  /// \return (least, greatest) depth over the nodes [m]; `depth` must not be empty.
  std::pair<double, double> depth_range() const {
    const auto mm = std::minmax_element(depth.begin(), depth.end());
    return {*mm.first, *mm.second};
  }
};

/// \brief Checks a height field: rows, cols ≥ 2, rows·cols depths, all finite (depths > 0 are
/// not required: a shoal may rise above the mean sea level), spacing finite > 0, origin finite.
/// \param h Height field to check (also: at most 1e8 nodes, |depth| ≤ 1e5 m).
/// \throws kelp::invalid_argument naming the field.
inline void validate(const HeightField& h) {
  KELP_CHECK(h.rows >= 2 && h.cols >= 2, "heightfield: rows and cols must be >= 2");
  KELP_CHECK(h.rows <= 100000 && h.cols <= 100000 && double(h.rows) * double(h.cols) <= 1e8,
             "heightfield: at most 1e8 nodes");
  KELP_CHECK(h.depth.size() == std::size_t(h.rows) * std::size_t(h.cols),
             "heightfield: depth must hold rows x cols values (row-major)");
  KELP_CHECK(std::isfinite(h.origin.x()) && std::isfinite(h.origin.y()),
             "heightfield: origin must be finite");
  KELP_CHECK(std::isfinite(h.spacing.x()) && std::isfinite(h.spacing.y()) && h.spacing.x() > 0 &&
                 h.spacing.y() > 0,
             "heightfield: spacing must be finite and > 0");
  for (double d : h.depth)
    KELP_CHECK(std::isfinite(d) && std::abs(d) <= 1e5,
               "heightfield: every depth must be finite (|depth| <= 1e5 m)");
}

/// \brief Closest points between a query (a point or a segment a→b) and an obstacle.
template <typename Scalar>
struct Proximity {
  /// Signed distance of the query from the obstacle's surface [m] (negative: inside).
  Scalar distance = Scalar(std::numeric_limits<double>::infinity());
  /// Barycentric coordinate of the closest point on the query segment: a + t (b − a) (0 for a
  /// point query).
  Scalar t = Scalar(0);
  /// Closest point on the query [m].
  Vector3<Scalar> on_query = Vector3<Scalar>::Zero();
  /// Closest point on the obstacle's surface (for a capsule: on its axis) [m].
  Vector3<Scalar> on_obstacle = Vector3<Scalar>::Zero();
  /// Unit normal from the obstacle towards the query.
  Vector3<Scalar> normal = Vector3<Scalar>::UnitZ();
};

/// \brief Closest points of two segments p0→p1 and q0→q1: parameters s (on p) and t (on q) in
/// [0, 1] and the squared distance. Degenerate (zero-length) segments are points. The
/// minimisation of |p(s) − q(t)|² over the unit square: the interior stationary point when the
/// segments are not parallel, else the edges (Ericson, Real-Time Collision Detection, 2005,
/// §5.1.9, gives the same case analysis).
/// \tparam Scalar double, float or an automatic-differentiation type.
template <typename Scalar>
struct SegmentPair {
  Scalar s,       ///< parameter of the closest point on p: p0 + s (p1 − p0), in [0, 1]
      t,          ///< parameter of the closest point on q: q0 + t (q1 − q0), in [0, 1]
      distance2;  ///< squared distance between the two closest points [m²]
};
/// \brief Closest points of two segments p0→p1 and q0→q1 (see SegmentPair).
/// \tparam Scalar double, float or an automatic-differentiation type.
/// \param p0 Start of the first segment [m].
/// \param p1 End of the first segment [m] (equal to p0: a point).
/// \param q0 Start of the second segment [m].
/// \param q1 End of the second segment [m] (equal to q0: a point).
/// \return s, t and the squared distance; parallel segments give s = 0 when that is a minimum.
template <typename Scalar>
SegmentPair<Scalar> closest_segment_segment(const Vector3<Scalar>& p0, const Vector3<Scalar>& p1,
                                            const Vector3<Scalar>& q0, const Vector3<Scalar>& q1) {
  const Vector3<Scalar> d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const Scalar a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const Scalar zero(0), one(1);
  const auto clamp01 = [&](Scalar x) { return x < zero ? zero : (x > one ? one : x); };
  Scalar s(0), t(0);
  const Scalar tiny = Scalar(1e-30);
  if (a <= tiny && e <= tiny) {
    s = t = zero;
  } else if (a <= tiny) {
    s = zero;
    t = clamp01(f / e);
  } else {
    const Scalar c = d1.dot(r);
    if (e <= tiny) {
      t = zero;
      s = clamp01(-c / a);
    } else {
      const Scalar b = d1.dot(d2), denom = a * e - b * b;
      // Parallel segments (denominator 0): any s; take s = 0 and let the clamps below settle t.
      s = denom > Scalar(1e-12) * a * e ? clamp01((b * f - c * e) / denom) : zero;
      t = (b * s + f) / e;
      if (t < zero) {
        t = zero;
        s = clamp01(-c / a);
      } else if (t > one) {
        t = one;
        s = clamp01((b - c) / a);
      }
    }
  }
  const Vector3<Scalar> dp = (p0 + s * d1) - (q0 + t * d2);
  return {s, t, dp.squaredNorm()};
}

/// \brief Segment a→b against a cylinder taken as a capsule: signed distance from the capsule's
/// surface, the closest point on the segment (t) and on the axis, the normal from the axis.
/// When the segment crosses the axis the normal is any unit vector perpendicular to the axis
/// (the contact force then cannot be resolved: keep penetrations below the radius).
/// \tparam Scalar Scalar of the query (double or float).
/// \param a Start of the segment, NED [m].
/// \param b End of the segment, NED [m] (equal to a: a point).
/// \param c The cylinder.
/// \return Proximity: distance negative inside the capsule; on_obstacle is the closest point on
/// the axis (not on the surface).
template <typename Scalar>
Proximity<Scalar> segment_capsule(const Vector3<Scalar>& a, const Vector3<Scalar>& b,
                                  const Cylinder& c) {
  using std::sqrt;
  const Vector3<Scalar> q0 = c.from.cast<Scalar>(), q1 = c.to.cast<Scalar>();
  const SegmentPair<Scalar> sp = closest_segment_segment(a, b, q0, q1);
  Proximity<Scalar> out;
  out.t = sp.s;
  out.on_query = a + sp.s * (b - a);
  out.on_obstacle = q0 + sp.t * (q1 - q0);
  const Scalar dist = sqrt(sp.distance2);
  const Vector3<Scalar> r = out.on_query - out.on_obstacle;
  if (dist > Scalar(0)) {
    out.normal = r / dist;
  } else {
    const Vector3<Scalar> axis = q1 - q0;
    Vector3<Scalar> any = axis.cross(Vector3<Scalar>::UnitX());
    if (any.squaredNorm() < Scalar(1e-12) * axis.squaredNorm())
      any = axis.cross(Vector3<Scalar>::UnitY());
    out.normal = any.normalized();
  }
  out.distance = dist - Scalar(c.radius);
  return out;
}

/// \brief Point p against a cylinder taken as a capsule (see segment_capsule).
/// \tparam Scalar Scalar of the query (double or float).
/// \param p The point, NED [m].
/// \param c The cylinder.
/// \return Proximity with t = 0 and on_query = p.
template <typename Scalar>
Proximity<Scalar> point_capsule(const Vector3<Scalar>& p, const Cylinder& c) {
  return segment_capsule<Scalar>(p, p, c);
}

namespace detail {
/// Signed distance and closest surface point of a point `l` in a box's own frame (half extents
/// h): outside, the clamp; inside, the nearest face.
template <typename Scalar>
Scalar box_local(const Vector3<Scalar>& l, const Vector3<Scalar>& h, Vector3<Scalar>& surface,
                 Vector3<Scalar>& normal) {
  using std::abs;
  using std::sqrt;
  Vector3<Scalar> clamped;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    clamped(k) = l(k) < -h(k) ? -h(k) : (l(k) > h(k) ? h(k) : l(k));
    if (clamped(k) != l(k)) inside = false;
  }
  if (!inside) {
    const Vector3<Scalar> r = l - clamped;
    const Scalar d = sqrt(r.squaredNorm());
    surface = clamped;
    normal = r / d;
    return d;
  }
  // Inside: the face with the least depth h_k − |l_k|.
  int best = 0;
  Scalar depth = h(0) - abs(l(0));
  for (int k = 1; k < 3; ++k) {
    const Scalar dk = h(k) - abs(l(k));
    if (dk < depth) {
      depth = dk;
      best = k;
    }
  }
  const Scalar sign = l(best) >= Scalar(0) ? Scalar(1) : Scalar(-1);
  surface = l;
  surface(best) = sign * h(best);
  normal = Vector3<Scalar>::Zero();
  normal(best) = sign;
  return -depth;
}
}  // namespace detail

/// \brief Point p against a box: signed distance, closest surface point, outward normal
/// (inside: towards the nearest face).
/// \tparam Scalar Scalar of the query (double or float).
/// \param p The point, NED [m].
/// \param box The box (sharp edges: no rounding).
/// \return Proximity with t = 0, on_query = p, on_obstacle on the box's surface [m] and the
/// normal in NED.
template <typename Scalar>
Proximity<Scalar> point_box(const Vector3<Scalar>& p, const Box& box) {
  const Matrix3<Scalar> R = box.rotation().cast<Scalar>();
  const Vector3<Scalar> c = box.center.cast<Scalar>(), h = box.half_extents.cast<Scalar>();
  const Vector3<Scalar> l = R.transpose() * (p - c);
  Vector3<Scalar> s, n;
  Proximity<Scalar> out;
  out.distance = detail::box_local(l, h, s, n);
  out.on_query = p;
  out.on_obstacle = c + R * s;
  out.normal = R * n;
  return out;
}

/// \brief Segment a→b against a box: the point of the segment with the least signed distance
/// (its parameter t, that point, the closest surface point and the normal).
///
/// The signed distance of a convex body is convex along the segment; in the box's frame it is
/// smooth between the parameters where a coordinate crosses −h_k, 0 or +h_k. Between two such
/// breakpoints the squared outside distance is a quadratic in t (its minimiser is a candidate),
/// and the inside distance the least of three linear functions (their crossings are
/// candidates); the least over all candidates and breakpoints is the exact minimum.
///
/// With `rounding` r > 0 the box's edges and corners are rounded by r (the distance to the box
/// shrunk by r on every side, less r): the same faces, but a normal that turns continuously
/// round an edge, also for a segment a little inside (up to r deep), which a contact law needs.
/// \tparam Scalar Scalar of the query (double or float).
/// \param a Start of the segment, NED [m].
/// \param b End of the segment, NED [m] (equal to a: a point).
/// \param box The box.
/// \param rounding Edge rounding r [m], 0 ≤ r < least half extent (ObstacleSet::box_rounding
/// gives the one contact uses); 0: sharp edges.
/// \return Proximity of the point of the segment with the least signed distance, less r.
template <typename Scalar>
Proximity<Scalar> segment_box(const Vector3<Scalar>& a, const Vector3<Scalar>& b, const Box& box,
                              double rounding = 0.0) {
  using std::abs;
  const Matrix3<Scalar> R = box.rotation().cast<Scalar>();
  const Vector3<Scalar> c = box.center.cast<Scalar>(),
                        h = (box.half_extents.array() - rounding).matrix().cast<Scalar>();
  const Vector3<Scalar> o = R.transpose() * (a - c), d = R.transpose() * (b - a);
  const Scalar zero(0), one(1);
  // Breakpoints: 0, 1 and the crossings of the planes −h, 0, +h of each axis (at most 11).
  Scalar bp[11];
  int nb = 0;
  bp[nb++] = zero;
  bp[nb++] = one;
  for (int k = 0; k < 3; ++k) {
    if (d(k) == zero) continue;
    for (Scalar plane : {-h(k), zero, h(k)}) {
      const Scalar t = (plane - o(k)) / d(k);
      if (t > zero && t < one) bp[nb++] = t;
    }
  }
  for (int i = 1; i < nb; ++i)  // insertion sort of at most 11 values
    for (int j = i; j > 0 && bp[j] < bp[j - 1]; --j) std::swap(bp[j], bp[j - 1]);
  Scalar cand[64];
  int nc = 0;
  for (int i = 0; i < nb; ++i) cand[nc++] = bp[i];
  for (int i = 0; i + 1 < nb; ++i) {
    const Scalar t0 = bp[i], t1 = bp[i + 1];
    if (!(t1 > t0)) continue;
    const Scalar tm = Scalar(0.5) * (t0 + t1);
    const Vector3<Scalar> lm = o + tm * d;
    bool outside = false;
    Scalar qa(0), qb(0);
    for (int k = 0; k < 3; ++k) {
      if (lm(k) > h(k) || lm(k) < -h(k)) {
        outside = true;
        const Scalar off = o(k) - (lm(k) > zero ? h(k) : -h(k));
        qa += d(k) * d(k);
        qb += d(k) * off;
      }
    }
    if (outside) {
      if (qa > zero) {
        const Scalar t = -qb / qa;
        if (t > t0 && t < t1) cand[nc++] = t;
      }
    } else {
      // g_k(t) = h_k − s_k (o_k + t d_k), s_k the sign in the interval: crossings g_j = g_k.
      Scalar g0[3], g1[3];
      for (int k = 0; k < 3; ++k) {
        const Scalar s = lm(k) >= zero ? one : -one;
        g0[k] = h(k) - s * o(k);
        g1[k] = -s * d(k);
      }
      for (int j = 0; j < 3; ++j)
        for (int k = j + 1; k < 3; ++k) {
          const Scalar den = g1[j] - g1[k];
          if (den == zero) continue;
          const Scalar t = (g0[k] - g0[j]) / den;
          if (t > t0 && t < t1) cand[nc++] = t;
        }
    }
  }
  Proximity<Scalar> best;
  Vector3<Scalar> s, n;
  for (int i = 0; i < nc; ++i) {
    const Vector3<Scalar> l = o + cand[i] * d;
    const Scalar dist = detail::box_local(l, h, s, n);
    if (dist < best.distance) {
      best.distance = dist;
      best.t = cand[i];
      best.on_query = a + cand[i] * (b - a);
      best.on_obstacle = c + R * (s + Scalar(rounding) * n);
      best.normal = R * n;
    }
  }
  best.distance -= Scalar(rounding);
  return best;
}

/// \brief The seabed under a horizontal point: its depth h (NED z [m]), the slopes ∂h/∂north,
/// ∂h/∂east and the unit normal pointing up into the water, (h_n, h_e, −1)/√(1 + h_n² + h_e²).
/// Bilinear in the cell that holds the point; the edge depth outside the grid (slope 0 across
/// the edge).
/// \tparam Scalar double, float or an automatic-differentiation type.
template <typename Scalar>
struct SeabedSample {
  Scalar depth;            ///< seabed depth h, NED z [m] (positive down)
  Scalar slope_north,      ///< ∂h/∂north [-]
      slope_east;          ///< ∂h/∂east [-]
  Vector3<Scalar> normal;  ///< unit normal, NED, pointing up into the water (z < 0)
};
/// \brief Samples a height-field seabed at a horizontal point (see SeabedSample).
/// \tparam Scalar double, float or an automatic-differentiation type.
/// \param hf The height field (valid: see validate(const HeightField&)).
/// \param north North coordinate of the point [m].
/// \param east East coordinate of the point [m].
/// \return Depth, slopes and normal there (bilinear; edge depth and zero slope outside the grid).
template <typename Scalar>
SeabedSample<Scalar> sample_heightfield(const HeightField& hf, const Scalar& north,
                                        const Scalar& east) {
  using std::floor;
  using std::sqrt;
  const Scalar dn = Scalar(hf.spacing.x()), de = Scalar(hf.spacing.y());
  Scalar u = (north - Scalar(hf.origin.x())) / dn, v = (east - Scalar(hf.origin.y())) / de;
  bool clamp_u = false, clamp_v = false;
  const Scalar umax = Scalar(hf.rows - 1), vmax = Scalar(hf.cols - 1);
  if (!(u > Scalar(0))) u = Scalar(0), clamp_u = true;
  if (!(u < umax)) u = umax, clamp_u = true;
  if (!(v > Scalar(0))) v = Scalar(0), clamp_v = true;
  if (!(v < vmax)) v = vmax, clamp_v = true;
  int i = int(floor(value_of(u))), j = int(floor(value_of(v)));
  if (i > hf.rows - 2) i = hf.rows - 2;
  if (j > hf.cols - 2) j = hf.cols - 2;
  const Scalar fu = u - Scalar(i), fv = v - Scalar(j);
  const Scalar h00 = Scalar(hf.at(i, j)), h01 = Scalar(hf.at(i, j + 1)),
               h10 = Scalar(hf.at(i + 1, j)), h11 = Scalar(hf.at(i + 1, j + 1));
  SeabedSample<Scalar> s;
  const Scalar one(1);
  s.depth = (one - fu) * ((one - fv) * h00 + fv * h01) + fu * ((one - fv) * h10 + fv * h11);
  s.slope_north = clamp_u ? Scalar(0) : (((one - fv) * (h10 - h00) + fv * (h11 - h01)) / dn);
  s.slope_east = clamp_v ? Scalar(0) : (((one - fu) * (h01 - h00) + fu * (h11 - h10)) / de);
  const Scalar inv = one / sqrt(one + s.slope_north * s.slope_north + s.slope_east * s.slope_east);
  s.normal = Vector3<Scalar>(s.slope_north * inv, s.slope_east * inv, -inv);
  return s;
}

/// \brief Point p against a height-field seabed: signed distance measured along the local
/// normal, (h − z)/√(1 + |∇h|²) (positive above the seabed, the first-order distance to the
/// local plane), the point straight below or above on the seabed, and the normal up into the water.
/// \tparam Scalar Scalar of the query (double or float).
/// \param p The point, NED [m].
/// \param hf The height field.
/// \return Proximity with t = 0, on_query = p, on_obstacle = (p.x, p.y, h).
template <typename Scalar>
Proximity<Scalar> point_heightfield(const Vector3<Scalar>& p, const HeightField& hf) {
  const SeabedSample<Scalar> s = sample_heightfield<Scalar>(hf, p.x(), p.y());
  Proximity<Scalar> out;
  out.on_query = p;
  out.on_obstacle = Vector3<Scalar>(p.x(), p.y(), s.depth);
  out.normal = s.normal;
  out.distance = (s.depth - p.z()) * (-s.normal.z());
  return out;
}

/// \brief Which obstacle of an ObstacleSet: a cylinder or a box, by index.
struct ObstacleRef {
  /// \brief The kind of obstacle referred to.
  enum Kind : std::uint8_t {
    cylinder = 0,  ///< an entry of ObstacleSet::cylinders()
    box = 1        ///< an entry of ObstacleSet::boxes()
  };
  Kind kind;  ///< cylinder or box
  int index;  ///< index in ObstacleSet::cylinders() or ObstacleSet::boxes(), by kind
};

/// \brief Axis-aligned bounding box (NED [m]).
struct Aabb {
  /// Least corner, NED [m] (+∞: the empty box).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  /// Greatest corner, NED [m] (−∞: the empty box).
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  /// \brief True when the two boxes overlap (touching counts).
  /// \param o The other box.
  /// \return True when the boxes share a point on every axis (never for an empty box).
  bool overlaps(const Aabb& o) const {
    return lo.x() <= o.hi.x() && o.lo.x() <= hi.x() && lo.y() <= o.hi.y() && o.lo.y() <= hi.y() &&
           lo.z() <= o.hi.z() && o.lo.z() <= hi.z();
  }
};

/// \brief The obstacles of an environment: cylinders, boxes and an optional height-field seabed,
/// with a broad phase.
///
/// Broad phase: a uniform grid of cells over the horizontal (north, east) extent of the
/// obstacles' bounding boxes, about two cells per obstacle along each side (at most 128 × 128);
/// each cell lists the obstacles whose box overlaps it. A query box visits only the cells it
/// overlaps and, in them, tests the listed obstacles' 3-D boxes, reporting each once (in the
/// first cell both boxes share). Its cost depends on the obstacles near the query, not on the
/// far ones. Built when obstacles are added (allocates); queries allocate nothing.
class ObstacleSet {
 public:
  /// \brief Adds a cylinder and rebuilds the broad phase (allocates).
  /// \param c The cylinder (copied).
  /// \return *this, for chaining.
  /// \throws kelp::invalid_argument (ends finite and distinct, radius finite in (0, 1e4] m,
  /// contact properties valid; names the cylinder).
  ObstacleSet& add(const Cylinder& c) {
    const std::string where = "cylinder '" + c.name + "'";
    KELP_CHECK(c.from.allFinite() && c.to.allFinite(), where + ": from and to must be finite");
    KELP_CHECK((c.to - c.from).norm() > 0.0, where + ": from and to must differ");
    KELP_CHECK(std::isfinite(c.radius) && c.radius > 0.0 && c.radius <= 1e4,
               where + ": radius must be finite in (0, 1e4] m");
    validate(c.contact, where);
    cylinders_.push_back(c);
    rebuild();
    return *this;
  }
  /// \brief Adds a box and rebuilds the broad phase (allocates).
  /// \param b The box (copied).
  /// \return *this, for chaining.
  /// \throws kelp::invalid_argument (centre and angles finite, half extents finite in
  /// (0, 1e5] m, contact properties valid; names the box).
  ObstacleSet& add(const Box& b) {
    const std::string where = "box '" + b.name + "'";
    KELP_CHECK(b.center.allFinite(), where + ": center must be finite");
    KELP_CHECK(b.half_extents.allFinite() && (b.half_extents.array() > 0.0).all() &&
                   (b.half_extents.array() <= 1e5).all(),
               where + ": half_extents must be finite in (0, 1e5] m");
    KELP_CHECK(std::isfinite(b.roll) && std::isfinite(b.pitch) && std::isfinite(b.yaw),
               where + ": roll, pitch, yaw must be finite");
    validate(b.contact, where);
    boxes_.push_back(b);
    rebuild();
    return *this;
  }
  /// \brief Sets (replaces) the height-field seabed.
  /// \param h The height field (copied).
  /// \return *this, for chaining.
  /// \throws kelp::invalid_argument (see validate(const HeightField&)).
  ObstacleSet& set_seabed(const HeightField& h) {
    validate(h);
    seabed_ = h;
    has_seabed_ = true;
    const auto r = h.depth_range();
    seabed_shallowest_ = r.first;
    return *this;
  }
  /// \brief Removes the height-field seabed.
  void clear_seabed() {
    seabed_ = HeightField{};
    has_seabed_ = false;
  }

  /// \brief The cylinders.
  /// \return The cylinders in the order added (the index is ObstacleRef::index).
  const std::vector<Cylinder>& cylinders() const { return cylinders_; }
  /// \brief The boxes.
  /// \return The boxes in the order added (the index is ObstacleRef::index).
  const std::vector<Box>& boxes() const { return boxes_; }
  /// \brief The height-field seabed, or null.
  /// \return A pointer valid until the seabed is set or cleared, or nullptr without one.
  const HeightField* seabed() const { return has_seabed_ ? &seabed_ : nullptr; }
  /// \brief Shallowest depth of the height field [m] (+∞ without one): a point above it cannot
  /// touch the seabed.
  /// \return The least node depth [m], or +∞.
  double seabed_shallowest() const {
    return has_seabed_ ? seabed_shallowest_ : std::numeric_limits<double>::infinity();
  }
  /// \brief Number of cylinders and boxes.
  /// \return cylinders().size() + boxes().size() (the height field is not counted).
  int size() const { return int(cylinders_.size() + boxes_.size()); }
  /// \brief True when there are no cylinders, no boxes and no height field.
  /// \return True when nothing can be touched.
  bool empty() const { return size() == 0 && !has_seabed_; }
  /// \brief Bounding box of all cylinders and boxes (empty box when none).
  /// \return The union of the obstacles' boxes, NED [m] (the height field is not included).
  const Aabb& bounds() const { return bounds_; }
  /// \brief Bounding box of one obstacle.
  /// \param r The obstacle (index in range, not checked).
  /// \return Its axis-aligned box, NED [m] (a cylinder's includes its radius).
  const Aabb& bounds(ObstacleRef r) const { return aabb_[std::size_t(flat(r))]; }
  /// \brief Contact law of one obstacle.
  /// \param r The obstacle (index in range, not checked).
  /// \return Its contact properties.
  const ContactProperties& contact(ObstacleRef r) const {
    return r.kind == ObstacleRef::cylinder ? cylinders_[std::size_t(r.index)].contact
                                           : boxes_[std::size_t(r.index)].contact;
  }
  /// \brief Name of one obstacle.
  /// \param r The obstacle (index in range, not checked).
  /// \return Its name (may be empty).
  const std::string& name(ObstacleRef r) const {
    return r.kind == ObstacleRef::cylinder ? cylinders_[std::size_t(r.index)].name
                                           : boxes_[std::size_t(r.index)].name;
  }

  /// \brief Calls `visit(ObstacleRef)` once for every cylinder or box whose bounding box
  /// overlaps `q` (broad phase; the caller then asks for the exact proximity). No allocation.
  /// \tparam Visit A callable taking an ObstacleRef.
  /// \param q Query box, NED [m].
  /// \param visit Called once per obstacle near `q`, in no particular order.
  template <typename Visit>
  void for_each_near(const Aabb& q, Visit&& visit) const {
    if (aabb_.empty() || !bounds_.overlaps(q)) return;
    const int cx0 = cell_x(q.lo.x()), cx1 = cell_x(q.hi.x());
    const int cy0 = cell_y(q.lo.y()), cy1 = cell_y(q.hi.y());
    for (int cx = cx0; cx <= cx1; ++cx)
      for (int cy = cy0; cy <= cy1; ++cy) {
        const int cell = cx * ny_ + cy;
        for (int k = cell_start_[std::size_t(cell)]; k < cell_start_[std::size_t(cell) + 1]; ++k) {
          const int o = cell_items_[std::size_t(k)];
          const Aabb& box = aabb_[std::size_t(o)];
          if (!box.overlaps(q)) continue;
          // Report in the first cell both boxes share only.
          if (cx != std::max(cx0, cell_x(box.lo.x())) || cy != std::max(cy0, cell_y(box.lo.y())))
            continue;
          visit(ref_of(o));
        }
      }
  }

  /// \brief Proximity of the segment a→b (a point when a = b) to one obstacle, as contact sees
  /// it: a cylinder as a capsule, a box with its edges rounded by box_rounding().
  /// \tparam Scalar Scalar of the query (double or float).
  /// \param r The obstacle (index in range, not checked).
  /// \param a Start of the segment, NED [m].
  /// \param b End of the segment, NED [m].
  /// \return See segment_capsule and segment_box.
  template <typename Scalar>
  Proximity<Scalar> proximity(ObstacleRef r, const Vector3<Scalar>& a,
                              const Vector3<Scalar>& b) const {
    if (r.kind == ObstacleRef::cylinder)
      return segment_capsule<Scalar>(a, b, cylinders_[std::size_t(r.index)]);
    const Box& box = boxes_[std::size_t(r.index)];
    return segment_box<Scalar>(a, b, box, box_rounding(box));
  }
  /// \brief Rounding of a box's edges for contact [m]: min(5 cm, ¼ of its least half extent).
  /// A sharp edge turns the contact normal abruptly from one face to the next as a line slides
  /// over it, a force that jumps and that Newton's method cannot converge on; rounded, the normal
  /// turns over the rounding as the line wraps the edge.
  /// \param box The box.
  /// \return The rounding radius [m].
  static double box_rounding(const Box& box) {
    return std::min(0.05, 0.25 * box.half_extents.minCoeff());
  }

 private:
  int flat(ObstacleRef r) const {
    return r.kind == ObstacleRef::cylinder ? r.index : int(cylinders_.size()) + r.index;
  }
  ObstacleRef ref_of(int o) const {
    const int nc = int(cylinders_.size());
    return o < nc ? ObstacleRef{ObstacleRef::cylinder, o} : ObstacleRef{ObstacleRef::box, o - nc};
  }
  int cell_x(double x) const {
    const double f = (x - bounds_.lo.x()) * inv_cell_.x();
    return f <= 0 ? 0 : (f >= nx_ - 1 ? nx_ - 1 : int(f));
  }
  int cell_y(double y) const {
    const double f = (y - bounds_.lo.y()) * inv_cell_.y();
    return f <= 0 ? 0 : (f >= ny_ - 1 ? ny_ - 1 : int(f));
  }
  void rebuild() {
    aabb_.clear();
    bounds_ = Aabb{};
    for (const Cylinder& c : cylinders_) {
      Aabb b;
      b.lo = c.from.cwiseMin(c.to).array() - c.radius;
      b.hi = c.from.cwiseMax(c.to).array() + c.radius;
      aabb_.push_back(b);
    }
    for (const Box& x : boxes_) {
      const Eigen::Vector3d e = x.rotation().cwiseAbs() * x.half_extents;
      Aabb b;
      b.lo = x.center - e;
      b.hi = x.center + e;
      aabb_.push_back(b);
    }
    for (const Aabb& b : aabb_) {
      bounds_.lo = bounds_.lo.cwiseMin(b.lo);
      bounds_.hi = bounds_.hi.cwiseMax(b.hi);
    }
    const int n = int(aabb_.size());
    int side = 1;
    while (side * side < 4 * n && side < 128) side *= 2;
    nx_ = ny_ = side;
    const Eigen::Vector3d ext = bounds_.hi - bounds_.lo;
    inv_cell_ =
        Eigen::Vector2d(ext.x() > 0 ? nx_ / ext.x() : 0.0, ext.y() > 0 ? ny_ / ext.y() : 0.0);
    cell_start_.assign(std::size_t(nx_ * ny_ + 1), 0);
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
      for (int o = 0; o < n; ++o) {
        const Aabb& b = aabb_[std::size_t(o)];
        for (int cx = cell_x(b.lo.x()); cx <= cell_x(b.hi.x()); ++cx)
          for (int cy = cell_y(b.lo.y()); cy <= cell_y(b.hi.y()); ++cy) {
            const std::size_t cell = std::size_t(cx * ny_ + cy);
            if (pass == 0)
              ++cell_start_[cell + 1];
            else
              cell_items_[std::size_t(fill[cell]++)] = o;
          }
      }
      if (pass == 0) {
        for (std::size_t k = 1; k < cell_start_.size(); ++k) cell_start_[k] += cell_start_[k - 1];
        cell_items_.assign(std::size_t(cell_start_.back()), 0);
      }
    }
  }

  std::vector<Cylinder> cylinders_;
  std::vector<Box> boxes_;
  HeightField seabed_;
  bool has_seabed_ = false;
  double seabed_shallowest_ = std::numeric_limits<double>::infinity();
  std::vector<Aabb> aabb_;  // cylinders then boxes
  Aabb bounds_;
  int nx_ = 1, ny_ = 1;
  Eigen::Vector2d inv_cell_ = Eigen::Vector2d::Zero();
  std::vector<int> cell_start_, cell_items_;
};

}  // namespace environment
}  // namespace kelp
