/// \file
/// \brief Contact of the lumped-mass tether with the environment's obstacles
/// (environment::ObstacleSet): the segments against cylinders and boxes, the nodes against a
/// height-field seabed. Part of compute_forces (a pass after the node forces) and of both
/// Jacobians of the implicit steps.
///
/// The law is the seabed's (TetherParameters::seabed_*; MoorDyn v2's seabed model with kelp's
/// damping ramp and saturated-viscous friction), applied along the obstacle's normal:
/// - segment s (nodes a = s, b = s + 1, rest length l, diameter d) against a cylinder or box:
///   the closest point of the segment p = (1 − t) x_a + t x_b to the obstacle
///   (environment::segment_capsule, environment::segment_box), its signed distance δ and the
///   normal n from the obstacle; penetration p = d/2 − δ; while p > 0 the force
///   F = N n − μ N v_t / max(|v_t|, v_f) with N = max(0, (k p + c w min(1, p/p_c)) d l),
///   w = −n·v_p the approach speed of the contact point v_p = (1 − t) v_a + t v_b, v_t its part
///   across n; F goes to the two nodes with the closest point's barycentric weights (1 − t) F on
///   a, t F on b. The obstacle's ContactProperties give k, c, μ, v_f, p_c. A node crossing a
///   thin cylinder is caught by its segments at any point of their length, not only at the
///   nodes (no tunnelling while a step moves the line by less than the cylinder's radius);
/// - node i (lumped length l_i) against a height-field seabed: penetration along the local
///   normal p = (z − h)/√(1 + |∇h|²), the same law with the tether's seabed constants
///   (seabed_stiffness, seabed_damping, seabed_friction, friction_velocity,
///   seabed_damping_depth) and d l_i, as the flat seabed.
/// Costs nothing when the environment has no obstacles; with obstacles, one broad-phase query
/// per segment (environment::ObstacleSet::for_each_near). No heap allocation.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/tether/force_kernels.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

