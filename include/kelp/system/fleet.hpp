/// \file
/// \brief Any tethered fleet: N vehicles, P free point masses and M tethers, each tether's ends
/// on a vehicle point, a fixed anchor, a point mass or hanging free, advanced together in one
/// environment by one `step`.
///
/// The tethered pair (kelp/system/system.hpp) is one such graph: fleet_of() turns its parameters
/// into a fleet, and the fleet's step reproduces the pair's bit for bit (same operations in the
/// same order). Other graphs: ship → umbilical → tether management system (a vehicle of its own,
/// with a winch on its tether) → tether → ROV; one boat with two ROVs; two ROVs joined by a
/// tether; a ROV tethered to a fixed dock; a clump weight (a point mass) between two lines.
///
/// **Coupling scheme**: the pair's (see system.hpp), for every tether at once. One step of h:
/// 1. each vehicle's propulsion is advanced under its commands (vehicle::advance);
/// 2. each tether end's motion over the step is predicted: a vehicle point's or a point mass's
///    from its state and its last acceleration (p + v τ + ½ a τ²), an anchor's as fixed; a
///    free end is the tether's own (EndMode::free, with its end point mass);
/// 3. each tether is advanced over the step with its ends on those paths (its own sub-steps;
///    implicit schemes retry in shorter ones, with FleetParameters::explicit_fallback as in the
///    pair), and delivers an impulse to each end (TetherWorkspace::end_impulse);
/// 4. each vehicle is advanced by RK4 under its inputs and the impulses of every tether end on
///    it, as constant NED forces at their attachment points (summed in tether order); each
///    point mass by RK4 under its weight, buoyancy, added mass, drag and the impulses on it.
/// The bodies receive exactly the impulses the tether ends delivered, so momentum is balanced
/// whatever the integrators; FleetParameters::coupling_corrections = k > 0 redoes steps 3–4
/// k times with the ends on the paths that reach the bodies' actual end points, which makes
/// the exchange of work exact up to the fixed point's convergence (tests: a vehicle – tether –
/// point mass – tether – vehicle chain keeps its momentum and, undamped, its energy).
///
/// A point mass must be heavy enough for the partitioned coupling: like a vehicle, it is
/// advanced explicitly under the force its tethers' ends delivered over the step, which is
/// stable while its mass (added mass included) is large against the end nodes' and the lines'
/// stiffness times h² (a clump weight, a TMS modelled as a mass; not a bead on a line: make
/// that a node of the line).
///
/// **Winches**: a tether may have a winch at its start end (FleetTether::winch; on a vehicle,
/// an anchor or a point mass), commanded by FleetInputs::winch_payout_rates; its node count
/// then changes between steps (FleetModel::tether_of), with every count's buffers built with
/// the workspace, so a step allocates nothing.
///
/// A step allocates nothing: the per-part results are written into the workspace's report
/// (FleetWorkspace::report, returned by reference), whose vectors are sized at construction.
/// A step that cannot be completed throws with every part of the state as it was.
#pragma once

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "kelp/system/fleet_parameters.hpp"
#include "kelp/system/system.hpp"

namespace kelp::system {

/// \brief A fleet built once from FleetParameters and an environment (copied: the one source
/// of water density and gravity; every vehicle is checked against it).
/// \throws kelp::invalid_argument naming the part.
/// \tparam Scalar double or float.
template <typename Scalar>
class FleetModel {
 public:
  /// \brief Validates the parameters and builds every part's model.
  /// \param p The fleet's parameters (copied).
  /// \param env The environment (copied); every vehicle's water density and gravity must be its.
  /// \throws kelp::invalid_argument naming the part (see validate(const
  /// FleetParameters<Scalar>&)), or the vehicle whose water differs from the environment's.
  FleetModel(const FleetParameters<Scalar>& p, const environment::Environment<Scalar>& env)
      : parameters_((validate(p), p)), environment_(env) {
    vehicles_.reserve(p.vehicles.size());
    propulsion_.resize(p.vehicles.size());
    loads_.resize(p.vehicles.size());
    for (std::size_t i = 0; i < p.vehicles.size(); ++i) {
      vehicles_.emplace_back(p.vehicles[i].parameters);
      vehicle::check_same_water(vehicles_.back(), environment_, p.vehicles[i].name);
      if (p.vehicles[i].propulsion) propulsion_[i].emplace(*p.vehicles[i].propulsion);
    }
    tethers_.reserve(p.tethers.size());
    winches_.resize(p.tethers.size());
    for (std::size_t k = 0; k < p.tethers.size(); ++k) {
      const tether::TetherParameters<Scalar> line = detail::line_of(p.tethers[k]);
      tethers_.emplace_back(line);
      if (p.tethers[k].winch) winches_[k].emplace(line, *p.tethers[k].winch);
      for (const TetherEnd<Scalar>* e : {&p.tethers[k].start, &p.tethers[k].end})
        if (e->kind == EndKind::vehicle) ++loads_[std::size_t(e->index)];
    }
  }
  /// \brief The parameters the fleet was built from.
  /// \return The parameters, as given (the tethers' end modes not yet set from their ends).
  const FleetParameters<Scalar>& parameters() const { return parameters_; }
  /// \brief The environment the fleet steps in.
  /// \return The environment (the last one set).
  const environment::Environment<Scalar>& environment() const { return environment_; }
  /// \brief Replaces the environment between steps (as SystemModel::set_environment).
  /// \param env The new environment (copied); same water density and gravity as the vehicles'.
  /// \throws kelp::invalid_argument naming the vehicle whose water differs (strong guarantee).
  void set_environment(const environment::Environment<Scalar>& env) {
    for (std::size_t i = 0; i < vehicles_.size(); ++i)
      vehicle::check_same_water(vehicles_[i], env, parameters_.vehicles[i].name);
    environment::Environment<Scalar> copy(env);
    environment_ = std::move(copy);
  }
  /// \brief The number of vehicles.
  /// \return N.
  int vehicle_count() const { return int(vehicles_.size()); }
  /// \brief The number of point masses.
  /// \return P.
  int point_mass_count() const { return int(parameters_.point_masses.size()); }
  /// \brief The number of tethers.
  /// \return M.
  int tether_count() const { return int(tethers_.size()); }
  /// \brief Vehicle i's model.
  /// \param i Vehicle index in [0, N) (not checked).
  /// \return Its model.
  const vehicle::VehicleModel<Scalar>& vehicle(int i) const { return vehicles_[std::size_t(i)]; }
  /// \brief Vehicle i's propulsion, or null.
  /// \param i Vehicle index in [0, N) (not checked).
  /// \return Its propulsion model, or nullptr without one.
  const vehicle::PropulsionModel<Scalar>* propulsion(int i) const {
    const auto& p = propulsion_[std::size_t(i)];
    return p ? &*p : nullptr;
  }
  /// \brief Vehicle i's hull, or null.
  /// \param i Vehicle index in [0, N) (not checked).
  /// \return Its hull contact, or nullptr without one.
  const HullContact<Scalar>* hull(int i) const {
    const auto& h = parameters_.vehicles[std::size_t(i)].hull;
    return h ? &*h : nullptr;
  }
  /// \brief Tether k's line at its initial node count.
  /// \param k Tether index in [0, M) (not checked).
  /// \return Its line model (end modes set from its ends).
  const tether::TetherModel<Scalar>& tether(int k) const { return tethers_[std::size_t(k)]; }
  /// \brief Tether k's winch, or null.
  /// \param k Tether index in [0, M) (not checked).
  /// \return Its winch model, or nullptr without one.
  const tether::WinchModel<Scalar>* winch(int k) const {
    const auto& w = winches_[std::size_t(k)];
    return w ? &*w : nullptr;
  }
  /// \brief Tether k's line model for its state (its winch's line at the state's node count).
  /// \param k Tether index in [0, M) (not checked).
  /// \param s The tether's state.
  /// \return tether(k) without a winch, else the winch's line of s's node count.
  const tether::TetherModel<Scalar>& tether_of(int k, const tether::TetherState<Scalar>& s) const {
    const auto* w = winch(k);
    return w ? w->line_of(s) : tether(k);
  }
  /// \brief The number of tether ends on vehicle i.
  /// \param i Vehicle index in [0, N) (not checked).
  /// \return The count (a tether with both ends on i counts twice).
  int loads_on(int i) const { return loads_[std::size_t(i)]; }
  /// \brief The index of the vehicle called `name`, or −1.
  /// \param name The vehicle's name (FleetVehicle::name).
  /// \return Its index in FleetParameters::vehicles, or −1.
  int vehicle_index(const std::string& name) const { return find(parameters_.vehicles, name); }
  /// \brief The index of the point mass called `name`, or −1.
  /// \param name The point mass's name (PointMassParameters::name).
  /// \return Its index in FleetParameters::point_masses, or −1.
  int point_mass_index(const std::string& name) const {
    return find(parameters_.point_masses, name);
  }
  /// \brief The index of the tether called `name`, or −1.
  /// \param name The tether's name (FleetTether::name).
  /// \return Its index in FleetParameters::tethers, or −1.
  int tether_index(const std::string& name) const { return find(parameters_.tethers, name); }

