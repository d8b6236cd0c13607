/// \file
/// \brief The environment facade: one object that vehicles and tether nodes query for the water
/// current, the wave orbital kinematics, the free-surface elevation and the wind.
///
/// One water: the `Environment` is the single source of truth for the water density, gravity and
/// air density. Models that carry their own copy (they need it inside their force laws) are
/// checked against it where they meet it, with `check_same_water`: here for a `WaveField` (its
/// gravity, also checked by `set_waves` / `set_gravity`), in `kelp/environment/paper.hpp` for the
/// paper's `SurfaceHydrostatics` and `PaperWave`, in `kelp/vehicle/water.hpp` for vehicle models. A
/// mismatch throws `kelp::invalid_argument` naming both values. Build such a model from the
/// environment (e.g. `h.rho = env.water_density(); h.gravity = env.gravity();`) and the check
/// passes.
///
/// Start-up ramp: `set_ramp(T)` brings the sea in smoothly over its first T seconds. Every water
/// and air velocity the environment reports (current, wave orbital velocity, wind), the wave
/// elevation, slope and velocity gradient are multiplied by the half-cosine ramp
/// r(t) = ½(1 − cos(π t / T)) for 0 ≤ t < T (0 before, 1 after), and the water acceleration gets
/// the ramp's own part ṙ(t)·v, so that the water a body sees starts at rest and still moves
/// consistently (its acceleration is the derivative of its velocity). Vehicles and a tether laid at
/// rest at t = 0 then start in equilibrium instead of being struck by the full sea in their first
/// step. This is the ramp WEC-Sim applies to its incident waves (NREL/Sandia, `simu.rampTime`;
/// source/wavesReg.m: amplitude × (1 + cos(π + π t/T_r))/2, the same function), and the reason
/// MoorDyn refines its initial line shape before a run (moordyn.readthedocs.io, "Initialization").
///
/// Frames and signs: world NED (x north, y east, z down, mean sea surface at z = 0). The surface
/// elevation ζ is positive UP, so the free surface lies at NED z = −ζ. Units SI.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <sstream>
#include <string>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/current.hpp"
#include "kelp/environment/limits.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/environment/waves.hpp"
#include "kelp/environment/wind.hpp"

namespace kelp {
namespace environment {

/// \brief Everything the environment knows at one point and time.
/// \tparam Scalar double, float or an automatic-differentiation type.
template <typename Scalar>
struct EnvironmentSample {
  /// Water current velocity, NED [m/s]. Above the free surface the value at the surface is
  /// returned, so a hull reference point slightly above the waterline still sees the current.
  Vector3<Scalar> current = Vector3<Scalar>::Zero();
  /// Wave orbital velocity, NED [m/s] (zero above the free surface and in a calm sea).
  Vector3<Scalar> wave_velocity = Vector3<Scalar>::Zero();
  /// Wave orbital acceleration ∂v/∂t (local), NED [m/s²].
  Vector3<Scalar> wave_acceleration = Vector3<Scalar>::Zero();
  /// Wave velocity gradient ∂v_i/∂x_k, NED [1/s]: (v·∇)v = wave_velocity_gradient ·
  /// wave_velocity is the convective part of the material acceleration Dv/Dt a body moving
  /// with the water feels (second order in the wave amplitude; its mean, k a²ω² e^{−2kz} upwards
  /// for a regular deep-water wave, keeps a neutrally buoyant body from sinking).
  Eigen::Matrix<Scalar, 3, 3> wave_velocity_gradient = Eigen::Matrix<Scalar, 3, 3>::Zero();
  /// Free-surface elevation ζ above the mean level at the point's (x, y) [m], positive UP.
  Scalar surface_elevation = Scalar(0);
  /// Free-surface slope (∂ζ/∂x, ∂ζ/∂y) [-] at the point's (x, y), as `surface_slope` gives it
  /// (summed with the kinematics, from the same sines: cheaper than a separate query).
  Eigen::Matrix<Scalar, 2, 1> surface_slope = Eigen::Matrix<Scalar, 2, 1>::Zero();
  /// Wind velocity at 10 m above the sea (the direction the air moves towards), NED [m/s].
  Vector3<Scalar> wind = Vector3<Scalar>::Zero();
};

namespace detail {
/// A number unique to each object and value: drawn anew on construction, copy and assignment
/// (a move copies: the moved-from object keeps its own).
struct InstanceId {
  std::uint64_t value = next();
  InstanceId() = default;
  InstanceId(const InstanceId&) : value(next()) {}
  InstanceId& operator=(const InstanceId&) {
    value = next();
    return *this;
  }
  static std::uint64_t next() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
  }
};
}  // namespace detail

/// \brief The sea a simulation runs in: fluid constants, seabed, current, waves and wind.
///
/// A default-constructed environment is still water (`calm()`): seawater of 1025 kg/m³, air of
/// 1.225 kg/m³, g = kelp::standard_gravity, no seabed, no current, no waves, no wind.
/// All queries are `const` and allocate nothing; in still water they only copy zeros.
/// Time is a `double` [s] for every Scalar (one clock: a float model must not drift or stop after
/// hours); wave phases are formed in double before any cast to Scalar.
/// The parts are built separately (`CurrentModel`, `WaveField`, `WindField`) and set here; see
/// `sea_state.hpp` for presets. The wave field and the current profile carry their own water
/// depth (set them to the seabed depth); the wave field's gravity must match this one.
/// \tparam Scalar double, float or an automatic-differentiation type.
template <typename Scalar>
class Environment {
 public:
  /// \brief Still water (same as `calm()`).
  Environment() = default;

