/// \file
/// \brief Contact of a vehicle's hull with the seabed (flat or a height field) and with the
/// environment's obstacles (cylinders, boxes): a penalty normal force with damping and a
/// regularised Coulomb friction, summed into one body wrench that system::step adds to the
/// vehicle's external wrench at every RK4 stage (docs/entanglement.md, "Vehicle contact").
///
/// The hull is a box in the body frame (`HullContact`). Contacts:
/// - seabed (flat: Environment::seabed_depth(); height field: ObstacleSet::seabed()): each of
///   the box's 8 corners below the seabed, penetration p along the seabed's normal;
/// - cylinders (capsules): the cylinder's axis within reach of the hull, in 4 pieces, each
///   against the hull box (environment::segment_box), p = radius − distance, at the closest
///   point of the hull (a pile along a face loads the face along its length, not at one end);
/// - boxes: each hull corner inside the obstacle box, and each obstacle-box corner inside the
///   hull box (force on the hull reversed).
/// Per contact point (body point r, NED velocity v_p = R(v + ω × r), unit normal n pushing the
/// hull out): N = max(0, k p + c w min(1, p/p_c)) with w = −v_p·n the approach speed (the
/// damping ramps in over p_c so the force is continuous at touchdown, as the tether's seabed
/// contact does), and friction F = −μ N v_t / max(|v_t|, v_f), v_t the tangential part of v_p
/// (Coulomb's law regularised to viscous below v_f). The obstacles are fixed.
///
/// Stiffness: the step is explicit RK4 at the system's dt; with k per corner and four corners on
/// the seabed, the contact's frequency √(4k/(m + m_a)) must stay well below 2.8/dt (RK4's
/// stability limit for an oscillator): the defaults (k = 2e4 N/m, c = 400 N s/m per point) give
/// 49 rad/s for the BlueROV2 (0.5/dt at 10 ms, damping ratio ≈ 0.5) and a resting penetration of
/// 0.15 mm under 12 N.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp::system {

/// \brief A vehicle's hull as a box for contact, and its contact law.
/// \tparam Scalar double or float.
template <typename Scalar>
struct HullContact {
  /// Box centre, body frame relative to the CO [m].
  Vector3<Scalar> center = Vector3<Scalar>::Zero();
  /// Half extents along body x, y, z [m], each > 0.
  Vector3<Scalar> half_extents = Vector3<Scalar>(Scalar(0.25), Scalar(0.25), Scalar(0.125));
  /// Normal stiffness per contact point [N/m].
  Scalar stiffness = Scalar(2e4);
  /// Normal damping per contact point [N s/m] (ramped in over damping_depth).
  Scalar damping = Scalar(400);
  /// Penetration over which the damping ramps in [m].
  Scalar damping_depth = Scalar(1e-3);
  /// Coulomb friction coefficient on the seabed (flat and height field) [-]; against an
  /// obstacle the obstacle's own ContactProperties::friction is used.
  Scalar seabed_friction = Scalar(0.5);
  /// Speed below which friction is viscous [m/s] (> 0).
  Scalar friction_velocity = Scalar(0.01);
};

/// \brief Checks hull contact parameters. \throws kelp::invalid_argument naming the field.
/// \param h the hull box [m] and contact law.
template <typename Scalar>
void validate(const HullContact<Scalar>& h) {
  check_all_finite(h.center, "hull.center");
  KELP_CHECK(h.half_extents.allFinite() && (h.half_extents.array() > Scalar(0)).all(),
             "hull.half_extents must be finite and > 0");
  KELP_CHECK(std::isfinite(double(value_of(h.stiffness))) && h.stiffness > Scalar(0),
             "hull.stiffness must be finite and > 0");
  KELP_CHECK(std::isfinite(double(value_of(h.damping))) && h.damping >= Scalar(0),
             "hull.damping must be finite and >= 0");
  KELP_CHECK(std::isfinite(double(value_of(h.damping_depth))) && h.damping_depth >= Scalar(0),
             "hull.damping_depth must be finite and >= 0");
  KELP_CHECK(std::isfinite(double(value_of(h.seabed_friction))) && h.seabed_friction >= Scalar(0),
             "hull.seabed_friction must be finite and >= 0");
  KELP_CHECK(
      std::isfinite(double(value_of(h.friction_velocity))) && h.friction_velocity > Scalar(0),
      "hull.friction_velocity must be finite and > 0");
}

/// \brief The BlueROV2 Heavy's hull: a box 457 × 575 × 254 mm (length × width × height, Blue
/// Robotics, "BlueROV2 Heavy Configuration Retrofit Kit" / BlueROV2 technical details: length
/// 457 mm, width 575 mm with the heavy configuration's outboard vertical thrusters, height
/// 254 mm), centred on the CO (assumed: kelp's preset puts the CG at the CO and the CB 1 cm above).
/// \return the hull box (body frame, [m]) and kelp's default contact law.
template <typename Scalar>
HullContact<Scalar> bluerov2_heavy_hull() {
  HullContact<Scalar> h;
  h.half_extents = Vector3<Scalar>(Scalar(0.2285), Scalar(0.2875), Scalar(0.127));
  return h;
}