 private:
  template <typename V>
  static int find(const V& v, const std::string& name) {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i].name == name) return int(i);
    return -1;
  }
  FleetParameters<Scalar> parameters_;
  environment::Environment<Scalar> environment_;
  std::vector<vehicle::VehicleModel<Scalar>> vehicles_;
  std::vector<std::optional<vehicle::PropulsionModel<Scalar>>> propulsion_;
  std::vector<int> loads_;
  std::vector<tether::TetherModel<Scalar>> tethers_;
  std::vector<std::optional<tether::WinchModel<Scalar>>> winches_;
};

/// \brief Everything that determines a fleet's next step: the clock, every part's state (the
/// parts' own clocks equal `time`), and the coupling's memory (last accelerations).
template <typename Scalar>
struct FleetState {
  double time = 0.0;                                    ///< [s]
  std::vector<vehicle::VehicleState<Scalar>> vehicles;  ///< per vehicle (body frame at its CO)
  /// Last body accelerations ν̇ per vehicle: the predictor of its attachment points' motion.
  std::vector<Vector6<Scalar>> vehicle_nu_dot;
  /// Per vehicle: thrusters and battery (empty state without propulsion).
  std::vector<vehicle::PropulsionState<Scalar>> propulsion;
  std::vector<PointMassState<Scalar>> point_masses;  ///< per point mass
  /// Last NED accelerations per point mass: the predictor of its motion.
  std::vector<Vector3<Scalar>> point_mass_acceleration;
  std::vector<tether::TetherState<Scalar>> tethers;  ///< per tether, with integrator history

  /// \brief Sets every clock to `t` [s].
  /// \param t Time [s]: the fleet's, each vehicle's and each tether's (its time carry reset).
  void set_time(double t) {
    time = t;
    for (auto& v : vehicles) v.time = t;
    for (auto& l : tethers) {
      l.time = t;
      l.time_carry = 0.0;
    }
  }
  /// \brief Forgets the coupling's memory (call it after editing states by hand).
  void reset_coupling() {
    for (auto& a : vehicle_nu_dot) a.setZero();
    for (auto& a : point_mass_acceleration) a.setZero();
  }
};

/// \brief The inputs of one fleet step, sized for a model by its constructor.
template <typename Scalar>
struct FleetInputs {
  /// Per vehicle: τ (control) and τ_ext (other external wrench), body axes [N, N m].
  std::vector<vehicle::VehicleInputs<Scalar>> vehicles;
  /// Per vehicle with propulsion: its thrusters' commands u ∈ [−1, 1]; empty: all 0 (and must be
  /// empty without propulsion).
  std::vector<vehicle::ThrusterVector<Scalar>> commands;
  /// Per tether: its winch's commanded payout rate [m/s] (0 without a winch).
  std::vector<Scalar> winch_payout_rates;

  /// \brief No parts (sized for an empty fleet).
  FleetInputs() = default;
  /// \brief All zero, sized for `model`.
  /// \param model The fleet: one entry per vehicle in `vehicles` and `commands` (commands empty,
  /// i.e. all 0) and one payout rate per tether.
  explicit FleetInputs(const FleetModel<Scalar>& model)
      : vehicles(std::size_t(model.vehicle_count())),
        commands(std::size_t(model.vehicle_count())),
        winch_payout_rates(std::size_t(model.tether_count()), Scalar(0)) {}
};