  /// \brief Still water: no current, no waves, no wind, seawater, standard gravity, no seabed.
  /// \return a still-water environment.
  static Environment calm() { return Environment(); }

  /// \brief An id of this object's value, new for every environment made, copied or assigned: a
  /// step that kept results computed in an environment (the explicit tether steps' last
  /// evaluation) can tell it is still the same.
  /// \return the id.
  std::uint64_t instance_id() const { return id_.value; }

  /// \brief Water density ρ [kg/m³].
  /// \return ρ [kg/m³].
  Scalar water_density() const { return water_density_; }
  /// \brief Air density ρ_air [kg/m³].
  /// \return ρ_air [kg/m³].
  Scalar air_density() const { return air_density_; }
  /// \brief Gravitational acceleration g [m/s²].
  /// \return g [m/s²].
  Scalar gravity() const { return gravity_; }
  /// \brief NED z of a flat seabed [m] (> 0); +infinity when there is none.
  /// \return the depth [m], or +∞.
  Scalar seabed_depth() const { return seabed_depth_; }

  /// \brief Sets the water density [kg/m³] (> 0, ≤ 1e5: `limits::max_fluid_density`, far above
  /// any liquid). \throws kelp::invalid_argument naming `water_density` and the value when it is
  /// not finite or not in (0, 1e5].
  /// \param rho the density [kg/m³]. \return *this.
  Environment& set_water_density(Scalar rho) {
    detail::check_positive_at_most(value_of(rho), limits::max_fluid_density, "water_density",
                                   "finite and in (0, 1e5] kg/m^3");
    water_density_ = rho;
    return *this;
  }
  /// \brief Sets the air density [kg/m³] (> 0, ≤ 1e5: `limits::max_fluid_density`).
  /// \throws kelp::invalid_argument naming `air_density` and the value when it is not finite or
  /// not in (0, 1e5].
  /// \param rho the density [kg/m³]. \return *this.
  Environment& set_air_density(Scalar rho) {
    detail::check_positive_at_most(value_of(rho), limits::max_fluid_density, "air_density",
                                   "finite and in (0, 1e5] kg/m^3");
    air_density_ = rho;
    return *this;
  }
  /// \brief Sets the gravitational acceleration [m/s²] (> 0, ≤ 1000: `limits::max_gravity`).
  /// \throws kelp::invalid_argument naming `gravity` and the value when it is not finite or not
  /// in (0, 1000], or when it differs from the wave field's gravity.
  /// \param g the acceleration [m/s²]. \return *this.
  Environment& set_gravity(Scalar g) {
    detail::check_positive_at_most(value_of(g), limits::max_gravity, "gravity",
                                   "finite and in (0, 1000] m/s^2");
    check_wave_gravity(waves_, value_of(g));
    gravity_ = g;
    return *this;
  }
  /// \brief Sets the NED z of a flat seabed [m] (> 0, or +infinity for none).
  /// \throws kelp::invalid_argument naming `seabed_depth`.
  /// \param depth NED z of the seabed [m]. \return *this.
  Environment& set_seabed_depth(Scalar depth) {
    KELP_CHECK(!std::isnan(value_of(depth)) && value_of(depth) > 0.0,
               "seabed_depth must be > 0 (or +infinity for no seabed)");
    seabed_depth_ = depth;
    return *this;
  }
  /// \brief The obstacles (cylinders, boxes, a height-field seabed) the tether and the vehicles
  /// touch, or null when there are none (the contact passes then cost nothing).
  /// \return a pointer valid until set_obstacles() or the last copy goes, or null.
  const ObstacleSet* obstacles() const {
    return obstacles_ && !obstacles_->empty() ? obstacles_.get() : nullptr;
  }
  /// \brief Sets the obstacles (copied once; copies of this environment share them, read-only).
  /// An empty set removes them. Allocates: call it at setup or between steps.
  /// \param obstacles the set (checked when it was built). \return *this.
  Environment& set_obstacles(const ObstacleSet& obstacles) {
    obstacles_ = obstacles.empty() ? nullptr : std::make_shared<const ObstacleSet>(obstacles);
    return *this;
  }
  /// \brief Sets a constant, depth-uniform current velocity, NED [m/s].
  /// \throws kelp::invalid_argument naming `current` when not finite.
  template <typename Derived>
  /// \param v_ned the current, NED [m/s]. \return *this.
  Environment& set_current(const Eigen::MatrixBase<Derived>& v_ned) {
    current_ = CurrentModel<Scalar>::constant(v_ned);
    return *this;
  }

