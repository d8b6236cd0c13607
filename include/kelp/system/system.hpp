/// \file
/// \brief The coupled world: a surface vehicle (ASV), an underwater vehicle (AUV) and the tether
/// between them, advanced together in one environment by one `step`.
///
/// Model / workspace / state as in the rest of kelp: a `SystemModel` is built once (vehicle
/// models, attachment points, tether model, the environment that is the one source of water
/// density and gravity), a `SystemWorkspace` holds every buffer a step needs, and a `SystemState`
/// holds everything that determines the next step (the clock, both vehicle states, the tether state
/// with its integrator history, and the coupling's memory), so that saving and restoring a state
/// reproduces a run bit for bit. The call is kelp's one convention, `step(model, ws, state,
/// inputs, dt, options)` (the system model owns its environment, so none is passed).
///
/// **Coupling scheme (partitioned, the tether first, impulse-consistent).** One step of length h:
/// 1. each attachment point's motion over the step is predicted from its vehicle's state and its
///    last acceleration ν̇ (kept in the state): p + v τ + ½ a τ²;
/// 2. the tether is advanced over the step (its own sub-steps; implicit schemes retry in shorter
///    ones) with its ends on those paths. Its integrator reports the impulse it delivered to
///    each end over the step (`TetherWorkspace::end_impulse`: the end force weighted as the
///    integrator weights node forces in its momentum update, end node inertia included, so the
///    end node's mass acts on the vehicle);
/// 3. each vehicle is advanced by RK4 in the environment (water, free surface and wind sampled at
///    its own position at the start and predicted end of the step, linear in time between: see
///    detail::step_vehicle) under its inputs and that impulse as a constant force over the step,
///    fixed in NED at the attachment point (its body-frame wrench follows the vehicle's attitude
///    through the RK4 stages).
/// The vehicles receive exactly the impulses the tether's ends delivered, so momentum is
/// balanced whatever the tether integrator: with no other horizontal force, the horizontal
/// momentum of vehicles and tether stays within 0.4 % over 20 s of snapping (BDF2 at 10 ms; the
/// rest is BDF2's own momentum update, which conserves a two-step average).
///
/// The work exchanged is exact up to the difference between the predicted and the actual paths
/// of the attachment points. `SystemParameters::coupling_corrections` = k > 0 redoes steps 2–3 k
/// times with the tether's ends on the paths that reach the vehicles' actual attachment points
/// (a fixed-point iteration, which converges fast: a vehicle moves ~ΔF h²/(6 m) under a change
/// ΔF of the end force). Measured with every dissipation off (AUV sent away at 1 m/s, the line
/// going taut and slack for 60 s, h = 10 ms, tether RK4 in 0.2 ms sub-steps): the total energy
/// stays within 0.17 % of its initial value with one corrector pass, 4 % without.
///
/// Energy and the tether integrator: BDF2 (the default, robust for snap loads) damps the line's
/// fast modes numerically (by design: it is L-stable), so an undamped line loses energy under it
/// (in the run above, 30 % over 60 s with the corrector, 46 % without); RK4 in short sub-steps
/// does not. With the line's drag and internal damping on, it also dissipates physically (how
/// the two compare was not measured). A step that cannot be completed throws with every part of
/// the state as it was.
///
/// **Propulsion (optional, per vehicle).** With `SystemParameters::asv_propulsion` /
/// `auv_propulsion` set, a vehicle's thrusters are part of the system: each step advances them
/// first under the inputs' per-thruster commands (vehicle::advance in vehicle/propulsion.hpp:
/// the battery's terminal voltage solved for the step, each thrust's first-order lag integrated
/// exactly) and adds the wrench of their mean thrust over the step, B f̄, to the vehicle's τ; the
/// thrusters' and battery's state is part of SystemState. Without it (the default), `inputs.tau`
/// is the whole control wrench, as before.
///
/// **Winch (optional).** With `SystemParameters::winch` set, the tether's start end (on the ASV)
/// runs over a winch (kelp/tether/winch.hpp): after the tether and the vehicles have been
/// advanced, the winch moves its payout rate towards `SystemInputs::winch_payout_rate` within its
/// limits, segment 0's unstretched length changes by rate·h, and nodes are inserted or removed
/// there (reported in SystemReport::remesh). The tether's node count then changes between steps:
/// SystemModel::tether_of(state) is the line model of a state, and the buffers of every count are
/// built with the workspace, so a step allocates nothing. The momentum a removed node hands to
/// the ASV's attachment (RemeshReport::impulse_on_start, at most μl/2 times the speed of node 1
/// relative to the winch) is reported, not applied to the ASV.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/system/hull_contact.hpp"
#include "kelp/system/tether_attachment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/winch.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/propulsion.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/surroundings.hpp"
#include "kelp/vehicle/water.hpp"