/// \brief The mechanical energy of a fleet [J], part by part (as SystemEnergy).
template <typename Scalar>
struct FleetEnergy {
  std::vector<Scalar> vehicles;      ///< kinetic + hydrostatic potential (vehicle::energy)
  std::vector<Scalar> point_masses;  ///< ½ (m + φ C_a ρ V) |v|² + weight and buoyancy potential
  std::vector<Scalar> tethers;       ///< kinetic + elastic + weight and buoyancy (tether_energy)
  /// \brief The sum of the parts.
  /// \return Σ vehicles + Σ point_masses + Σ tethers [J].
  Scalar total() const {
    Scalar s(0);
    for (const auto* v : {&vehicles, &point_masses, &tethers})
      for (const Scalar& e : *v) s += e;
    return s;
  }
};

/// \brief What one fleet step did; sized once (FleetWorkspace::report) and refilled by each
/// step, so that stepping allocates nothing.
template <typename Scalar>
struct FleetReport {
  /// Every tether's integration report, summed (sub-steps, Newton iterations, worst residual,
  /// retries); its `partings` and `failure` are the committed pass's, over all tethers.
  tether::StepReport<Scalar> tether;
  /// Per tether: its own report (committed pass's partings and failure).
  std::vector<tether::StepReport<Scalar>> tethers;
  /// Per tether: the force its start end delivered to what holds it over the step, NED [N]
  /// (impulse / dt; on an anchor: the anchor's load; zero at a free end).
  std::vector<Vector3<Scalar>> force_at_start;
  std::vector<Vector3<Scalar>> force_at_end;  ///< per tether, at its end; see force_at_start
  std::vector<vehicle::PropulsionStep<Scalar>> propulsion;  ///< per vehicle (zero without)
  std::vector<tether::RemeshReport<Scalar>> remesh;         ///< per tether (zero without winch)
  std::vector<HullContactLoad<Scalar>> contact;  ///< per vehicle, at the end (zero without hull)
  FleetEnergy<Scalar> energy;  ///< after the step, when asked for (SystemStepOptions)
  int tether_fallbacks = 0;    ///< tether steps redone explicitly

  /// \brief An empty report (no parts).
  FleetReport() = default;
  /// \brief Sized for `model`.
  /// \param model The fleet: one entry per vehicle or tether in each per-part vector, all zero.
  explicit FleetReport(const FleetModel<Scalar>& model) {
    const auto n = std::size_t(model.vehicle_count()), m = std::size_t(model.tether_count());
    tethers.resize(m);
    force_at_start.assign(m, Vector3<Scalar>::Zero());
    force_at_end.assign(m, Vector3<Scalar>::Zero());
    propulsion.resize(n);
    remesh.resize(m);
    contact.resize(n);
    energy.vehicles.assign(n, Scalar(0));
    energy.point_masses.assign(std::size_t(model.point_mass_count()), Scalar(0));
    energy.tethers.assign(m, Scalar(0));
  }
};

/// \brief The buffers of one tether of a fleet.
template <typename Scalar>
struct FleetTetherWorkspace {
  tether::TetherWorkspace<Scalar> tether;  ///< the line's buffers (the current node count's)
  tether::StateBackup<Scalar> backup;      ///< the state at the start of a step
  std::optional<tether::WinchWorkspace<Scalar>> winch;  ///< with a winch: every count's buffers
  /// \brief The backup of the state's node count.
  /// \param line The line model of the state's node count (FleetModel::tether_of).
  /// \return `backup` without a winch, else the winch's backup of that count.
  tether::StateBackup<Scalar>& backup_of(const tether::TetherModel<Scalar>& line) {
    return winch ? winch->backup[winch->slot(line.segments())] : backup;
  }
};

/// \brief Preallocated buffers of a fleet step (and its report).
template <typename Scalar>
struct FleetWorkspace {
  std::vector<vehicle::VehicleWorkspace<Scalar>> vehicles;  ///< per vehicle
  std::vector<FleetTetherWorkspace<Scalar>> tethers;        ///< per tether
  FleetReport<Scalar> report;                               ///< the last step's report
  // The step's scratch: inputs after propulsion, a failed step's restore copies, the tether
  // forces on each vehicle and point mass.
  /// Per vehicle: the step's inputs, the propulsion's mean wrench added to τ [N, N m] (body).
  std::vector<vehicle::VehicleInputs<Scalar>> inputs;
  /// Per vehicle: a copy of its propulsion state advanced over the step, committed to the state
  /// only when the whole step succeeds.
  std::vector<vehicle::PropulsionState<Scalar>> propulsion;
  /// Per vehicle: its state at the start of the step (restored after a throw).
  std::vector<vehicle::VehicleState<Scalar>> vehicles_before;
  std::vector<Vector6<Scalar>> nu_dot_before;  ///< per vehicle: ν̇ at the start of the step
  std::vector<PointMassState<Scalar>> masses_before;  ///< per point mass: state at the start
  /// Per point mass: its acceleration at the start of the step [m/s²].
  std::vector<Vector3<Scalar>> mass_acceleration_before;
  std::vector<tether::TetherBoundary<Scalar>> ends;  ///< per tether: its ends' predicted motion
  std::vector<std::vector<detail::PointLoad<Scalar>>>
      loads;                                 ///< per vehicle, one per tether end on it
  std::vector<Vector3<Scalar>> mass_forces;  ///< per point mass, NED [N]