  /// \brief Sets the current model (speed, direction, depth profile, variation).
  /// \param current the model. \return *this.
  Environment& set_current(const CurrentModel<Scalar>& current) {
    current_ = current;
    return *this;
  }
  /// \brief Sets the wave field (a default-constructed `WaveField` is a calm sea). Its dispersion
  /// relation must use this environment's gravity; its `depth` should be the seabed depth (deep
  /// water, +∞, is an accepted approximation over any seabed deeper than about half a wavelength).
  /// \throws kelp::invalid_argument naming `waves.gravity` when the gravities differ.
  /// \param waves the wave field. \return *this.
  Environment& set_waves(const WaveField<Scalar>& waves) {
    check_wave_gravity(waves, value_of(gravity_));
    waves_ = waves;
    return *this;
  }
  /// \brief Sets the wind field (a default-constructed `WindField` is no wind).
  /// \param wind the wind field. \return *this.
  Environment& set_wind(const WindField<Scalar>& wind) {
    wind_ = wind;
    return *this;
  }
  /// \brief Sets the start-up ramp T [s] (0: none, the default): the sea comes in over [0, T]
  /// (see the file's comment). \throws kelp::invalid_argument naming `ramp` when T is not finite
  /// or negative.
  /// \param duration T [s]. \return *this.
  Environment& set_ramp(double duration) {
    KELP_CHECK(std::isfinite(duration) && duration >= 0.0,
               "ramp must be a finite, non-negative duration [s]");
    ramp_ = duration;
    return *this;
  }
  /// \brief The start-up ramp's duration T [s] (0: none).
  /// \return T [s].
  double ramp() const { return ramp_; }
  /// \brief The ramp factor r(t) ∈ [0, 1] at time t [s] and its rate ṙ(t) [1/s]:
  /// r = ½(1 − cos(π t/T)) on [0, T), 0 before, 1 from T on (and always 1 without a ramp).
  /// \param[in] t time [s] \param[out] rate ṙ(t) [1/s] \returns r(t)
  double ramp_factor(double t, double& rate) const {
    rate = 0.0;
    if (!(ramp_ > 0.0) || t >= ramp_) return 1.0;
    if (!(t > 0.0)) return 0.0;
    const double w = kelp::pi / ramp_;
    rate = 0.5 * w * std::sin(w * t);
    return 0.5 * (1.0 - std::cos(w * t));
  }
  /// \brief True when the water is still everywhere and at all times (no wave components and no
  /// current), so that water velocity and acceleration are zero at every point: callers such as
  /// the tether may skip their water queries.
  /// \return whether the water never moves.
  bool is_still_water() const { return waves_.empty() && current_.is_zero(); }
  /// \brief The current model.
  /// \return a reference valid until the next set_current().
  const CurrentModel<Scalar>& current() const { return current_; }
  /// \brief The wave field.
  /// \return a reference valid until the next set_waves().
  const WaveField<Scalar>& waves() const { return waves_; }
  /// \brief The wind field.
  /// \return a reference valid until the next set_wind().
  const WindField<Scalar>& wind() const { return wind_; }