namespace kelp::system {

/// \brief What a system is made of (all magnitudes as in the parts' own parameters).
/// \tparam Scalar double or float.
template <typename Scalar>
struct SystemParameters {
  /// The surface vehicle (start end of the tether).
  vehicle::VehicleParameters<Scalar> asv;
  /// The underwater vehicle (far end of the tether).
  vehicle::VehicleParameters<Scalar> auv;
  /// Tether attachment point on the ASV, body frame [m].
  Vector3<Scalar> asv_attachment = Vector3<Scalar>::Zero();
  /// Tether attachment point on the AUV, body frame [m].
  Vector3<Scalar> auv_attachment = Vector3<Scalar>::Zero();
  /// The tether; both ends must be `kinematic` (they are carried by the vehicles).
  tether::TetherParameters<Scalar> tether;
  /// Tether time integration (implicit schemes retry unconverged steps in sub-steps).
  tether::Integrator tether_integrator = tether::Integrator::bdf2;
  /// Newton settings of the tether's implicit schemes.
  tether::ImplicitOptions<Scalar> tether_options;
  /// Longest tether sub-step [s]; a system step of dt takes ⌈dt / max_tether_dt⌉ of them.
  double max_tether_dt = 0.01;
  /// Corrector passes per step: after the vehicles have moved, the tether step is redone with
  /// its ends on the paths that reach the vehicles' actual attachment points, and the vehicles
  /// are stepped again under the new end force. 0 (explicit partitioned coupling) is the
  /// fastest; each pass costs about one more step and makes the exchange of work between the
  /// vehicles and the tether more exact (see the file's comment).
  int coupling_corrections = 0;
  /// An opt-in safety net: when an implicit tether step fails (Newton's method does not
  /// converge even in the sub-steps `tether_options.max_step_halvings` allows), redo that step
  /// with RK4 in sub-steps of the line's stable explicit step (tether::estimate_stable_dt)
  /// instead of throwing; counted in SystemReport::tether_fallbacks (and SolverStats). Such a
  /// step costs about dt / h_stable × 4 force evaluations, and its numbers are RK4's, not the
  /// chosen scheme's. false (the default): throw kelp::numerical_error with the state unchanged,
  /// as the tether step does, so that a run's results never silently depend on it.
  bool explicit_fallback = false;
  /// The ASV's thrusters and battery (lag, current, voltage sag), driven by
  /// SystemInputs::asv_commands; empty (the default): no propulsion model, `inputs.asv.tau` is
  /// the control wrench.
  std::optional<vehicle::PropulsionParameters<Scalar>> asv_propulsion;
  /// The AUV's thrusters and battery; see asv_propulsion.
  std::optional<vehicle::PropulsionParameters<Scalar>> auv_propulsion;
  /// A winch at the tether's start end (on the ASV) that pays out and reels in during the run
  /// (kelp/tether/winch.hpp; commanded by SystemInputs::winch_payout_rate). Empty (the default):
  /// the tether keeps its length and node count.
  std::optional<tether::WinchParameters<Scalar>> winch;
  /// The ASV's hull against the seabed (flat or height field) and the environment's obstacles
  /// (kelp/system/hull_contact.hpp: e.g. blueboat_hull()); its contact wrench is added to the
  /// vehicle's external wrench at every RK4 stage. Empty (the default): no hull contact.
  std::optional<HullContact<Scalar>> asv_hull;
  /// The AUV's hull (e.g. bluerov2_heavy_hull()); see asv_hull.
  std::optional<HullContact<Scalar>> auv_hull;
};

/// \brief Checks system parameters (the parts' own checks, kinematic tether ends, attachment
/// points, the tether sub-step). \throws kelp::invalid_argument naming the field.
/// \param p the parameters (vehicles, tether, attachment points in the body frames [m], the
/// longest tether sub-step [s], propulsion, winch, hulls).
template <typename Scalar>
void validate(const SystemParameters<Scalar>& p) {
  vehicle::validate(p.asv);
  vehicle::validate(p.auv);
  tether::validate(p.tether);
  check_all_finite(p.asv_attachment, "asv_attachment");
  check_all_finite(p.auv_attachment, "auv_attachment");
  KELP_CHECK(
      p.tether.start_mode == tether::EndMode::kinematic &&
          p.tether.end_mode == tether::EndMode::kinematic,
      "tether.start_mode and tether.end_mode must be kinematic (the vehicles carry the ends)");
  tether::detail::check_implicit_options(p.tether_options);
  check_positive(p.max_tether_dt, "max_tether_dt");
  KELP_CHECK(p.coupling_corrections >= 0 && p.coupling_corrections <= 16,
             "coupling_corrections must be in [0, 16]");
  if (p.asv_propulsion) vehicle::validate(*p.asv_propulsion);
  if (p.auv_propulsion) vehicle::validate(*p.auv_propulsion);
  if (p.asv_hull) validate(*p.asv_hull);
  if (p.auv_hull) validate(*p.auv_hull);
}

/// \brief A system built once from SystemParameters and an environment (copied; it is the one
/// source of water density and gravity, and both vehicles are checked against it). The
/// environment may be replaced between steps (set_environment()); the parts may not.
/// \throws kelp::invalid_argument naming the field, or the vehicle whose water differs.
template <typename Scalar>
class SystemModel {
 public:
  /// \brief Builds the parts (vehicle models, tether model, propulsion, winch) once.
  /// \param p the parameters (validate()). \param env the environment, copied.
  /// \throws kelp::invalid_argument naming the field, or the vehicle whose water differs.
  SystemModel(const SystemParameters<Scalar>& p, const environment::Environment<Scalar>& env)
      : parameters_((validate(p), p)),
        environment_(env),
        asv_(p.asv),
        auv_(p.auv),
        tether_(p.tether) {
    vehicle::check_same_water(asv_, environment_, "asv");
    vehicle::check_same_water(auv_, environment_, "auv");
    if (p.asv_propulsion) asv_propulsion_.emplace(*p.asv_propulsion);
    if (p.auv_propulsion) auv_propulsion_.emplace(*p.auv_propulsion);
    if (p.winch) winch_.emplace(p.tether, *p.winch);
  }
  /// \brief The parameters the system was built from. \return a reference valid as long as
  /// the model.
  const SystemParameters<Scalar>& parameters() const { return parameters_; }
  /// \brief The environment the system steps in. \return a reference valid until
  /// set_environment().
  const environment::Environment<Scalar>& environment() const { return environment_; }