namespace detail {

/// True for environments that carry obstacles: `const environment::ObstacleSet* obstacles() const`
/// (kelp::environment::Environment does). Other environments have none.
template <typename Env, typename = void>
struct has_obstacles_query : std::false_type {};
template <typename Env>
struct has_obstacles_query<Env, std::void_t<decltype(static_cast<const environment::ObstacleSet*>(
                                    std::declval<const Env&>().obstacles()))>> : std::true_type {};

/// The obstacles of `env`, or null.
template <typename Env>
const environment::ObstacleSet* obstacles_of(const Env& env) {
  if constexpr (has_obstacles_query<Env>::value)
    return env.obstacles();
  else
    return nullptr;
}

/// The contact law at one point: penetration `pen` > 0 along the unit normal `n`, velocity `vp`
/// of the contact point, stiffness k and damping c already multiplied by d·l [N/m, N s/m],
/// damping ramp depth pc, friction μ and regularisation speed vf. Returns false (and no force)
/// when there is no compressive normal force.
template <typename Scalar>
struct ContactLaw {
  Vector3<Scalar> force = Vector3<Scalar>::Zero();
  Scalar normal = Scalar(0);  ///< N [N]
  Scalar kn = Scalar(0);      ///< ∂N/∂p [N/m] (stiffness plus the ramp's part while landing)
  Scalar cn = Scalar(0);      ///< ∂N/∂w [N s/m]
  Scalar coef = Scalar(0);    ///< friction μN / max(|v_t|, v_f) [N s/m]
};
template <typename Scalar>
bool contact_law(Scalar pen, const Vector3<Scalar>& n, const Vector3<Scalar>& vp, Scalar k,
                 Scalar c, Scalar pc, Scalar mu, Scalar vf, ContactLaw<Scalar>& out) {
  using std::sqrt;
  if (!(pen > Scalar(0))) return false;
  const Scalar w = -n.dot(vp);
  const bool ramping = pc > Scalar(0) && pen < pc;
  const Scalar ramp = ramping ? pen / pc : Scalar(1);
  const Scalar normal = k * pen + c * w * ramp;
  if (!(normal > Scalar(0))) return false;
  out.normal = normal;
  out.kn = k + (ramping ? c * w / pc : Scalar(0));
  out.cn = c * ramp;
  out.force = normal * n;
  out.coef = Scalar(0);
  if (mu > Scalar(0)) {
    const Vector3<Scalar> vt = vp + w * n;
    const Scalar vt_abs = sqrt(vt.squaredNorm());
    out.coef = mu * normal / (vt_abs > vf ? vt_abs : vf);
    out.force -= out.coef * vt;
  }
  return true;
}

/// Contact of obstacle `r` with segment xa→xb: the forces on its two nodes, the normal force,
/// the barycentric t and the normal of the closest point, and the law's terms.
template <typename Scalar>
struct SegmentContact {
  Vector3<Scalar> fa = Vector3<Scalar>::Zero(), fb = Vector3<Scalar>::Zero();
  Vector3<Scalar> n = Vector3<Scalar>::UnitZ();
  Scalar t = Scalar(0);
  ContactLaw<Scalar> law;
};
template <typename Scalar>
bool segment_contact(const environment::ObstacleSet& set, environment::ObstacleRef r,
                     const Vector3<Scalar>& xa, const Vector3<Scalar>& xb,
                     const Vector3<Scalar>& va, const Vector3<Scalar>& vb, Scalar radius, Scalar dl,
                     SegmentContact<Scalar>& out) {
  const environment::Proximity<Scalar> pr = set.proximity<Scalar>(r, xa, xb);
  const Scalar pen = radius - pr.distance;
  if (!(pen > Scalar(0))) return false;
  const environment::ContactProperties& cp = set.contact(r);
  const Scalar t = pr.t, one(1);
  const Vector3<Scalar> vp = (one - t) * va + t * vb;
  if (!contact_law(pen, pr.normal, vp, Scalar(cp.stiffness) * dl, Scalar(cp.damping) * dl,
                   Scalar(cp.damping_depth), Scalar(cp.friction), Scalar(cp.friction_velocity),
                   out.law))
    return false;
  out.t = t;
  out.n = pr.normal;
  out.fa = (one - t) * out.law.force;
  out.fb = t * out.law.force;
  return true;
}

/// Contact of the height field with node x (lumped length li) under the tether's seabed law.
template <typename Scalar>
bool node_seabed_contact(const environment::HeightField& hf, const TetherParameters<Scalar>& p,
                         const Vector3<Scalar>& x, const Vector3<Scalar>& v, Scalar li,
                         ContactLaw<Scalar>& law, Vector3<Scalar>& normal) {
  const environment::Proximity<Scalar> pr = environment::point_heightfield<Scalar>(x, hf);
  const Scalar dl = p.diameter * li;
  // MoorDyn's seabed has no damping ramp (LineModel::moordyn ignores seabed_damping_depth).
  const Scalar pc = p.line_model == LineModel::moordyn ? Scalar(0) : p.seabed_damping_depth;
  if (!contact_law(-pr.distance, pr.normal, v, p.seabed_stiffness * dl, p.seabed_damping * dl, pc,
                   p.seabed_friction, p.friction_velocity, law))
    return false;
  normal = pr.normal;
  return true;
}

/// Rest length of segment s (segment 0's own at a winch).
template <typename Scalar>
Scalar contact_segment_length(const ForcePass<Scalar>& c, const TetherWorkspace<Scalar>& ws,
                              int s) {
  return s == 0 && c.winch ? ws.winch_length : c.l;
}

/// The broad-phase query box of segment xa→xb inflated by the cable's radius.
template <typename Scalar>
environment::Aabb segment_box(const Vector3<Scalar>& xa, const Vector3<Scalar>& xb, Scalar radius) {
  environment::Aabb q;
  const double r = double(value_of(radius));
  for (int k = 0; k < 3; ++k) {
    const double a = double(value_of(xa(k))), b = double(value_of(xb(k)));
    q.lo(k) = (a < b ? a : b) - r;
    q.hi(k) = (a < b ? b : a) + r;
  }
  return q;
}

/// Flat index of an obstacle (cylinders first, then boxes).
inline int flat_index(const environment::ObstacleSet& set, environment::ObstacleRef r) {
  return r.kind == environment::ObstacleRef::cylinder ? r.index
                                                      : int(set.cylinders().size()) + r.index;
}

/// m += f · (symmetric 3×3 of a a ᵀ) in the (xx, yx, zx, yy, zy, zz) layout of node_dv.
template <typename Scalar, typename Col>
void add_sym_outer(Col&& m, Scalar f, const Vector3<Scalar>& a) {
  m(0) += f * a(0) * a(0);
  m(1) += f * a(1) * a(0);
  m(2) += f * a(2) * a(0);
  m(3) += f * a(1) * a(1);
  m(4) += f * a(2) * a(1);
  m(5) += f * a(2) * a(2);
}

/// Adds the contact law's part of the symmetric block-tridiagonal Jacobian at one node with
/// weight w (the barycentric weight squared): −∂F/∂x ≈ w kn n nᵀ into node_kc, −∂F/∂v ≈
/// w (cn n nᵀ + coef (I − n nᵀ)) into node_dv. Left out (the whole Jacobian has them): the
/// turning of the normal, the coupling of the segment's two nodes, the friction's dependence on N.
template <typename Scalar>
void add_contact_diagonal(TetherWorkspace<Scalar>& ws, int i, Scalar w, const Vector3<Scalar>& n,
                          const ContactLaw<Scalar>& law) {
  add_sym_outer(ws.node_kc.col(i), w * law.kn, n);
  add_sym_outer(ws.node_dv.col(i), w * (law.cn - law.coef), n);
  ws.node_dv(0, i) += w * law.coef;
  ws.node_dv(3, i) += w * law.coef;
  ws.node_dv(5, i) += w * law.coef;
}

/// The contact pass of compute_forces: adds the obstacles' forces to the node forces in the
/// pass buffer (before finish_block), fills ws.contact_force, segment_contact, segment_obstacle,
/// any_contact, adds the heightfield's normal force to ws.seabed_force and, WithJacobian, the
/// contacts' diagonal terms (add_contact_diagonal).
template <bool WithJacobian, typename Scalar>
void contact_pass(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  using V3 = Vector3<Scalar>;
  const environment::ObstacleSet& set = *c.obstacles;
  const TetherParameters<Scalar>& p = *c.p;
  ws.contact_force.setZero();
  ws.segment_contact.setZero();
  ws.segment_obstacle.setConstant(-1);
  ws.any_contact = false;
  if constexpr (WithJacobian) ws.node_kc.setZero();
  const int n = c.n;
  const Scalar radius = c.half_d;
  const auto add_force = [&](int i, const V3& f) {
    for (int k = 0; k < 3; ++k) {
      ws.pass_buffer(i, kNodeForce + k) += f(k);
      ws.contact_force(k, i) += f(k);
    }
  };
  if (set.size() > 0) {
    for (int s = 0; s < n; ++s) {
      if (c.parted && c.parted[s]) continue;
      const V3 xa(c.X(0, s), c.X(1, s), c.X(2, s)), xb(c.X(0, s + 1), c.X(1, s + 1), c.X(2, s + 1));
      const environment::Aabb q = segment_box(xa, xb, radius);
      const Scalar dl = p.diameter * contact_segment_length(c, ws, s);
      Scalar strongest(0);
      set.for_each_near(q, [&](environment::ObstacleRef r) {
        const V3 va(c.V(0, s), c.V(1, s), c.V(2, s)),
            vb(c.V(0, s + 1), c.V(1, s + 1), c.V(2, s + 1));
        SegmentContact<Scalar> sc;
        if (!segment_contact(set, r, xa, xb, va, vb, radius, dl, sc)) return;
        add_force(s, sc.fa);
        add_force(s + 1, sc.fb);
        ws.segment_contact(s) += sc.law.normal;
        if (sc.law.normal > strongest) {
          strongest = sc.law.normal;
          ws.segment_obstacle(s) = flat_index(set, r);
        }
        ws.any_contact = true;
        if constexpr (WithJacobian) {
          const Scalar wa = Scalar(1) - sc.t, wb = sc.t;
          add_contact_diagonal(ws, s, wa * wa, sc.n, sc.law);
          add_contact_diagonal(ws, s + 1, wb * wb, sc.n, sc.law);
        }
      });
    }
  }
  if (const environment::HeightField* hf = set.seabed()) {
    const Scalar shallowest = Scalar(set.seabed_shallowest());
    for (int i = 0; i <= n; ++i) {
      if (c.X(2, i) < shallowest) continue;  // above every node of the grid: no contact
      const int kind = i == 0 ? 0 : (i == n ? 2 : (i == 1 && c.winch ? 3 : 1));
      const V3 x(c.X(0, i), c.X(1, i), c.X(2, i)), v(c.V(0, i), c.V(1, i), c.V(2, i));
      ContactLaw<Scalar> law;
      V3 nrm;
      if (!node_seabed_contact(*hf, p, x, v, c.kinds[kind].li, law, nrm)) continue;
      add_force(i, law.force);
      ws.seabed_force(i) += law.normal;
      ws.any_contact = true;
      if constexpr (WithJacobian) add_contact_diagonal(ws, i, Scalar(1), nrm, law);
    }
  }
}

/// Central differences of a contact force f(y) (y: 12 numbers, x_a, x_b, v_a, v_b; f: 6, the
/// forces on a and b) in place of an analytic derivative of the closest-point parameters: the
/// law is closed-form and cheap, evaluated 24 times per segment in contact. Steps h_x, h_v.
template <typename Scalar, typename F>
void contact_differences(F&& f, const Eigen::Matrix<Scalar, 12, 1>& y, Scalar hx, Scalar hv,
                         Eigen::Matrix<Scalar, 6, 12>& jac) {
  Eigen::Matrix<Scalar, 12, 1> yp = y;
  for (int k = 0; k < 12; ++k) {
    const Scalar h = k < 6 ? hx : hv;
    yp(k) = y(k) + h;
    const Eigen::Matrix<Scalar, 6, 1> fp = f(yp);
    yp(k) = y(k) - h;
    const Eigen::Matrix<Scalar, 6, 1> fm = f(yp);
    yp(k) = y(k);
    jac.col(k) = (fp - fm) / (Scalar(2) * h);
  }
}

/// Hands the obstacle contacts' Jacobian blocks ∂F_i/∂x_j, ∂F_i/∂v_j to `sink` (the interface of
/// force_jacobian_blocks: sink.x(i, j, A, c), sink.v(i, j, A, c)) for positions x, velocities v.
/// Segment contacts by central differences of the closed-form law (contact_differences, the
/// closest point, its barycentric weights and normal moving with the nodes), node contacts with
/// the height field likewise. No heap allocation.
template <typename Scalar, typename Env, typename DX, typename DV, typename Sink>
void contact_jacobian_blocks(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                             const Env& env, const Eigen::MatrixBase<DX>& x,
                             const Eigen::MatrixBase<DV>& v, Sink& sink) {
  using V3 = Vector3<Scalar>;
  using Y = Eigen::Matrix<Scalar, 12, 1>;
  using F6 = Eigen::Matrix<Scalar, 6, 1>;
  const environment::ObstacleSet* set = obstacles_of(env);
  if (!set) return;
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  const Scalar radius = Scalar(0.5) * p.diameter;
  using std::abs;
  using std::cbrt;
  const Scalar eps3 = cbrt(Scalar(std::numeric_limits<Scalar>::epsilon()));
  Scalar xmax(0);
  for (int i = 0; i <= n; ++i)
    for (int k = 0; k < 3; ++k) xmax = abs(x(k, i)) > xmax ? abs(x(k, i)) : xmax;
  const Scalar hx =
      eps3 * (p.diameter > eps3 * (Scalar(1) + xmax) ? p.diameter : eps3 * (Scalar(1) + xmax));
  const Scalar hv =
      eps3 * (p.friction_velocity > Scalar(0.01) ? p.friction_velocity : Scalar(0.01));
  const auto emit = [&](int i0, int i1, const Eigen::Matrix<Scalar, 6, 12>& jac) {
    const int node[2] = {i0, i1};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        if (i0 == i1 && (a == 1 || b == 1)) continue;
        const Matrix3<Scalar> jx = jac.template block<3, 3>(3 * a, 3 * b);
        const Matrix3<Scalar> jv = jac.template block<3, 3>(3 * a, 6 + 3 * b);
        sink.x(node[a], node[b], jx, Scalar(1));
        sink.v(node[a], node[b], jv, Scalar(1));
      }
  };
  Eigen::Matrix<Scalar, 6, 12> jac;
  if (set->size() > 0) {
    for (int s = 0; s < n; ++s) {
      if (ws.is_parted(s)) continue;
      const V3 xa = x.col(s), xb = x.col(s + 1);
      const Scalar l = s == 0 && has_winch_segment(ws) ? ws.winch_length : model.segment_length();
      const Scalar dl = p.diameter * l;
      // A margin of the difference steps, so that a segment touching within them is seen.
      const environment::Aabb q = segment_box(xa, xb, Scalar(radius + Scalar(2) * hx));
      set->for_each_near(q, [&](environment::ObstacleRef r) {
        Y y;
        y << xa, xb, v.col(s), v.col(s + 1);
        const auto f = [&](const Y& z) {
          SegmentContact<Scalar> sc;
          F6 out = F6::Zero();
          if (segment_contact<Scalar>(*set, r, z.template segment<3>(0), z.template segment<3>(3),
                                      z.template segment<3>(6), z.template segment<3>(9), radius,
                                      dl, sc))
            out << sc.fa, sc.fb;
          return out;
        };
        // Only segments in contact, or within a step of it.
        const environment::Proximity<Scalar> pr = set->proximity<Scalar>(r, xa, xb);
        if (!(radius - pr.distance > -Scalar(2) * hx)) return;
        contact_differences<Scalar>(f, y, hx, hv, jac);
        emit(s, s + 1, jac);
      });
    }
  }
  if (const environment::HeightField* hf = set->seabed()) {
    const Scalar shallowest = Scalar(set->seabed_shallowest());
    for (int i = 0; i <= n; ++i) {
      if (x(2, i) + Scalar(2) * hx < shallowest) continue;
      const Scalar li = node_length_at(model, ws, i);
      Y y;
      y << x.col(i), x.col(i), v.col(i), v.col(i);
      const auto f = [&](const Y& z) {
        ContactLaw<Scalar> law;
        V3 nrm;
        F6 out = F6::Zero();
        if (node_seabed_contact<Scalar>(*hf, p, z.template segment<3>(0), z.template segment<3>(6),
                                        li, law, nrm))
          out.template head<3>() = law.force;
        return out;
      };
      contact_differences<Scalar>(f, y, hx, hv, jac);
      if (jac.isZero(Scalar(0))) continue;
      emit(i, i, jac);
    }
  }
}

}  // namespace detail

}  // namespace kelp::tether