  /// \brief Everything at NED point `p_ned` [m] and time `t` [s]: current, wave orbital velocity
  /// and acceleration (zero above the free surface), surface elevation and slope at (x, y), wind at
  /// 10 m (left at zero when `with_wind` is false: the gust sum costs as much as the waves at a
  /// point). \throws kelp::invalid_argument when a coordinate of p_ned is NaN or ±∞ (a point
  /// without a depth or a wave phase: no sample), or when t is not finite and a wave field, a
  /// varying current or gusts read it.
  /// \param p_ned the point, NED [m]. \param t time [s]. \param with_wind whether to sum the gusts.
  /// \return current and wave velocity [m/s] and acceleration [m/s²] (NED), elevation [m, up],
  /// slope [-], wind [m/s] (NED).
  EnvironmentSample<Scalar> sample(const Vector3<Scalar>& p_ned, double t,
                                   bool with_wind = true) const {
    check_all_finite(p_ned, "Environment::sample: p_ned");
    return sample_unchecked(p_ned, t, with_wind);
  }

  /// \brief sample() without the check of the point, for the samplers inside a step (the vehicle
  /// steps sample their stages through it, vehicle::surroundings): there a stage that has blown
  /// up to NaN gives NaN values, which the step reports as numerical_error with the state
  /// unchanged, instead of an invalid_argument from the middle of the step (the step checks the
  /// state it is given once, up front). Same values as sample() for a finite point.
  /// \throws kelp::invalid_argument when t is not finite and a wave field, a varying current or
  /// gusts read it.
  /// \param p_ned the point, NED [m]. \param t time [s]. \param with_wind whether to sum the gusts.
  /// \return as sample().
  EnvironmentSample<Scalar> sample_unchecked(const Vector3<Scalar>& p_ned, double t,
                                             bool with_wind) const {
    EnvironmentSample<Scalar> s;
    if (!current_.is_zero())  // as CurrentModel::velocity, without its check of the point
      s.current = current_.surface_velocity(t) *
                  detail::profile_factor_unchecked(current_.parameters().profile, p_ned(2));
    if (!waves_.empty()) {
      const WaveKinematics<Scalar> k = waves_.kinematics(p_ned, t);
      s.wave_velocity = k.velocity;
      s.wave_acceleration = k.acceleration;
      s.wave_velocity_gradient = k.velocity_gradient;
      s.surface_elevation = k.elevation;
      s.surface_slope = k.slope;
    }
    if (with_wind) s.wind = wind_.velocity(t);
    double rate = 0.0;
    const double r = ramp_factor(t, rate);
    if (r < 1.0) {  // the start-up ramp: scaled fields, plus ṙ v in the water's acceleration
      const Scalar rs(r), rd(rate);
      s.wave_acceleration = rs * s.wave_acceleration + rd * (s.current + s.wave_velocity);
      s.current *= rs;
      s.wave_velocity *= rs;
      s.wave_velocity_gradient *= rs;
      s.surface_elevation *= rs;
      s.surface_slope *= rs;
      s.wind *= rs;
    }
    return s;
  }

  /// \brief Free-surface elevation ζ(x, y, t) [m], positive up (x north, y east [m], t [s]).
  /// \throws kelp::invalid_argument when there are waves and t is not finite.
  /// \param x north [m]. \param y east [m]. \param t time [s]. \return ζ [m].
  Scalar surface_elevation(Scalar x, Scalar y, double t) const {
    if (waves_.empty()) return Scalar(0);
    double rate = 0.0;
    const double r = ramp_factor(t, rate);
    return r < 1.0 ? Scalar(r) * waves_.elevation(x, y, t) : waves_.elevation(x, y, t);
  }