  /// \brief Replaces the environment of a built (possibly running) system: the sea state,
  /// current, wind, air density or seabed may change between two steps (a squall, a tide turning
  /// the current); the next step() samples the new one. The water must stay the vehicles' (it is
  /// checked as at construction: their density and gravity are built into their models).
  /// Typical use: `auto env = model.environment(); env.set_current(...);
  /// model.set_environment(env);`. Copies the environment (it allocates: call it between steps,
  /// not inside one).
  /// \throws kelp::invalid_argument naming the vehicle whose water differs; the system keeps its
  /// old environment then (strong guarantee).
  /// \param env the new environment (same water density and gravity as the vehicles').
  void set_environment(const environment::Environment<Scalar>& env) {
    vehicle::check_same_water(asv_, env, "asv");
    vehicle::check_same_water(auv_, env, "auv");
    environment::Environment<Scalar> copy(env);  // may throw: environment_ untouched
    environment_ = std::move(copy);
  }

  /// \brief The surface vehicle's model. \return a reference valid as long as the model.
  const vehicle::VehicleModel<Scalar>& asv() const { return asv_; }
  /// \brief The underwater vehicle's model. \return a reference valid as long as the model.
  const vehicle::VehicleModel<Scalar>& auv() const { return auv_; }
  /// \brief The tether's model at its initial node count (see tether_of() with a winch).
  /// \return a reference valid as long as the model.
  const tether::TetherModel<Scalar>& tether() const { return tether_; }
  /// \brief The winch and its line at every node count (null without a winch).
  /// \return a pointer valid as long as the model, or null.
  const tether::WinchModel<Scalar>* winch() const { return winch_ ? &*winch_ : nullptr; }
  /// \brief The tether model of `state`: tether() without a winch, else the winch's line with
  /// the state's node count.
  /// \tparam State a SystemState (anything with a `tether` state).
  /// \param state the state whose node count selects the model.
  /// \return a reference valid as long as the model.
  template <typename State>
  const tether::TetherModel<Scalar>& tether_of(const State& state) const {
    return winch_ ? winch_->line_of(state.tether) : tether_;
  }
  /// \brief The ASV's propulsion, or null when the system has none for it.
  /// \return a pointer valid as long as the model, or null.
  const vehicle::PropulsionModel<Scalar>* asv_propulsion() const {
    return asv_propulsion_ ? &*asv_propulsion_ : nullptr;
  }
  /// \brief The AUV's propulsion, or null when the system has none for it.
  /// \return a pointer valid as long as the model, or null.
  const vehicle::PropulsionModel<Scalar>* auv_propulsion() const {
    return auv_propulsion_ ? &*auv_propulsion_ : nullptr;
  }