  /// \brief Empty buffers (for an empty fleet; assign a sized workspace before stepping).
  FleetWorkspace() = default;
  /// \brief Buffers for `model` (allocates; a step then allocates nothing).
  /// \param model The fleet (its winches' buffers for every node count are built too).
  explicit FleetWorkspace(const FleetModel<Scalar>& model) : report(model) {
    const auto n = std::size_t(model.vehicle_count()), m = std::size_t(model.tether_count());
    const auto pm = std::size_t(model.point_mass_count());
    vehicles.resize(n);
    tethers.resize(m);
    for (std::size_t k = 0; k < m; ++k) {
      tethers[k].tether = tether::TetherWorkspace<Scalar>(model.tether(int(k)));
      tethers[k].backup.resize(model.tether(int(k)).nodes());
      if (model.winch(int(k))) tethers[k].winch.emplace(*model.winch(int(k)));
    }
    inputs.resize(n);
    propulsion.resize(n);
    vehicles_before.resize(n);
    nu_dot_before.resize(n);
    masses_before.resize(pm);
    mass_acceleration_before.resize(pm);
    ends.resize(m);
    loads.resize(n);
    for (std::size_t i = 0; i < n; ++i) loads[i].resize(std::size_t(model.loads_on(int(i))));
    mass_forces.resize(pm);
  }
  /// \brief Whether the buffers were built for `model`.
  /// \param model A fleet.
  /// \return True when the counts of vehicles, tethers, point masses, ends per vehicle and
  /// winches match.
  bool fits(const FleetModel<Scalar>& model) const {
    if (vehicles.size() != std::size_t(model.vehicle_count()) ||
        tethers.size() != std::size_t(model.tether_count()) ||
        mass_forces.size() != std::size_t(model.point_mass_count()))
      return false;
    for (std::size_t i = 0; i < loads.size(); ++i)
      if (loads[i].size() != std::size_t(model.loads_on(int(i)))) return false;
    for (std::size_t k = 0; k < tethers.size(); ++k)
      if (bool(tethers[k].winch) != (model.winch(int(k)) != nullptr)) return false;
    return true;
  }
};

/// \brief Readies `ws` for stepping `state` when the workspace last stepped another state: each
/// tether with a winch whose node count in `state` is not the one the workspace holds gets that
/// count's buffers (as the pair's fit_workspace, system.hpp). Call it between steps: it may
/// allocate (once).
/// \throws kelp::invalid_argument when the workspace or the state is not sized for the fleet
/// or a tether's node count is outside its winch's range.
/// \tparam Scalar double or float.
/// \param model The fleet.
/// \param[in,out] ws Its workspace.
/// \param state The state to be stepped next.
template <typename Scalar>
void fit_workspace(const FleetModel<Scalar>& model, FleetWorkspace<Scalar>& ws,
                   const FleetState<Scalar>& state) {
  KELP_CHECK(ws.fits(model), "workspace was built for a different fleet");
  KELP_CHECK(state.tethers.size() == std::size_t(model.tether_count()),
             "state must be sized for the fleet (initial_state(model, ...))");
  for (std::size_t k = 0; k < state.tethers.size(); ++k) {
    const tether::WinchModel<Scalar>* w = model.winch(int(k));
    const int nodes = int(state.tethers[k].position.cols());
    if (w == nullptr || ws.tethers[k].tether.fits(nodes)) continue;
    ws.tethers[k].winch->lend(*w, ws.tethers[k].tether, nodes - 1);
  }
}