  /// \brief Free-surface slope (∂ζ/∂x, ∂ζ/∂y) [-] at (x, y, t).
  /// \throws kelp::invalid_argument when there are waves and t is not finite.
  /// \param x north [m]. \param y east [m]. \param t time [s]. \return (∂ζ/∂x, ∂ζ/∂y) [-].
  Eigen::Matrix<Scalar, 2, 1> surface_slope(Scalar x, Scalar y, double t) const {
    double rate = 0.0;
    const double r = ramp_factor(t, rate);
    return r < 1.0 ? Eigen::Matrix<Scalar, 2, 1>(Scalar(r) * waves_.slope(x, y, t))
                   : waves_.slope(x, y, t);
  }

  /// \brief Water velocity and acceleration at many NED points at once (e.g. all tether nodes);
  /// no heap allocation.
  ///
  /// `velocity.col(i)` = current + wave orbital velocity at `points.col(i)`;
  /// `acceleration.col(i)` = wave orbital acceleration there (no wave part above the free
  /// surface; the current there is the surface current). \param[in] points 3×n NED positions [m]
  /// \param[in] t time [s] \param[out] velocity 3×n [m/s] \param[out] acceleration 3×n [m/s²]
  /// \throws kelp::invalid_argument when the output sizes differ from the points', or t is not
  /// finite and waves or a varying current read it (NaN positions give NaN values, no exception:
  /// the tether's integrators report those as a numerical error).
  void sample_water(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
                    Eigen::Ref<Matrix3X<Scalar>> velocity,
                    Eigen::Ref<Matrix3X<Scalar>> acceleration) const {
    KELP_CHECK(velocity.cols() == points.cols() && acceleration.cols() == points.cols(),
               "sample_water: velocity and acceleration must have as many columns as points");
    sample_water_unramped(points, t, velocity, acceleration);
    apply_ramp(t, velocity, acceleration);
  }

  /// \brief The same, plus the free-surface elevation ζ above each point [m] (positive up), from
  /// the same wave sums: much cheaper than calling `surface_elevation` for each point.
  /// \param[in] points 3×n NED positions [m] \param[in] t time [s]
  /// \param[out] velocity 3×n [m/s] \param[out] acceleration 3×n [m/s²]
  /// \param[out] elevation n values [m]
  /// \throws kelp::invalid_argument as the four-argument sample_water, or when elevation has not
  /// one entry per point.
  void sample_water(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
                    Eigen::Ref<Matrix3X<Scalar>> velocity,
                    Eigen::Ref<Matrix3X<Scalar>> acceleration,
                    Eigen::Ref<VectorX<Scalar>> elevation) const {
    KELP_CHECK(elevation.size() == points.cols(),
               "sample_water: elevation must have one entry per point");
    KELP_CHECK(velocity.cols() == points.cols() && acceleration.cols() == points.cols(),
               "sample_water: velocity and acceleration must have as many columns as points");
    if (waves_.empty()) {
      sample_water_unramped(points, t, velocity, acceleration);
      elevation.setZero();
    } else {
      waves_.kinematics(points, t, velocity, acceleration, elevation);
      add_current(points, t, velocity);
    }
    if (apply_ramp(t, velocity, acceleration)) {
      double rate = 0.0;
      elevation *= Scalar(ramp_factor(t, rate));
    }
  }

 private:
  /// sample_water without the ramp (sizes checked by the caller).
  void sample_water_unramped(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
                             Eigen::Ref<Matrix3X<Scalar>> velocity,
                             Eigen::Ref<Matrix3X<Scalar>> acceleration) const {
    if (waves_.empty()) {  // calm sea: no wave pass, the current is written directly
      acceleration.setZero();
      if (current_.is_zero()) {
        velocity.setZero();
        return;
      }
      const Vector3<Scalar> vs = current_.surface_velocity(t);
      if (current_.parameters().profile.kind == CurrentProfileKind::uniform) {
        velocity = vs.replicate(1, points.cols());
        return;
      }
      for (Eigen::Index i = 0; i < points.cols(); ++i)
        velocity.col(i) =
            vs * detail::profile_factor_unchecked(current_.parameters().profile, points(2, i));
      return;
    }
    waves_.kinematics(points, t, velocity, acceleration);
    add_current(points, t, velocity);
  }