 private:
  SystemParameters<Scalar> parameters_;
  environment::Environment<Scalar> environment_;
  vehicle::VehicleModel<Scalar> asv_, auv_;
  tether::TetherModel<Scalar> tether_;
  std::optional<vehicle::PropulsionModel<Scalar>> asv_propulsion_, auv_propulsion_;
  std::optional<tether::WinchModel<Scalar>> winch_;
};

/// \brief Everything that determines the system's next step.
///
/// The clock is the system's (`time`); the parts carry their own (`asv.time`, `auv.time`,
/// `tether.time`, as when they are stepped on their own), which step() advances in lock-step
/// with it and refuses to run when they disagree with it (a state assembled by hand from parts
/// at other times).
template <typename Scalar>
struct SystemState {
  /// The system's clock [s] (a double for every Scalar). After a step it is the tether's clock,
  /// which sums its sub-steps with compensated (Kahan) summation.
  double time = 0.0;
  vehicle::VehicleState<Scalar> asv;  ///< the ASV (body frame at its CO); asv.time == time
  vehicle::VehicleState<Scalar> auv;  ///< the AUV; auv.time == time
  /// The tether, with its integrator history; tether.time == time.
  tether::TetherState<Scalar> tether;
  /// Last accelerations ν̇ of the vehicles (body axes): the predictor of the attachment motion.
  Vector6<Scalar> asv_nu_dot = Vector6<Scalar>::Zero();
  Vector6<Scalar> auv_nu_dot = Vector6<Scalar>::Zero();  ///< see asv_nu_dot
  /// The ASV's thrusters (lagged thrust) and battery (charge and energy drawn); empty when the
  /// system has no propulsion for it.
  vehicle::PropulsionState<Scalar> asv_propulsion;
  vehicle::PropulsionState<Scalar> auv_propulsion;  ///< the AUV's; see asv_propulsion
  /// \brief Sets the clock of the system and of its parts to `t` [s] (e.g. to start a run at
  /// another time than 0).
  /// \param t the time [s].
  void set_time(double t) {
    time = t;
    asv.time = t;
    auv.time = t;
    tether.time = t;
    tether.time_carry = 0.0;
  }
  /// \brief Forgets the coupling's memory (the vehicles' last accelerations, which predict the
  /// attachment motion): call it after editing the vehicle states by hand.
  void reset_coupling() {
    asv_nu_dot.setZero();
    auv_nu_dot.setZero();
  }
};

/// \brief The inputs of one system step: each vehicle's τ (control) and τ_ext (any other external
/// wrench; the tether's is added by the step), body axes [N, N m], and, for a vehicle with
/// propulsion, its thrusters' normalised commands (held over the step; the thrust's wrench is
/// added to τ).
template <typename Scalar>
struct SystemInputs {
  vehicle::VehicleInputs<Scalar> asv;  ///< the ASV's wrenches
  vehicle::VehicleInputs<Scalar> auv;  ///< the AUV's wrenches
  /// The ASV's thruster commands u ∈ [−1, 1] (clamped), one per thruster in the propulsion's
  /// order; empty: all 0. Must be empty when the ASV has no propulsion.
  vehicle::ThrusterVector<Scalar> asv_commands;
  vehicle::ThrusterVector<Scalar> auv_commands;  ///< the AUV's; see asv_commands
  /// Commanded payout rate of the winch [m/s] (positive: paying out); the winch follows it
  /// within its limits (tether::limited_payout_rate). Must be 0 without a winch.
  Scalar winch_payout_rate = Scalar(0);
};

/// \brief The options of one system step.
struct SystemStepOptions {
  /// Also fill `SystemReport::energy` (energy(model, state) after the step).
  bool with_energy = false;
};

/// \brief The mechanical energy of a system [J], part by part.
template <typename Scalar>
struct SystemEnergy {
  /// ASV: kinetic ½νᵀMν (added mass included) plus its hydrostatic potential (vehicle::energy).
  Scalar asv = Scalar(0);
  Scalar auv = Scalar(0);     ///< AUV, as `asv`
  Scalar tether = Scalar(0);  ///< tether: kinetic + elastic + weight and buoyancy (tether_energy)
  /// \brief The sum of the parts. \return asv + auv + tether [J].
  Scalar total() const { return asv + auv + tether; }
};

/// \brief The energy of `state` (the hydrostatic potentials relative to the environment's free
/// surface at the vehicles and the nodes). Allocation-free; costs about one tether force
/// evaluation plus a surface query per node.
/// \tparam Scalar double or float.
/// \param model The system (its environment gives ρ, g and the free surface).
/// \param state The state whose energy is wanted (its time places the free surface).
/// \return The energy of each part [J].
template <typename Scalar>
SystemEnergy<Scalar> energy(const SystemModel<Scalar>& model, const SystemState<Scalar>& state) {
  const auto& env = model.environment();
  SystemEnergy<Scalar> e;
  e.asv = vehicle::energy(model.asv(), state.asv,
                          vehicle::surroundings(model.asv(), env, state.asv, state.time));
  e.auv = vehicle::energy(model.auv(), state.auv,
                          vehicle::surroundings(model.auv(), env, state.auv, state.time));
  e.tether = tether::tether_energy(model.tether_of(state), env, state.tether);
  return e;
}

/// \brief What one system step did.
template <typename Scalar>
struct SystemReport {
  /// The tether integration: sub-steps, Newton iterations, worst residual, retries, summed over
  /// the step's coupling passes (SystemParameters::coupling_corrections) and its explicit
  /// fallback, if any; its `partings` and `failure` are the committed pass's (the line parted in
  /// this step: tether::TetherParameters::breaking_strength, kelp/tether/failure.hpp).
  tether::StepReport<Scalar> tether;
  /// Tether force on each vehicle over the step, NED [N]: the impulse the tether's integrator
  /// delivered to that end divided by dt (for BDF2, the end force at t + h).
  Vector3<Scalar> force_on_asv = Vector3<Scalar>::Zero();
  Vector3<Scalar> force_on_auv = Vector3<Scalar>::Zero();  ///< see force_on_asv
  /// The energy terms after the step, when the step was asked for them (else all zero).
  SystemEnergy<Scalar> energy;
  /// Tether steps redone explicitly after the implicit scheme failed
  /// (SystemParameters::explicit_fallback).
  int tether_fallbacks = 0;
  /// The ASV's propulsion over the step: the thrust's wrench, the battery's voltage and current
  /// (zero without propulsion).
  vehicle::PropulsionStep<Scalar> asv_propulsion;
  vehicle::PropulsionStep<Scalar> auv_propulsion;  ///< the AUV's; see asv_propulsion
  /// The winch's re-meshes after the step (nodes inserted and removed, kinetic energy lost,
  /// momentum handed to the ends); zero without a winch.
  tether::RemeshReport<Scalar> remesh;
  /// The ASV's hull contact at the end of the step (SystemParameters::asv_hull; zero without).
  HullContactLoad<Scalar> asv_contact;
  HullContactLoad<Scalar> auv_contact;  ///< the AUV's; see asv_contact
};

/// \brief Preallocated buffers of a system step.
template <typename Scalar>
struct SystemWorkspace {
  /// \brief The vehicles' buffers (ASV, AUV).
  ///@{
  vehicle::VehicleWorkspace<Scalar> asv, auv;
  ///@}
  tether::TetherWorkspace<Scalar> tether;  ///< tether buffers
  /// The tether state at the start of a step, restored if the step fails.
  tether::StateBackup<Scalar> tether_backup;
  /// With a winch: the tether buffers of every node count (tether::WinchWorkspace); `tether`
  /// holds the current count's, swapped in and out as the winch re-meshes.
  std::optional<tether::WinchWorkspace<Scalar>> winch;