namespace detail {

/// Sphere of volume V: radius, and its submerged volume and volume integral at centre depth d
/// (d > 0 below the surface). V_sub(d) = π h² (3R − h)/3 with h = clamp(d + R, 0, 2R), and
/// Φ(d) = ∫_{−R}^{d} V_sub = π (R h³/3 − h⁴/12) for |d| < R, V d above (so that d ≥ R gives V d).
template <typename Scalar>
struct SphereWetness {
  Scalar volume = Scalar(0);    ///< V_sub [m³]
  Scalar integral = Scalar(0);  ///< Φ [m⁴]
};
template <typename Scalar>
SphereWetness<Scalar> sphere_wetness(const Scalar& V, const Scalar& d) {
  using std::cbrt;
  SphereWetness<Scalar> w;
  if (!(V > Scalar(0))) return w;
  const Scalar pi(3.14159265358979323846);
  const Scalar R = cbrt(Scalar(3) * V / (Scalar(4) * pi));
  if (d >= R) {
    w.volume = V;
    w.integral = V * d;
  } else if (d > -R) {
    const Scalar h = d + R;
    w.volume = pi * h * h * (Scalar(3) * R - h) / Scalar(3);
    w.integral = pi * (R * h * h * h / Scalar(3) - h * h * h * h / Scalar(12));
  }
  return w;
}

/// The sampled water at a point mass: velocity, material acceleration, surface elevation.
template <typename Scalar>
struct PointWater {
  Vector3<Scalar> velocity = Vector3<Scalar>::Zero();
  Vector3<Scalar> acceleration = Vector3<Scalar>::Zero();
  Scalar elevation = Scalar(0);
};
template <typename Scalar, typename Env>
PointWater<Scalar> point_water(const Env& env, const Vector3<Scalar>& p, double t) {
  const auto e = vehicle::detail::sample(env, p, t, false);
  PointWater<Scalar> w;
  w.velocity = e.current + e.wave_velocity;
  w.acceleration = vehicle::detail::material_acceleration<Scalar>(e);
  w.elevation = e.surface_elevation;
  return w;
}

/// Acceleration of a point mass at (p, v) in water `w` under the constant NED force `f`:
/// (m + C_a ρ V_s) a = (m g − ρ g V_s) e_z + ρ V_s (1 + C_a) a_w + ½ ρ C_d A φ |u| u + f,
/// u = v_w − v, V_s its submerged volume (sphere), φ = V_s / V.
template <typename Scalar>
Vector3<Scalar> point_mass_acceleration(const PointMassParameters<Scalar>& p, Scalar rho, Scalar g,
                                        const Vector3<Scalar>& x, const Vector3<Scalar>& v,
                                        const PointWater<Scalar>& w, const Vector3<Scalar>& f) {
  using std::sqrt;
  const Scalar vs = sphere_wetness(p.volume, x.z() + w.elevation).volume;
  const Vector3<Scalar> u = w.velocity - v;
  Vector3<Scalar> force = f + (rho * vs * (Scalar(1) + p.added_mass_coefficient)) * w.acceleration;
  force.z() += (p.mass - rho * vs) * g;
  if (p.drag_area > Scalar(0) && p.volume > Scalar(0))
    force += (Scalar(0.5) * rho * p.drag_area * (vs / p.volume) * sqrt(u.squaredNorm())) * u;
  return force / (p.mass + p.added_mass_coefficient * rho * vs);
}

/// One RK4 step of a point mass under the constant NED force `f`, the water sampled at its
/// position at t and its predicted one at t + h and taken linearly in time between (as the
/// vehicles'). Returns the last stage's acceleration; commits only a finite state.
template <typename Scalar, typename Env>
Vector3<Scalar> step_point_mass(const PointMassParameters<Scalar>& p, PointMassState<Scalar>& x,
                                const Env& env, double t, double dt, const Vector3<Scalar>& f) {
  const Scalar rho = Scalar(env.water_density()), g = Scalar(env.gravity()), h(dt);
  const PointWater<Scalar> w0 = point_water(env, x.position, t);
  const PointWater<Scalar> w1 = point_water<Scalar>(env, x.position + x.velocity * h, t + dt);
  const auto water = [&](Scalar c) {
    PointWater<Scalar> w;
    w.velocity = w0.velocity + c * (w1.velocity - w0.velocity);
    w.acceleration = w0.acceleration + c * (w1.acceleration - w0.acceleration);
    w.elevation = w0.elevation + c * (w1.elevation - w0.elevation);
    return w;
  };
  const auto acc = [&](const Vector3<Scalar>& q, const Vector3<Scalar>& v, Scalar c) {
    return point_mass_acceleration(p, rho, g, q, v, water(c), f);
  };
  const Scalar half = Scalar(0.5) * h;
  const Vector3<Scalar> a1 = acc(x.position, x.velocity, Scalar(0));
  const Vector3<Scalar> v2 = x.velocity + half * a1;
  const Vector3<Scalar> a2 = acc(x.position + half * x.velocity, v2, Scalar(0.5));
  const Vector3<Scalar> v3 = x.velocity + half * a2;
  const Vector3<Scalar> a3 = acc(x.position + half * v2, v3, Scalar(0.5));
  const Vector3<Scalar> v4 = x.velocity + h * a3;
  const Vector3<Scalar> a4 = acc(x.position + h * v3, v4, Scalar(1));
  PointMassState<Scalar> next;
  next.position = x.position + (h / Scalar(6)) * (x.velocity + Scalar(2) * (v2 + v3) + v4);
  next.velocity = x.velocity + (h / Scalar(6)) * (a1 + Scalar(2) * (a2 + a3) + a4);
  if (!next.position.allFinite() || !next.velocity.allFinite())
    ::kelp::detail::throw_numerical_error(
        "system::step (point mass): non-finite state; the mass may be too light for the "
        "partitioned coupling at this step");
  x = next;
  return a4;
}

/// The predicted motion of tether end `e` over a step (free ends are the line's own).
template <typename Scalar>
tether::EndMotion<Scalar> predicted_end(const TetherEnd<Scalar>& e, const FleetState<Scalar>& s) {
  tether::EndMotion<Scalar> m;
  switch (e.kind) {
    case EndKind::vehicle: {
      const auto i = std::size_t(e.index);
      return predicted_end(s.vehicles[i], s.vehicle_nu_dot[i], e.point);
    }
    case EndKind::point_mass: {
      const auto i = std::size_t(e.index);
      m.position = s.point_masses[i].position;
      m.velocity = s.point_masses[i].velocity;
      m.acceleration = s.point_mass_acceleration[i];
      return m;
    }
    case EndKind::anchor:
      m.position = e.point;
      return m;
    default:
      return m;
  }
}

/// Where end `e` actually is after a step (for the corrector); false for anchors and free ends.
template <typename Scalar>
bool actual_end(const TetherEnd<Scalar>& e, const FleetState<Scalar>& s, Vector3<Scalar>& p) {
  if (e.kind == EndKind::vehicle) {
    p = s.vehicles[std::size_t(e.index)].point_position(e.point);
    return true;
  }
  if (e.kind == EndKind::point_mass) {
    p = s.point_masses[std::size_t(e.index)].position;
    return true;
  }
  return false;
}

/// The name of element `index` of the array named `array`, followed by `rest`, e.g.
/// element("state.point_masses", 2, ".position must be finite") is
/// "state.point_masses[2].position must be finite": an error message, built only when a check
/// fails (so that a step's checks allocate nothing).
inline std::string element(const char* array, std::size_t index, const char* rest) {
  return std::string(array) + "[" + std::to_string(index) + "]" + rest;
}

}  // namespace detail

/// \brief The energy of `state`, part by part (allocation-free into `e`, sized for the model:
/// FleetReport's). Hydrostatic potentials relative to the environment's free surface.
/// \throws kelp::invalid_argument when `e` or `state` does not have the fleet's parts.
/// \tparam Scalar double or float.
/// \param model The fleet (its environment gives ρ, g and the free surface).
/// \param state The state whose energy is wanted.
/// \param[out] e Energy per part [J], sized for the fleet (e.g. FleetReport::energy).
template <typename Scalar>
void energy(const FleetModel<Scalar>& model, const FleetState<Scalar>& state,
            FleetEnergy<Scalar>& e) {
  const auto nv = std::size_t(model.vehicle_count()), np = std::size_t(model.point_mass_count()),
             nt = std::size_t(model.tether_count());
  KELP_CHECK(e.vehicles.size() == nv && e.point_masses.size() == np && e.tethers.size() == nt,
             "system::energy: the FleetEnergy is not sized for this fleet (one value per "
             "vehicle, point mass and tether: FleetReport's is)");
  KELP_CHECK(
      state.vehicles.size() == nv && state.point_masses.size() == np && state.tethers.size() == nt,
      "system::energy: the state is not of this fleet");
  const auto& env = model.environment();
  for (int i = 0; i < model.vehicle_count(); ++i) {
    const auto& x = state.vehicles[std::size_t(i)];
    e.vehicles[std::size_t(i)] = vehicle::energy(
        model.vehicle(i), x, vehicle::surroundings(model.vehicle(i), env, x, state.time));
  }
  const Scalar rho = Scalar(env.water_density()), g = Scalar(env.gravity());
  for (int j = 0; j < model.point_mass_count(); ++j) {
    const auto& p = model.parameters().point_masses[std::size_t(j)];
    const auto& x = state.point_masses[std::size_t(j)];
    const Scalar zeta = env.surface_elevation(x.position.x(), x.position.y(), state.time);
    const auto w = detail::sphere_wetness(p.volume, Scalar(x.position.z() + zeta));
    e.point_masses[std::size_t(j)] = Scalar(0.5) *
                                         (p.mass + p.added_mass_coefficient * rho * w.volume) *
                                         x.velocity.squaredNorm() -
                                     p.mass * g * x.position.z() + rho * g * w.integral;
  }
  for (int k = 0; k < model.tether_count(); ++k) {
    const auto& l = state.tethers[std::size_t(k)];
    e.tethers[std::size_t(k)] = tether::tether_energy(model.tether_of(k, l), env, l);
  }
}

