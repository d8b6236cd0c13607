// Attaching tether ends to vehicles: end motion of a body-fixed point, the body-frame wrench of
// an NED force, and a tether advanced between two vehicles through those two.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "kelp/core/rotation.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/system/tether_attachment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"

namespace kt = kelp::tether;
namespace ks = kelp::system;
using kelp::Vector3;
using kelp::Vector6;

TEMPLATE_TEST_CASE("attachment motion is the body-fixed point's position and velocity",
                   "[system][attachment]", double, float) {
  using S = TestType;
  kelp::vehicle::VehicleState<S> v;
  v.position = Vector3<S>(S(1), S(2), S(3));
  v.attitude = kelp::quaternion_from_euler(S(0.1), S(-0.2), S(0.7));
  v.nu << S(0.5), S(-0.1), S(0.2), S(0.05), S(-0.03), S(0.2);
  const Vector3<S> r(S(0.4), S(-0.2), S(0.1));
  const kt::EndMotion<S> m = ks::attachment_motion(v, r);
  CHECK((m.position - (v.position + v.attitude * r)).norm() < S(1e-6));
  // Finite difference of the point position along the motion: p(t+h) with
  // position += R v h and attitude += ½ q ⊗ ω h (Fossen eq. 2.75), compared with R (v + ω × r).
  const S h = S(1e-4);
  kelp::vehicle::VehicleState<S> w = v;
  w.position += (v.attitude * Vector3<S>(v.nu.template head<3>())) * h;
  const Eigen::Matrix<S, 4, 1> qd = kelp::quaternion_rate(v.attitude, v.nu.template tail<3>());
  w.attitude.coeffs() = v.attitude.coeffs() + h * qd;  // qd in coeffs() order (x, y, z, w)
  w.attitude.normalize();
  const Vector3<S> fd = (w.point_position(r) - v.point_position(r)) / h;
  CHECK((fd - m.velocity).norm() < S(2e-3));
  CHECK(m.acceleration.isZero());
}

TEST_CASE("attachment wrench: force in body axes and moment r x f about the CO",
          "[system][attachment]") {
  kelp::vehicle::VehicleStated v;
  v.attitude = kelp::quaternion_from_euler(0.0, 0.0, kelp::pi / 2);  // heading east
  const Vector3<double> r(1.0, 0.0, 0.5);                            // 1 m forward, 0.5 m down
  // A 10 N force pointing north on a vehicle heading east acts to port (−y body).
  const Vector6<double> tau = ks::attachment_wrench(v, r, Vector3<double>(10, 0, 0));
  CHECK(tau(0) == Approx(0).margin(1e-12));
  CHECK(tau(1) == Approx(-10));
  CHECK(tau(2) == Approx(0).margin(1e-12));
  // Moment = r × f_body = (1, 0, 0.5) × (0, −10, 0) = (5, 0, −10).
  CHECK(tau(3) == Approx(5));
  CHECK(tau(4) == Approx(0).margin(1e-12));
  CHECK(tau(5) == Approx(-10));
  // Power balance: the force does the same work on the point as τ on ν.
  v.nu << 0.3, -0.2, 0.1, 0.02, 0.05, -0.1;
  const Vector3<double> f(3, -1, 2);
  const Vector6<double> t2 = ks::attachment_wrench(v, r, f);
  CHECK(t2.dot(v.nu) == Approx(f.dot(v.point_velocity(r))));
}