  /// \brief An empty workspace (build one from the model before stepping).
  SystemWorkspace() = default;
  /// \brief Buffers sized for `model` (allocates; step() then allocates nothing).
  /// \param model the system to be stepped with this workspace.
  explicit SystemWorkspace(const SystemModel<Scalar>& model) : tether(model.tether()) {
    tether_backup.resize(model.tether().nodes());
    if (model.winch()) winch.emplace(*model.winch());
  }
};

/// \brief Readies `ws` for stepping `state` when the workspace last stepped another state: with
/// a winch, a state of another node count (one loaded from a file, kelp/sim/state_io.hpp, or a
/// copy restored after the winch re-meshed) gets that count's buffers
/// (tether::WinchWorkspace::lend). Does nothing without a winch or at the count the workspace
/// holds. Call it between steps: it may allocate (once); step() refuses a state whose node count
/// the workspace does not hold. The steps that follow are those of the state's own run, bit for
/// bit (the workspace holds scratch only).
/// \throws kelp::invalid_argument when the state's node count is outside the winch's range or
/// the workspace was built for another system.
/// \param model the system. \param ws its workspace, refitted. \param state the state to step.
template <typename Scalar>
void fit_workspace(const SystemModel<Scalar>& model, SystemWorkspace<Scalar>& ws,
                   const SystemState<Scalar>& state) {
  if (model.winch() == nullptr) return;
  KELP_CHECK(ws.winch, "workspace was built for a different system (it has no winch buffers)");
  const int nodes = int(state.tether.position.cols());
  if (ws.tether.fits(nodes)) return;
  ws.winch->lend(*model.winch(), ws.tether, nodes - 1);
}

namespace detail {

/// NED acceleration of the body point r of a vehicle in state x with body acceleration ν̇:
/// R [v̇ + ω̇ × r + ω × (v + ω × r)].
template <typename Scalar>
Vector3<Scalar> point_acceleration(const vehicle::VehicleState<Scalar>& x,
                                   const Vector6<Scalar>& nu_dot, const Vector3<Scalar>& r) {
  const Vector3<Scalar> v = x.nu.template head<3>(), w = x.nu.template tail<3>();
  const Vector3<Scalar> a =
      nu_dot.template head<3>() + nu_dot.template tail<3>().cross(r) + w.cross(v + w.cross(r));
  return x.attitude * a;
}

/// The attachment point's predicted motion over a step.
template <typename Scalar>
tether::EndMotion<Scalar> predicted_end(const vehicle::VehicleState<Scalar>& x,
                                        const Vector6<Scalar>& nu_dot, const Vector3<Scalar>& r) {
  tether::EndMotion<Scalar> m = motion_of_point(x, r);
  m.acceleration = point_acceleration(x, nu_dot, r);
  return m;
}

/// Surroundings a fraction c ∈ [0, 1] of the way from `a` to `b` (linear in every field).
template <typename Scalar>
vehicle::Surroundings<Scalar> lerp(const vehicle::Surroundings<Scalar>& a,
                                   const vehicle::Surroundings<Scalar>& b, Scalar c) {
  vehicle::Surroundings<Scalar> s;
  s.water_velocity = a.water_velocity + c * (b.water_velocity - a.water_velocity);
  s.water_acceleration = a.water_acceleration + c * (b.water_acceleration - a.water_acceleration);
  s.surface_elevation = a.surface_elevation + c * (b.surface_elevation - a.surface_elevation);
  s.surface_slope = a.surface_slope + c * (b.surface_slope - a.surface_slope);
  s.wind_velocity = a.wind_velocity + c * (b.wind_velocity - a.wind_velocity);
  s.air_density = a.air_density + c * (b.air_density - a.air_density);
  return s;
}

/// A force fixed in NED [N] applied at a body point r [m] of a vehicle (a tether's end).
template <typename Scalar>
struct PointLoad {
  Vector3<Scalar> r = Vector3<Scalar>::Zero();  ///< body frame [m]
  Vector3<Scalar> f = Vector3<Scalar>::Zero();  ///< NED [N]
};

/// One RK4 step of a vehicle in the environment under constant body wrenches `tau` and `n`
/// constant forces fixed in NED at body points (`loads`; their wrenches follow the stage
/// attitudes, summed in order). Returns the last stage's ν̇ (the predictor of the next step);
/// commits only a finite state. With a hull (`hull` not null), its contact wrench with the
/// environment's seabed and obstacles (hull_contact()) is added at every stage, from the stage's
/// state.
///
/// The surroundings (water, free surface, wind) are sampled twice per step, at the vehicle's
/// position at t and at its predicted position p + R v h at t + h, and taken linearly in time
/// at the RK4 stages (the stages' own position and attitude still enter the hydrostatics and
/// the relative velocities). Against sampling at every stage (vehicle::step_rk4) this halves the
/// environment's cost; the difference is O(h²) in the sampled fields: ~h²/8 ζ̈ ≈ 1e-5 m of
/// elevation in the paper's rough sea at h = 10 ms.
template <typename Scalar, typename Env>
Vector6<Scalar> step_vehicle(const vehicle::VehicleModel<Scalar>& model,
                             vehicle::VehicleWorkspace<Scalar>& ws,
                             vehicle::VehicleState<Scalar>& x, const Env& env, double t, double dt,
                             const vehicle::VehicleInputs<Scalar>& in,
                             const PointLoad<Scalar>* loads, int n,
                             const HullContact<Scalar>* hull = nullptr) {
  const vehicle::Surroundings<Scalar> s0 = vehicle::surroundings(model, env, x, t);
  vehicle::VehicleState<Scalar> ahead = x;
  ahead.position += x.attitude * Vector3<Scalar>(x.nu.template head<3>()) * Scalar(dt);
  const vehicle::Surroundings<Scalar> s1 = vehicle::surroundings(model, env, ahead, t + dt);
  return vehicle::detail::rk4(
             x, Scalar(dt),
             [&](const vehicle::VehicleState<Scalar>& s, double c) {
               vehicle::StateDerivative<Scalar> d;
               d.pose = vehicle::pose_rate(s.attitude, s.nu);
               Vector6<Scalar> tau_ext = in.tau_ext;
               for (int k = 0; k < n; ++k) tau_ext += wrench_of_force(s, loads[k].r, loads[k].f);
               if (hull) tau_ext += hull_contact(*hull, env, s).wrench;
               // Unchecked: a NaN tether force or stage state ends the step as numerical_error.
               d.nu_dot = vehicle::detail::forward_dynamics_unchecked(model, ws, s, in.tau, tau_ext,
                                                                      lerp(s0, s1, Scalar(c)));
               return d;
             },
             "system::step (vehicle)")
      .nu_dot;
}

/// step_vehicle under one tether force `f_ned` at the body point r.
template <typename Scalar, typename Env>
Vector6<Scalar> step_vehicle(const vehicle::VehicleModel<Scalar>& model,
                             vehicle::VehicleWorkspace<Scalar>& ws,
                             vehicle::VehicleState<Scalar>& x, const Env& env, double t, double dt,
                             const vehicle::VehicleInputs<Scalar>& in, const Vector3<Scalar>& r,
                             const Vector3<Scalar>& f_ned,
                             const HullContact<Scalar>* hull = nullptr) {
  const PointLoad<Scalar> load{r, f_ned};
  return step_vehicle(model, ws, x, env, t, dt, in, &load, 1, hull);
}

/// One pass of a tether over a system step: tether::advance with `options`; when an implicit
/// scheme fails and `fallback` allows it, the same step redone by RK4 in sub-steps of the
/// line's stable explicit step (counted in `fallbacks`). Returns the committed advance's report.
/// (With a winch, segment 0 may be as short as r·l (r = remove_ratio): node 1's springs
/// EA/(r l) + EA/l over its mass μ(1 + r) l/2 give a frequency 1/√r times the uniform line's,
/// hence the factor √r on the stable step.)
template <typename Scalar, typename Env>
tether::StepReport<Scalar> advance_tether(const tether::TetherModel<Scalar>& line,
                                          const tether::WinchModel<Scalar>* winch,
                                          tether::TetherWorkspace<Scalar>& ws, const Env& env,
                                          tether::TetherState<Scalar>& state,
                                          const tether::TetherBoundary<Scalar>& ends, double dt,
                                          const tether::AdvanceOptions<Scalar>& options,
                                          bool fallback, int& fallbacks) {
  try {
    return tether::advance(line, ws, env, state, ends, dt, options);
  } catch (const kelp::numerical_error&) {
    // A line without a free node has no stable explicit step to redo it in (estimate_stable_dt
    // refuses it), nor anything an explicit scheme would do differently.
    if (!fallback || !tether::is_implicit(options.integrator) ||
        line.first_free_node() > line.last_free_node())
      throw;
    // The failed step left the tether as it was: redo it explicitly.
    using std::sqrt;
    const Scalar h =
        tether::estimate_stable_dt(line, tether::Integrator::rk4, env.water_density()) *
        (winch ? sqrt(winch->winch().remove_ratio) : Scalar(1));
    tether::AdvanceOptions<Scalar> explicit_options = options;
    explicit_options.max_dt = std::min(options.max_dt, double(value_of(h)));
    explicit_options.integrator = tether::Integrator::rk4;
    tether::StepReport<Scalar> r =
        tether::advance(line, ws, env, state, ends, dt, explicit_options);
    ++fallbacks;
    return r;
  }
}

/// A vehicle's propulsion over a step (none: its commands must be empty): advances `x` under
/// the commands `u` and adds the mean thrust's wrench to `in.tau`; `r` reports it.
template <typename Scalar>
void propel(const vehicle::PropulsionModel<Scalar>* m, vehicle::PropulsionState<Scalar>& x,
            const vehicle::ThrusterVector<Scalar>& u, vehicle::VehicleInputs<Scalar>& in,
            vehicle::PropulsionStep<Scalar>& r, double dt, const std::string& which,
            const char* state_name) {
  if (m == nullptr) {
    KELP_CHECK(u.size() == 0,
               "inputs." + which + "_commands: the system has no propulsion for the " + which);
    return;
  }
  vehicle::check_state(*m, x, state_name);
  r = vehicle::advance(*m, x, u, dt);
  in.tau += r.wrench;
}

/// The still water of `env` (its density, gravity and seabed; no waves, current or wind): where
/// an initial state's tethers find their static shape.
template <typename Scalar>
environment::Environment<Scalar> still_water(const environment::Environment<Scalar>& env) {
  environment::Environment<Scalar> still;
  still.set_water_density(env.water_density());
  still.set_gravity(env.gravity());
  still.set_seabed_depth(env.seabed_depth());
  return still;
}

/// An initial state's static tolerance unless `o` gives one: 1e-4 × the line's weight in air
/// (a neutrally buoyant slack line has no unique static shape, and a start state needs no more).
template <typename Scalar>
void default_static_tolerance(const tether::TetherModel<Scalar>& line,
                              const environment::Environment<Scalar>& env,
                              tether::StaticOptions<Scalar>& o) {
  if (o.force_tolerance > Scalar(0)) return;
  const tether::TetherParameters<Scalar>& tp = line.parameters();
  o.force_tolerance = Scalar(1e-4) * tp.mass_per_length * tp.length * Scalar(env.gravity());
}

/// The coupling corrector: end motion `m` keeps its start and reaches `target` after h.
template <typename Scalar>
void reach(tether::EndMotion<Scalar>& m, const Vector3<Scalar>& target, const Scalar& h) {
  m.acceleration = Scalar(2) * (target - m.position - h * m.velocity) / (h * h);
}

/// The small parts of a state (all but the tether), saved to restore after a failed step.
template <typename Scalar>
struct CouplingSnapshot {
  vehicle::VehicleState<Scalar> asv, auv;
  Vector6<Scalar> asv_nu_dot, auv_nu_dot;