  /// During the start-up ramp: acceleration ← r a + ṙ v, velocity ← r v. Returns whether it
  /// applied (t inside the ramp).
  bool apply_ramp(double t, Eigen::Ref<Matrix3X<Scalar>> velocity,
                  Eigen::Ref<Matrix3X<Scalar>> acceleration) const {
    double rate = 0.0;
    const double r = ramp_factor(t, rate);
    if (!(r < 1.0)) return false;
    acceleration = Scalar(r) * acceleration + Scalar(rate) * velocity;
    velocity *= Scalar(r);
    return true;
  }

  /// Adds the current at each point to `velocity` (waves already written).
  void add_current(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
                   Eigen::Ref<Matrix3X<Scalar>> velocity) const {
    if (current_.is_zero()) return;
    const Vector3<Scalar> vs = current_.surface_velocity(t);
    if (current_.parameters().profile.kind == CurrentProfileKind::uniform) {
      velocity.colwise() += vs;
      return;
    }
    for (Eigen::Index i = 0; i < points.cols(); ++i)
      velocity.col(i) +=
          vs * detail::profile_factor_unchecked(current_.parameters().profile, points(2, i));
  }

  static void check_wave_gravity(const WaveField<Scalar>& waves, double g) {
    KELP_CHECK(waves.empty() || std::abs(waves.parameters().gravity - g) <= 1e-6 * g,
               "waves.gravity must equal the environment's gravity");
  }

  Scalar water_density_ = Scalar(kelp::seawater_density);
  Scalar air_density_ = Scalar(kelp::air_density);
  Scalar gravity_ = Scalar(kelp::standard_gravity);
  Scalar seabed_depth_ = Scalar(std::numeric_limits<double>::infinity());
  double ramp_ = 0.0;  // start-up ramp T [s]
  CurrentModel<Scalar> current_;
  WaveField<Scalar> waves_;
  WindField<Scalar> wind_;
  std::shared_ptr<const ObstacleSet> obstacles_;
  detail::InstanceId id_;
};

/// \brief Throws `kelp::invalid_argument` unless a model's water density and gravity are those of
/// the environment (to 1e-6 relative: a single-precision copy of the same number passes).
///
/// The one check every "model meets environment" path uses (the vehicle and tether layers and the
/// system layer call it, or an overload of it, when they combine a model with an environment).
/// \param[in] density the model's water density [kg/m³] \param[in] gravity the model's g [m/s²]
/// \param[in] env the environment (the source of truth)
/// \param[in] who the model's name for the message (e.g. "vehicle 'BlueROV2 Heavy'")
template <typename Scalar>
void check_same_water(double density, double gravity, const Environment<Scalar>& env,
                      const std::string& who) {
  const auto differs = [](double a, double b) {
    return !(std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)));
  };
  const double rho_env = value_of(env.water_density()), g_env = value_of(env.gravity());
  if (differs(density, rho_env) || differs(gravity, g_env)) {
    std::ostringstream msg;
    msg.precision(9);
    msg << who << ": water does not match the environment: ";
    if (differs(density, rho_env))
      msg << "density " << density << " kg/m^3 but the environment's water_density is " << rho_env
          << " kg/m^3";
    if (differs(density, rho_env) && differs(gravity, g_env)) msg << "; ";
    if (differs(gravity, g_env))
      msg << "gravity " << gravity << " m/s^2 but the environment's gravity is " << g_env
          << " m/s^2";
    msg << " (build the model from env.water_density() and env.gravity())";
    ::kelp::detail::throw_invalid_argument(msg.str());
  }
}

/// \brief Checks a wave field's gravity (its dispersion relation) against the environment (the
/// same test `Environment::set_waves` makes). \throws kelp::invalid_argument
/// \param waves the wave field. \param env the environment it is meant for.
template <typename Scalar>
void check_same_water(const WaveField<Scalar>& waves, const Environment<Scalar>& env) {
  check_same_water(value_of(env.water_density()), waves.parameters().gravity, env, "WaveField");
}

/// \brief Double-precision environment.
using Environmentd = Environment<double>;
/// \brief Single-precision environment.
using Environmentf = Environment<float>;

}  // namespace environment
}  // namespace kelp