/// \brief Advances the whole fleet by `dt` [s] (see the file's coupling scheme). No heap
/// allocation.
/// \param[in] model the fleet (its environment included). \param[in,out] ws buffers (built for
/// the model). \param[in,out] state advanced by dt. \param[in] inputs sized for the model.
/// \param[in] dt step [s], > 0. \param[in] options SystemStepOptions::with_energy.
/// \returns `ws.report`, refilled.
/// \throws kelp::invalid_argument for bad input (dt, inputs or states of the wrong size or
/// non-finite, clocks that differ from state.time, a workspace built for another model), naming
/// the element (e.g. `state.point_masses[2].position`);
/// kelp::numerical_error when a part cannot be advanced. After any throw every part of `state`
/// is bit-identical to what it was.
template <typename Scalar>
const FleetReport<Scalar>& step(const FleetModel<Scalar>& model, FleetWorkspace<Scalar>& ws,
                                FleetState<Scalar>& state, const FleetInputs<Scalar>& inputs,
                                double dt, SystemStepOptions options = {}) {
  const FleetParameters<Scalar>& p = model.parameters();
  const auto n = std::size_t(model.vehicle_count()), m = std::size_t(model.tether_count());
  const auto pm = std::size_t(model.point_mass_count());
  check_positive(dt, "dt");
  check_finite(state.time, "state.time");
  KELP_CHECK(ws.fits(model), "workspace was built for a different fleet");
  KELP_CHECK(inputs.vehicles.size() == n && inputs.commands.size() == n &&
                 inputs.winch_payout_rates.size() == m,
             "inputs must be sized for the fleet (FleetInputs(model))");
  KELP_CHECK(state.vehicles.size() == n && state.vehicle_nu_dot.size() == n &&
                 state.propulsion.size() == n && state.point_masses.size() == pm &&
                 state.point_mass_acceleration.size() == pm && state.tethers.size() == m,
             "state must be sized for the fleet (initial_state(model, ...))");
  // The messages name the element (e.g. "state.point_masses[2].position"), built only when a
  // check fails.
  for (std::size_t i = 0; i < n; ++i) {
    KELP_CHECK(all_finite(inputs.vehicles[i].tau),
               detail::element("inputs.vehicles", i, ".tau must be finite"));
    KELP_CHECK(all_finite(inputs.vehicles[i].tau_ext),
               detail::element("inputs.vehicles", i, ".tau_ext must be finite"));
    KELP_CHECK(state.vehicles[i].time == state.time,
               detail::element("state.vehicles", i,
                               ".time must equal state.time (use FleetState::set_time)"));
    vehicle::detail::check_state(state.vehicles[i]);
    KELP_CHECK(all_finite(state.vehicle_nu_dot[i]),
               detail::element("state.vehicle_nu_dot", i, " must be finite"));
  }
  for (std::size_t j = 0; j < pm; ++j) {
    KELP_CHECK(all_finite(state.point_masses[j].position),
               detail::element("state.point_masses", j, ".position must be finite"));
    KELP_CHECK(all_finite(state.point_masses[j].velocity),
               detail::element("state.point_masses", j, ".velocity must be finite"));
    KELP_CHECK(all_finite(state.point_mass_acceleration[j]),
               detail::element("state.point_mass_acceleration", j, " must be finite"));
  }
  for (std::size_t k = 0; k < m; ++k) {
    KELP_CHECK(is_finite(inputs.winch_payout_rates[k]),
               detail::element("inputs.winch_payout_rates", k, " must be finite"));
    KELP_CHECK(
        model.winch(int(k)) != nullptr || inputs.winch_payout_rates[k] == Scalar(0),
        detail::element("inputs.winch_payout_rates", k, " must be 0 for a tether without a winch"));
    KELP_CHECK(state.tethers[k].time == state.time,
               detail::element("state.tethers", k,
                               ".time must equal state.time (use FleetState::set_time)"));
    KELP_CHECK(ws.tethers[k].tether.fits(model.tether_of(int(k), state.tethers[k]).nodes()),
               ws.tethers[k].winch
                   ? detail::element("workspace holds the buffers of tethers", k,
                                     " at another node count than the state's: call "
                                     "system::fit_workspace(model, ws, state) first (a state "
                                     "loaded or restored at another count)")
                   : std::string("workspace was built for a different fleet"));
  }
  FleetReport<Scalar>& report = ws.report;
  report.tether = {};
  report.tether_fallbacks = 0;
  // Propulsion first, on copies committed with the rest.
  for (std::size_t i = 0; i < n; ++i) {
    ws.inputs[i] = inputs.vehicles[i];
    ws.propulsion[i] = state.propulsion[i];
    report.propulsion[i] = {};
    // The state's name in a refusal's message, on the stack (no allocation in a step).
    char state_name[40];
    std::snprintf(state_name, sizeof state_name, "state.propulsion[%zu]", i);
    detail::propel(model.propulsion(int(i)), ws.propulsion[i], inputs.commands[i], ws.inputs[i],
                   report.propulsion[i], dt, p.vehicles[i].name, state_name);
  }
  const auto& env = model.environment();
  const double t = state.time;
  tether::AdvanceOptions<Scalar> tether_options;
  tether_options.max_dt = p.max_tether_dt;
  tether_options.integrator = p.tether_integrator;
  tether_options.implicit = p.tether_options;
  // Everything a failure must restore.
  for (std::size_t i = 0; i < n; ++i) {
    ws.vehicles_before[i] = state.vehicles[i];
    ws.nu_dot_before[i] = state.vehicle_nu_dot[i];
  }
  for (std::size_t j = 0; j < pm; ++j) {
    ws.masses_before[j] = state.point_masses[j];
    ws.mass_acceleration_before[j] = state.point_mass_acceleration[j];
  }
  for (std::size_t k = 0; k < m; ++k)
    ws.tethers[k].backup_of(model.tether_of(int(k), state.tethers[k])).save(state.tethers[k]);
  const auto restore_bodies = [&] {
    for (std::size_t i = 0; i < n; ++i) state.vehicles[i] = ws.vehicles_before[i];
    for (std::size_t j = 0; j < pm; ++j) state.point_masses[j] = ws.masses_before[j];
  };
  const auto restore_tethers = [&] {
    for (std::size_t k = 0; k < m; ++k)
      ws.tethers[k].backup_of(model.tether_of(int(k), state.tethers[k])).restore(state.tethers[k]);
  };
  try {
    for (std::size_t k = 0; k < m; ++k) {
      ws.ends[k].start = detail::predicted_end(p.tethers[k].start, state);
      ws.ends[k].end = detail::predicted_end(p.tethers[k].end, state);
    }
    for (int pass = 0;; ++pass) {
      for (std::size_t k = 0; k < m; ++k) {
        const auto& line = model.tether_of(int(k), state.tethers[k]);
        try {
          report.tethers[k] = detail::advance_tether(
              line, model.winch(int(k)), ws.tethers[k].tether, env, state.tethers[k], ws.ends[k],
              dt, tether_options, p.explicit_fallback, report.tether_fallbacks);
        } catch (const kelp::invalid_argument& e) {
          // The tether's step checks its state (winch_length, payout_rate, ...) and names its own
          // fields ("state.winch_length ..."): say which tether. The state is restored below.
          throw kelp::invalid_argument(detail::element("state.tethers", k, ": ") + e.what());
        }
        report.tether += report.tethers[k];
        const auto& impulse = ws.tethers[k].tether.end_impulse;
        report.force_at_start[k] = p.tethers[k].start.kind == EndKind::free
                                       ? Vector3<Scalar>::Zero()
                                       : Vector3<Scalar>(impulse.on_start / Scalar(dt));
        report.force_at_end[k] = p.tethers[k].end.kind == EndKind::free
                                     ? Vector3<Scalar>::Zero()
                                     : Vector3<Scalar>(impulse.on_end / Scalar(dt));
      }
      // Gather the end forces on each body (in tether order), then advance the bodies.
      for (std::size_t j = 0; j < pm; ++j) ws.mass_forces[j].setZero();
      for (std::size_t i = 0; i < n; ++i) {
        int c = 0;
        for (std::size_t k = 0; k < m; ++k)
          for (int side = 0; side < 2; ++side) {
            const TetherEnd<Scalar>& e = side == 0 ? p.tethers[k].start : p.tethers[k].end;
            if (e.kind != EndKind::vehicle || std::size_t(e.index) != i) continue;
            ws.loads[i][std::size_t(c++)] = {
                e.point, side == 0 ? report.force_at_start[k] : report.force_at_end[k]};
          }
      }
      for (std::size_t k = 0; k < m; ++k)
        for (int side = 0; side < 2; ++side) {
          const TetherEnd<Scalar>& e = side == 0 ? p.tethers[k].start : p.tethers[k].end;
          if (e.kind == EndKind::point_mass)
            ws.mass_forces[std::size_t(e.index)] +=
                side == 0 ? report.force_at_start[k] : report.force_at_end[k];
        }
      for (std::size_t i = 0; i < n; ++i)
        state.vehicle_nu_dot[i] = detail::step_vehicle(
            model.vehicle(int(i)), ws.vehicles[i], state.vehicles[i], env, t, dt, ws.inputs[i],
            ws.loads[i].data(), int(ws.loads[i].size()), model.hull(int(i)));
      for (std::size_t j = 0; j < pm; ++j)
        state.point_mass_acceleration[j] = detail::step_point_mass(
            p.point_masses[j], state.point_masses[j], env, t, dt, ws.mass_forces[j]);
      if (pass >= p.coupling_corrections) break;
      // Corrector: the end paths that start as before and reach the actual end points.
      for (std::size_t k = 0; k < m; ++k) {
        Vector3<Scalar> target;
        if (detail::actual_end(p.tethers[k].start, state, target))
          detail::reach(ws.ends[k].start, target, Scalar(dt));
        if (detail::actual_end(p.tethers[k].end, state, target))
          detail::reach(ws.ends[k].end, target, Scalar(dt));
      }
      restore_tethers();
      restore_bodies();
    }
    report.tether.partings = 0;
    for (std::size_t k = 0; k < m; ++k) report.tether.partings += report.tethers[k].partings;
    report.tether.failure = {};
    for (std::size_t k = 0; k < m; ++k)
      if (report.tethers[k].partings > 0) report.tether.failure = report.tethers[k].failure;
  } catch (const kelp::error&) {
    restore_bodies();
    for (std::size_t i = 0; i < n; ++i) state.vehicle_nu_dot[i] = ws.nu_dot_before[i];
    for (std::size_t j = 0; j < pm; ++j)
      state.point_mass_acceleration[j] = ws.mass_acceleration_before[j];
    restore_tethers();
    throw;
  }
  // The winches, between this step and the next.
  for (std::size_t k = 0; k < m; ++k) {
    report.remesh[k] = {};
    if (model.winch(int(k)))
      report.remesh[k] =
          tether::advance_winch(*model.winch(int(k)), *ws.tethers[k].winch, state.tethers[k],
                                ws.tethers[k].tether, inputs.winch_payout_rates[k], dt);
  }
  // The clocks in lock-step: the first tether's (Kahan-summed over its sub-steps) is the fleet's.
  // (Every tether sums the same sub-steps; a retried one may differ in the last bits: it takes
  // the first's clock.)
  state.time = m > 0 ? state.tethers[0].time : t + dt;
  for (std::size_t k = 1; k < m; ++k) {
    state.tethers[k].time = state.time;
    state.tethers[k].time_carry = state.tethers[0].time_carry;
  }
  for (std::size_t i = 0; i < n; ++i) {
    state.vehicles[i].time = state.time;
    state.propulsion[i] = ws.propulsion[i];
    report.contact[i] = {};
    if (model.hull(int(i)))
      report.contact[i] = hull_contact(*model.hull(int(i)), env, state.vehicles[i]);
  }
  if (options.with_energy) energy(model, state, report.energy);
  return report;
}