TEST_CASE("tether between two vehicles: loads balance the line and follow the vehicles",
          "[system][attachment]") {
  kelp::environment::Environmentd env;
  kt::TetherParametersd p;
  p.segments = 20;
  p.internal_damping = 100.0;
  const kt::TetherModeld model(p);
  kt::TetherWorkspaced ws(model);
  // ASV at the surface with the tether 0.5 m behind its CO; AUV 10 m north, 5 m down, tether on
  // its top 0.2 m forward of the CO.
  kelp::vehicle::VehicleStated asv, auv;
  asv.position = Vector3<double>(0.5, 0, 0);
  auv.position = Vector3<double>(9.8, 0, 5.2);
  const Vector3<double> r_asv(-0.5, 0, 0), r_auv(0.2, 0, -0.2);
  kt::TetherStated state;
  REQUIRE(kt::static_initial_state(model, ws, env, asv.point_position(r_asv),
                                   auv.point_position(r_auv), state)
              .converged);
  CHECK((state.position.col(0) - Vector3<double>(0, 0, 0)).norm() < 1e-12);
  CHECK((state.position.col(20) - Vector3<double>(10, 0, 5)).norm() < 1e-12);
  // The loads on both vehicles over one advance: the tether's end forces, NED, and the wrenches
  // they exert through the attachment points.
  struct Loads {
    Vector3<double> start, end;
    Vector6<double> tau_start, tau_end;
    kt::StepReportd report;
  };
  const auto advance = [&](const kelp::vehicle::VehicleStated& a,
                           const kelp::vehicle::VehicleStated& b, kt::Integrator integrator) {
    Loads l;
    l.report = kt::advance(model, ws, env, state, ks::tether_boundary(a, r_asv, b, r_auv), 0.1,
                           {0.01, integrator});
    l.start = ws.end_forces.on_start;
    l.end = ws.end_forces.on_end;
    l.tau_start = ks::attachment_wrench(a, r_asv, l.start);
    l.tau_end = ks::attachment_wrench(b, r_auv, l.end);
    return l;
  };
  // Both vehicles at rest: a 0.1 s advance keeps the static loads. The vertical forces carry the
  // submerged weight of the line, less the buoyancy it lacks where it leaves the ASV at the
  // surface: the cross-section goes under over its first half diameter of depth (φ from ½ to 1),
  // which takes D/8 of wet length per unit of depth, l D/(8 Δz) along segment 0 (Δz its drop).
  // The horizontal ones are equal and opposite (H).
  const Loads loads = advance(asv, auv, kt::Integrator::bdf2);
  CHECK(loads.report.substeps == 10);
  const double w = model.submerged_weight_per_length(env.water_density(), env.gravity());
  const double dz0 = state.position(2, 1) - state.position(2, 0);
  REQUIRE(dz0 > 0.5 * p.diameter);
  const double missing = env.water_density() * model.area() * env.gravity() *
                         model.segment_length() * p.diameter / (8 * dz0);
  CHECK(loads.start.z() + loads.end.z() == Approx(w * p.length + missing).epsilon(1e-5));
  CHECK(loads.start.x() == Approx(-loads.end.x()).epsilon(1e-4));
  CHECK(loads.start.x() > 0);  // the ASV is pulled towards the AUV
  // The AUV's tether point is 0.2 m forward (r_x > 0) and 0.2 m above (r_z < 0) its CO and the
  // line pulls it backward (f_x < 0) and down (f_z > 0). In the pitch moment M = r_z f_x − r_x f_z
  // the first term is nose-up and the second nose-down; the downward pull is larger than the
  // backward one here, so the r_x f_z term dominates and the nose pitches down (M < 0).
  CHECK(loads.tau_end(4) < 0);
  CHECK(loads.tau_start.head<3>().isApprox(loads.start));  // ASV level, heading north
  // Moving the AUV away tightens the tether: after 2 s at 1 m/s north the pull grows. The
  // boundary, the advance and the wrenches allocate nothing.
  kelp::vehicle::VehicleStated moving = auv;
  moving.nu(0) = 1.0;
  Loads last;
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 20; ++k) {
    last = advance(asv, moving, kt::Integrator::implicit_euler);
    moving.position.x() += 0.1;
  }
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(state.position(0, 20) == Approx(12.0).epsilon(1e-9));
  CHECK(last.end.norm() > 1.5 * loads.end.norm());
  // A bad attachment point is refused before anything moves.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(ks::tether_boundary(asv, Vector3<double>(nan, 0, 0), auv, r_auv),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(ks::tether_boundary(asv, r_asv, auv, Vector3<double>(0, 0, nan)),
                  kelp::invalid_argument);
}