/// \brief The BlueBoat's hull: the envelope box of its two hulls, 1.20 × 1.00 m (Blue Robotics
/// product data, as in vehicle::blueboat), 0.20 m keel to deck (vehicle::blueboat's hull_height),
/// its keel at the draft 0.077 m below the CO on the waterline (∇/A_wp, vehicle::blueboat): centre
/// 0.023 m above the CO.
/// \return the hull box (body frame, [m]) and kelp's default contact law.
template <typename Scalar>
HullContact<Scalar> blueboat_hull() {
  HullContact<Scalar> h;
  h.half_extents = Vector3<Scalar>(Scalar(0.60), Scalar(0.50), Scalar(0.10));
  h.center = Vector3<Scalar>(Scalar(0), Scalar(0), Scalar(-0.023));
  return h;
}

/// \brief The contact load on a hull.
template <typename Scalar>
struct HullContactLoad {
  Vector6<Scalar> wrench = Vector6<Scalar>::Zero();  ///< body axes about the CO [N, N m]
  Vector3<Scalar> force = Vector3<Scalar>::Zero();   ///< total force, NED [N]
  int points = 0;                                    ///< contact points in touch
};

namespace detail {

/// Adds the force of one contact point: body point `r` (relative to the CO) at penetration `p`
/// along the NED unit normal `n` (pushing the hull out), friction coefficient `mu`.
template <typename Scalar>
void add_hull_point(const HullContact<Scalar>& hull, const vehicle::VehicleState<Scalar>& x,
                    const Matrix3<Scalar>& R, const Vector3<Scalar>& r, Scalar p,
                    const Vector3<Scalar>& n, Scalar mu, HullContactLoad<Scalar>& load) {
  using std::sqrt;
  if (!(p > Scalar(0))) return;
  const Vector3<Scalar> vb = x.nu.template head<3>() + x.nu.template tail<3>().cross(r);
  const Vector3<Scalar> v = R * vb;
  const Scalar w = -v.dot(n);
  const Scalar ramp =
      hull.damping_depth > Scalar(0) && p < hull.damping_depth ? p / hull.damping_depth : Scalar(1);
  const Scalar normal = hull.stiffness * p + hull.damping * w * ramp;
  if (!(normal > Scalar(0))) return;
  Vector3<Scalar> f = normal * n;
  if (mu > Scalar(0)) {
    const Vector3<Scalar> vt = v - v.dot(n) * n;
    const Scalar s = sqrt(vt.squaredNorm());
    const Scalar vf = hull.friction_velocity;
    f -= (mu * normal / (s > vf ? s : vf)) * vt;
  }
  const Vector3<Scalar> fb = R.transpose() * f;
  load.wrench.template head<3>() += fb;
  load.wrench.template tail<3>() += r.cross(fb);
  load.force += f;
  ++load.points;
}

}  // namespace detail