/// \brief A fleet state with the vehicles at `vehicles`, the point masses at rest at
/// `point_masses` (NED [m]), and each tether at its static equilibrium in still water between
/// its ends' positions (a free end: the line hanging from its other end, solved with its end
/// mass), at rest, at time `t` [s]. The static solve's tolerance is, unless `options` gives one,
/// 1e-4 × each line's weight in air.
/// \throws kelp::invalid_argument for states of the wrong count or bad (a point mass's position
/// named with its index, e.g. `point_masses[2]`); kelp::numerical_error
/// when a tether's static solve does not converge (naming the tether).
/// \tparam Scalar double or float.
/// \param model The fleet.
/// \param ws Its workspace (the static solves' buffers).
/// \param vehicles One state per vehicle (pose, body velocity), copied as given.
/// \param point_masses One NED position per point mass [m] (default: none).
/// \param t Start time [s] (default 0).
/// \param options The tethers' static solve (tolerance, iterations).
/// \return The state: propulsion at its initial state, coupling memory zero, every clock at t.
template <typename Scalar>
FleetState<Scalar> initial_state(const FleetModel<Scalar>& model, FleetWorkspace<Scalar>& ws,
                                 const std::vector<vehicle::VehicleState<Scalar>>& vehicles,
                                 const std::vector<Vector3<Scalar>>& point_masses = {},
                                 double t = 0.0, tether::StaticOptions<Scalar> options = {}) {
  const auto n = std::size_t(model.vehicle_count()), m = std::size_t(model.tether_count());
  const auto pm = std::size_t(model.point_mass_count());
  KELP_CHECK(vehicles.size() == n, "initial_state: one state per vehicle");
  KELP_CHECK(point_masses.size() == pm, "initial_state: one position per point mass");
  KELP_CHECK(ws.fits(model), "workspace was built for a different fleet");
  FleetState<Scalar> s;
  s.vehicles = vehicles;
  for (const auto& v : s.vehicles) vehicle::detail::check_state(v);
  s.vehicle_nu_dot.assign(n, Vector6<Scalar>::Zero());
  s.propulsion.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    if (model.propulsion(int(i)))
      s.propulsion[i] = vehicle::initial_state(*model.propulsion(int(i)));
  s.point_masses.resize(pm);
  for (std::size_t j = 0; j < pm; ++j) {
    KELP_CHECK(all_finite(point_masses[j]), detail::element("point_masses", j, " must be finite"));
    s.point_masses[j].position = point_masses[j];
  }
  s.point_mass_acceleration.assign(pm, Vector3<Scalar>::Zero());
  const environment::Environment<Scalar> still = detail::still_water(model.environment());
  s.tethers.resize(m);
  const auto& p = model.parameters();
  for (std::size_t k = 0; k < m; ++k) {
    const auto& line = model.tether(int(k));
    tether::StaticOptions<Scalar> o = options;
    detail::default_static_tolerance(line, still, o);
    // The fixed ends where their bodies are; a free end starts hanging straight down from the
    // other (the solve lets it go).
    const TetherEnd<Scalar>&e0 = p.tethers[k].start, &e1 = p.tethers[k].end;
    const auto fixed = [&](const TetherEnd<Scalar>& e) {
      Vector3<Scalar> q(e.point);
      detail::actual_end(e, s, q);
      return q;
    };
    const Vector3<Scalar> down(Scalar(0), Scalar(0), line.parameters().length);
    Vector3<Scalar> a = e0.kind == EndKind::free ? Vector3<Scalar>::Zero() : fixed(e0);
    const Vector3<Scalar> b = e1.kind == EndKind::free ? Vector3<Scalar>(a + down) : fixed(e1);
    if (e0.kind == EndKind::free) a = b + down;
    const tether::StaticResult<Scalar> r =
        tether::static_initial_state(line, ws.tethers[k].tether, still, a, b, s.tethers[k], o);
    if (!r.converged)
      ::kelp::detail::throw_numerical_error("fleet initial_state: tether \"" + p.tethers[k].name +
                                            "\"'s static shape did not converge (residual " +
                                            std::to_string(double(value_of(r.residual))) + " N)");
  }
  s.set_time(t);
  return s;
}