  explicit CouplingSnapshot(const SystemState<Scalar>& s)
      : asv(s.asv), auv(s.auv), asv_nu_dot(s.asv_nu_dot), auv_nu_dot(s.auv_nu_dot) {}
  void restore(SystemState<Scalar>& s) const {
    s.asv = asv;
    s.auv = auv;
    s.asv_nu_dot = asv_nu_dot;
    s.auv_nu_dot = auv_nu_dot;
  }
};

}  // namespace detail

/// \brief Advances the whole system by `dt` [s] (see the file's coupling scheme). No heap
/// allocation.
/// \param[in] model the system (its environment included). \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock and its parts' clocks too).
/// \param[in] inputs the vehicles' wrenches. \param[in] dt step [s], > 0.
/// \param[in] options what else to compute (SystemStepOptions::with_energy).
/// \returns the tether's integration report and the forces applied to the vehicles.
/// \throws kelp::invalid_argument for bad input (dt, non-finite inputs or vehicle states, a
/// non-unit attitude, a workspace not built for the model, parts' clocks that differ from
/// `state.time`); kelp::numerical_error when a part
/// cannot be advanced. After any throw every part of `state` is bit-identical to
/// what it was.
template <typename Scalar>
SystemReport<Scalar> step(const SystemModel<Scalar>& model, SystemWorkspace<Scalar>& ws,
                          SystemState<Scalar>& state, const SystemInputs<Scalar>& inputs, double dt,
                          SystemStepOptions options = {}) {
  check_positive(dt, "dt");
  check_all_finite(inputs.asv.tau, "inputs.asv.tau");
  check_all_finite(inputs.asv.tau_ext, "inputs.asv.tau_ext");
  check_all_finite(inputs.auv.tau, "inputs.auv.tau");
  check_all_finite(inputs.auv.tau_ext, "inputs.auv.tau_ext");
  check_finite(state.time, "state.time");
  KELP_CHECK(state.asv.time == state.time && state.auv.time == state.time &&
                 state.tether.time == state.time,
             "state.asv.time, state.auv.time and state.tether.time must equal state.time (use "
             "SystemState::set_time to set every clock)");
  KELP_CHECK(model.winch() == nullptr || ws.winch,
             "workspace was built for a different system (it has no winch buffers)");
  KELP_CHECK(model.winch() != nullptr || inputs.winch_payout_rate == Scalar(0),
             "inputs.winch_payout_rate must be 0: the system has no winch");
  check_finite(inputs.winch_payout_rate, "inputs.winch_payout_rate");
  const tether::TetherModel<Scalar>& line = model.tether_of(state);
  KELP_CHECK(ws.tether.fits(line.nodes()),
             ws.winch ? "workspace holds the tether buffers of another node count than the "
                        "state's: call system::fit_workspace(model, ws, state) first (a state "
                        "loaded or restored at another count)"
                      : "workspace was built for a different system");
  vehicle::detail::check_state(state.asv);
  vehicle::detail::check_state(state.auv);
  check_all_finite(state.asv_nu_dot, "state.asv_nu_dot");
  check_all_finite(state.auv_nu_dot, "state.auv_nu_dot");
  // Propulsion first, on copies committed with the rest (no heap: fixed-capacity vectors).
  vehicle::VehicleInputs<Scalar> asv_in = inputs.asv, auv_in = inputs.auv;
  vehicle::PropulsionState<Scalar> asv_prop = state.asv_propulsion;
  vehicle::PropulsionState<Scalar> auv_prop = state.auv_propulsion;
  SystemReport<Scalar> report;
  detail::propel(model.asv_propulsion(), asv_prop, inputs.asv_commands, asv_in,
                 report.asv_propulsion, dt, "asv", "state.asv_propulsion");
  detail::propel(model.auv_propulsion(), auv_prop, inputs.auv_commands, auv_in,
                 report.auv_propulsion, dt, "auv", "state.auv_propulsion");
  const SystemParameters<Scalar>& p = model.parameters();
  const auto& env = model.environment();
  const double t = state.time;
  tether::AdvanceOptions<Scalar> tether_options;
  tether_options.max_dt = p.max_tether_dt;
  tether_options.integrator = p.tether_integrator;
  tether_options.implicit = p.tether_options;
  // Everything a failure must restore.
  const detail::CouplingSnapshot<Scalar> before(state);
  // (With a winch, the backup buffers of the state's node count: no allocation.)
  tether::StateBackup<Scalar>& backup =
      ws.winch ? ws.winch->backup[ws.winch->slot(line.segments())] : ws.tether_backup;
  backup.save(state.tether);
  try {
    tether::TetherBoundary<Scalar> ends;
    ends.start = detail::predicted_end(state.asv, state.asv_nu_dot, p.asv_attachment);
    ends.end = detail::predicted_end(state.auv, state.auv_nu_dot, p.auv_attachment);
    // The line's partings of the committed (last) coupling pass: an earlier pass's are undone
    // with its tether state.
    tether::StepReport<Scalar> pass_report;
    for (int pass = 0;; ++pass) {
      pass_report =
          detail::advance_tether(line, model.winch(), ws.tether, env, state.tether, ends, dt,
                                 tether_options, p.explicit_fallback, report.tether_fallbacks);
      report.tether += pass_report;
      // The impulse the tether's integrator delivered to its ends, as a mean force.
      report.force_on_asv = ws.tether.end_impulse.on_start / Scalar(dt);
      report.force_on_auv = ws.tether.end_impulse.on_end / Scalar(dt);
      state.asv_nu_dot =
          detail::step_vehicle(model.asv(), ws.asv, state.asv, env, t, dt, asv_in, p.asv_attachment,
                               report.force_on_asv, p.asv_hull ? &*p.asv_hull : nullptr);
      state.auv_nu_dot =
          detail::step_vehicle(model.auv(), ws.auv, state.auv, env, t, dt, auv_in, p.auv_attachment,
                               report.force_on_auv, p.auv_hull ? &*p.auv_hull : nullptr);
      if (pass >= p.coupling_corrections) break;
      // Corrector: the end paths that start as before and reach the actual attachment points.
      detail::reach(ends.start, state.asv.point_position(p.asv_attachment), Scalar(dt));
      detail::reach(ends.end, state.auv.point_position(p.auv_attachment), Scalar(dt));
      backup.restore(state.tether);
      state.asv = before.asv;
      state.auv = before.auv;
    }
    report.tether.partings = pass_report.partings;
    report.tether.failure = pass_report.failure;
  } catch (const kelp::error&) {
    before.restore(state);
    backup.restore(state.tether);
    throw;
  }
  // The winch, between this step and the next (it cannot fail: its inputs were checked, the
  // state's winch length and payout rate by the tether's step).
  if (model.winch())
    report.remesh = tether::advance_winch(*model.winch(), *ws.winch, state.tether, ws.tether,
                                          inputs.winch_payout_rate, dt);
  // The clocks in lock-step: the tether's (Kahan-summed over its sub-steps) is the system's.
  state.time = state.tether.time;
  state.asv.time = state.time;
  state.auv.time = state.time;
  state.asv_propulsion = asv_prop;
  state.auv_propulsion = auv_prop;
  if (p.asv_hull) report.asv_contact = hull_contact(*p.asv_hull, env, state.asv);
  if (p.auv_hull) report.auv_contact = hull_contact(*p.auv_hull, env, state.auv);
  if (options.with_energy) report.energy = energy(model, state);
  return report;
}

/// \brief A system state with the vehicles at `asv` and `auv` and the tether at its static
/// equilibrium between their attachment points in still water (its own weight, buoyancy and
/// elasticity; waves and current are left to the first steps), at rest, at time `t` [s].
/// Unless `options` says otherwise, the static solve stops at a residual of 1e-4 × the line's
/// weight in air (a neutrally buoyant slack line has no unique static shape, and a start state
/// needs no more).
/// \throws kelp::invalid_argument for bad vehicle states; kelp::numerical_error when the tether's
/// static solve does not converge.
/// \param model the system. \param ws its workspace (the static solve's buffers).
/// \param asv the surface vehicle's state (NED pose, body velocity), copied as given.
/// \param auv the underwater vehicle's state, likewise. \param t the start time [s].
/// \param options the tether's static solve (tolerance, iterations).
/// \return the state, every part's clock at `t`.
template <typename Scalar>
SystemState<Scalar> initial_state(const SystemModel<Scalar>& model, SystemWorkspace<Scalar>& ws,
                                  const vehicle::VehicleState<Scalar>& asv,
                                  const vehicle::VehicleState<Scalar>& auv, double t = 0.0,
                                  tether::StaticOptions<Scalar> options = {}) {
  vehicle::detail::check_state(asv);
  vehicle::detail::check_state(auv);
  SystemState<Scalar> s;
  s.asv = asv;
  s.auv = auv;
  const Vector3<Scalar> a = asv.point_position(model.parameters().asv_attachment);
  const Vector3<Scalar> b = auv.point_position(model.parameters().auv_attachment);
  const environment::Environment<Scalar> still = detail::still_water(model.environment());
  detail::default_static_tolerance(model.tether(), still, options);
  const tether::StaticResult<Scalar> r =
      tether::static_initial_state(model.tether(), ws.tether, still, a, b, s.tether, options);
  if (!r.converged)
    ::kelp::detail::throw_numerical_error(
        "system::initial_state: the tether's static shape did not converge (residual " +
        std::to_string(double(value_of(r.residual))) + " N)");
  if (model.asv_propulsion()) s.asv_propulsion = vehicle::initial_state(*model.asv_propulsion());
  if (model.auv_propulsion()) s.auv_propulsion = vehicle::initial_state(*model.auv_propulsion());
  s.set_time(t);
  return s;
}

using SystemParametersd = SystemParameters<double>;  ///< SystemParameters<double>
using SystemModeld = SystemModel<double>;            ///< SystemModel<double>
using SystemStated = SystemState<double>;            ///< SystemState<double>
using SystemWorkspaced = SystemWorkspace<double>;    ///< SystemWorkspace<double>
using SystemInputsd = SystemInputs<double>;          ///< SystemInputs<double>
using SystemReportd = SystemReport<double>;          ///< SystemReport<double>
using SystemEnergyd = SystemEnergy<double>;          ///< SystemEnergy<double>
using SystemParametersf = SystemParameters<float>;   ///< SystemParameters<float>
using SystemModelf = SystemModel<float>;             ///< SystemModel<float>
using SystemStatef = SystemState<float>;             ///< SystemState<float>
using SystemWorkspacef = SystemWorkspace<float>;     ///< SystemWorkspace<float>
using SystemInputsf = SystemInputs<float>;           ///< SystemInputs<float>
using SystemReportf = SystemReport<float>;           ///< SystemReport<float>
using SystemEnergyf = SystemEnergy<float>;           ///< SystemEnergy<float>

}  // namespace kelp::system