/// \brief The contact wrench on a hull in state `x` from the environment's seabed (flat and
/// height field) and obstacles (see the file's comment). No allocation.
/// \param[in] hull the hull box and contact law. \param[in] env seabed and obstacles.
/// \param[in] x the vehicle's state.
/// \return the contact wrench (body axes, about the CO [N, N m]), the total force (NED [N])
/// and the number of contact points in touch.
template <typename Scalar>
HullContactLoad<Scalar> hull_contact(const HullContact<Scalar>& hull,
                                     const environment::Environment<Scalar>& env,
                                     const vehicle::VehicleState<Scalar>& x) {
  using std::sqrt;
  HullContactLoad<Scalar> load;
  const Matrix3<Scalar> R = x.attitude.toRotationMatrix();
  const Vector3<Scalar>& h = hull.half_extents;
  Vector3<Scalar> corners[8];
  for (int k = 0; k < 8; ++k)
    corners[k] = hull.center + Vector3<Scalar>((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                                               (k & 4) ? h.z() : -h.z());
  // The hull's NED bounding box (for the broad phase and the flat seabed).
  environment::Aabb box;
  for (const Vector3<Scalar>& c : corners) {
    const Vector3<Scalar> p = x.position + R * c;
    for (int i = 0; i < 3; ++i) {
      box.lo(i) = std::min(box.lo(i), double(value_of(p(i))));
      box.hi(i) = std::max(box.hi(i), double(value_of(p(i))));
    }
  }
  // Flat seabed.
  const Scalar bed = env.seabed_depth();
  if (double(box.hi.z()) > double(value_of(bed))) {
    const Vector3<Scalar> up(Scalar(0), Scalar(0), Scalar(-1));
    for (const Vector3<Scalar>& c : corners) {
      const Vector3<Scalar> p = x.position + R * c;
      detail::add_hull_point(hull, x, R, c, p.z() - bed, up, hull.seabed_friction, load);
    }
  }
  const environment::ObstacleSet* obstacles = env.obstacles();
  if (obstacles == nullptr) return load;
  if (const environment::HeightField* hf = obstacles->seabed();
      hf != nullptr && box.hi.z() > obstacles->seabed_shallowest()) {
    for (const Vector3<Scalar>& c : corners) {
      const Vector3<Scalar> p = x.position + R * c;
      const environment::Proximity<Scalar> q = environment::point_heightfield<Scalar>(p, *hf);
      detail::add_hull_point(hull, x, R, c, -q.distance, q.normal, hull.seabed_friction, load);
    }
  }
  // The hull as an obstacle box in NED (for the cylinder and corner queries).
  environment::Box self;
  {
    const Vector3<Scalar> centre = x.position + R * hull.center;
    for (int i = 0; i < 3; ++i) {
      self.center(i) = double(value_of(centre(i)));
      self.half_extents(i) = double(value_of(h(i)));
    }
    const Eigen::Vector3d e =
        x.attitude.toRotationMatrix().template cast<double>().eulerAngles(2, 1, 0);
    self.yaw = e(0);
    self.pitch = e(1);
    self.roll = e(2);
  }
  obstacles->for_each_near(box, [&](environment::ObstacleRef ref) {
    const Scalar mu = Scalar(obstacles->contact(ref).friction);
    if (ref.kind == environment::ObstacleRef::cylinder) {
      const environment::Cylinder& cyl = obstacles->cylinders()[std::size_t(ref.index)];
      const Vector3<Scalar> a = cyl.from.template cast<Scalar>(),
                            b = cyl.to.template cast<Scalar>();
      // The part of the axis within the hull's bounding sphere, in `pieces` sub-segments, each
      // a contact point: a cylinder along a face touches the hull along a line, which one
      // closest point would load at one end (a spurious moment).
      const Vector3<Scalar> ab = b - a, centre = x.position + R * hull.center;
      const Scalar l2 = ab.squaredNorm(), reach = h.norm() + Scalar(cyl.radius);
      const Scalar tc = (centre - a).dot(ab) / l2, dt = reach / sqrt(l2);
      const Scalar t0 = std::max(Scalar(0), tc - dt), t1 = std::min(Scalar(1), tc + dt);
      if (!(t1 > t0)) return;
      constexpr int pieces = 4;
      for (int k = 0; k < pieces; ++k) {
        const Vector3<Scalar> pa = a + (t0 + (t1 - t0) * Scalar(k) / Scalar(pieces)) * ab;
        const Vector3<Scalar> pb = a + (t0 + (t1 - t0) * Scalar(k + 1) / Scalar(pieces)) * ab;
        const environment::Proximity<Scalar> q = environment::segment_box<Scalar>(pa, pb, self);
        // q.normal points from the hull towards the axis: the hull is pushed the other way.
        const Vector3<Scalar> r = R.transpose() * (q.on_obstacle - x.position);
        detail::add_hull_point(hull, x, R, r, Scalar(cyl.radius) - q.distance,
                               Vector3<Scalar>(-q.normal), mu, load);
      }
    } else {
      const environment::Box& ob = obstacles->boxes()[std::size_t(ref.index)];
      // Hull corners inside the obstacle box.
      for (const Vector3<Scalar>& c : corners) {
        const Vector3<Scalar> p = x.position + R * c;
        const environment::Proximity<Scalar> q = environment::point_box<Scalar>(p, ob);
        detail::add_hull_point(hull, x, R, c, -q.distance, q.normal, mu, load);
      }
      // Obstacle corners inside the hull box.
      const Eigen::Matrix3d Ro = ob.rotation();
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d oc =
            ob.center + Ro * Eigen::Vector3d((k & 1) ? ob.half_extents.x() : -ob.half_extents.x(),
                                             (k & 2) ? ob.half_extents.y() : -ob.half_extents.y(),
                                             (k & 4) ? ob.half_extents.z() : -ob.half_extents.z());
        const Vector3<Scalar> p = oc.template cast<Scalar>();
        const environment::Proximity<Scalar> q = environment::point_box<Scalar>(p, self);
        const Vector3<Scalar> r = R.transpose() * (p - x.position);
        detail::add_hull_point(hull, x, R, r, -q.distance, Vector3<Scalar>(-q.normal), mu, load);
      }
    }
  });
  return load;
}

using HullContactd = HullContact<double>;  ///< HullContact<double>
using HullContactf = HullContact<float>;   ///< HullContact<float>

}  // namespace kelp::system