using FleetParametersd = FleetParameters<double>;          ///< FleetParameters<double>
using FleetModeld = FleetModel<double>;                    ///< FleetModel<double>
using FleetStated = FleetState<double>;                    ///< FleetState<double>
using FleetWorkspaced = FleetWorkspace<double>;            ///< FleetWorkspace<double>
using FleetInputsd = FleetInputs<double>;                  ///< FleetInputs<double>
using FleetReportd = FleetReport<double>;                  ///< FleetReport<double>
using FleetEnergyd = FleetEnergy<double>;                  ///< FleetEnergy<double>
using PointMassParametersd = PointMassParameters<double>;  ///< PointMassParameters<double>
using PointMassStated = PointMassState<double>;            ///< PointMassState<double>

}  // namespace kelp::system

/// \brief The double-precision fleet step and initial state, for a compiled layer that
/// instantiates them once (as KELP_SYSTEM_INSTANCES).
#define KELP_FLEET_INSTANCES(prefix)                                                           \
  prefix const kelp::system::FleetReport<double>& kelp::system::step<double>(                  \
      const kelp::system::FleetModel<double>&, kelp::system::FleetWorkspace<double>&,          \
      kelp::system::FleetState<double>&, const kelp::system::FleetInputs<double>&, double,     \
      kelp::system::SystemStepOptions);                                                        \
  prefix kelp::system::FleetState<double> kelp::system::initial_state<double>(                 \
      const kelp::system::FleetModel<double>&, kelp::system::FleetWorkspace<double>&,          \
      const std::vector<kelp::vehicle::VehicleState<double>>&,                                 \
      const std::vector<kelp::Vector3<double>>&, double, kelp::tether::StaticOptions<double>); \
  prefix void kelp::system::energy<double>(const kelp::system::FleetModel<double>&,            \
                                           const kelp::system::FleetState<double>&,            \
                                           kelp::system::FleetEnergy<double>&);