/// \brief The double-precision system step, initial state and energy, for a compiled layer that
/// instantiates them once: `KELP_SYSTEM_INSTANCES(template)` in one unit,
/// `KELP_SYSTEM_INSTANCES(extern template)` wherever they are called (kelp::sim does:
/// kelp/sim/instantiation.hpp). `prefix` may carry attributes after `template`.
#define KELP_SYSTEM_INSTANCES(prefix)                                                         \
  prefix kelp::system::SystemReport<double> kelp::system::step<double>(                       \
      const kelp::system::SystemModel<double>&, kelp::system::SystemWorkspace<double>&,       \
      kelp::system::SystemState<double>&, const kelp::system::SystemInputs<double>&, double,  \
      kelp::system::SystemStepOptions);                                                       \
  prefix kelp::system::SystemState<double> kelp::system::initial_state<double>(               \
      const kelp::system::SystemModel<double>&, kelp::system::SystemWorkspace<double>&,       \
      const kelp::vehicle::VehicleState<double>&, const kelp::vehicle::VehicleState<double>&, \
      double, kelp::tether::StaticOptions<double>);                                           \
  prefix kelp::system::SystemEnergy<double> kelp::system::energy<double>(                     \
      const kelp::system::SystemModel<double>&, const kelp::system::SystemState<double>&);
