/// \file
/// \brief Scenario files (JSON): the schema, its defaults and its validation.
///
/// A scenario describes one run of the tethered pair (a BlueBoat and a BlueROV2 Heavy joined by a
/// tether): the sea, the tether, the vehicles' attachment points and start, the controllers, the
/// mission and the output rates. Every field is optional; the defaults are the embedded default
/// run of kelp-tethered-pair. Errors name the file, the JSON path and what was expected
/// (`scenario_error`). The schema is documented in apps/tethered_pair/README.md. Part of the
/// compiled `kelp::sim` component (`find_package(kelp CONFIG COMPONENTS sim)`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "kelp/control/tether_management.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/kernel_path.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/environment/wave_stretching.hpp"
#include "kelp/sim/entanglement.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/navigation.hpp"
#include "kelp/sim/scenario_reader.hpp"
#include "kelp/tether/model.hpp"

namespace kelp {
namespace sim {

/// \brief A choice of a scenario file: an enumerator and its name, as scenario files, summaries
/// and error messages spell it. Each choice's names are one table (e.g. sea_names), which the
/// schema reads and writes by and to_string() looks up.
template <class E>
struct ChoiceName {
  E value;           ///< the enumerator
  const char* name;  ///< its name in scenario files
};

/// \brief The name of `value` in the table `names`, or `unknown` (by default nullptr) when the
/// table lacks it (a value cast from an integer).
/// \tparam E the enumeration \tparam N the table's length
/// \param value the enumerator to look up \param names its table (e.g. sea_names)
/// \param unknown what to return for a value the table lacks
/// \return the name (static storage, from the table), or `unknown`. No throw.
template <class E, std::size_t N>
constexpr const char* choice_name(E value, const ChoiceName<E> (&names)[N],
                                  const char* unknown = nullptr) {
  for (const ChoiceName<E>& n : names)
    if (n.value == value) return n.name;
  return unknown;
}

/// \brief What the controllers navigate by (the scenario's `navigation.mode`).
enum class NavigationMode {
  perfect,  ///< "perfect": the true state (the default)
  sensors   ///< "sensors": the estimates of kelp::nav's sensors and filters
            ///< (kelp/sim/navigation.hpp)
};

/// \brief The sea of a scenario (`sea`): one of the paper's presets, or the values of a `sea`
/// object.
enum class Sea {
  calm,      ///< "calm": environment::presets::calm
  moderate,  ///< "moderate": environment::presets::moderate (the default)
  rough,     ///< "rough": environment::presets::rough
  custom     ///< "custom": a `sea` object's values (Scenario::significant_height and the others)
};

/// \brief Which line joins the vehicles (`tether.kind`; system::presets::TetherKind's choice,
/// kept apart so that this header does not include the system's).
enum class TetherKind {
  rov_tether,  ///< "rov_tether": Fathom-class ROV tether (tether::presets::rov_tether; default)
  bead_chain   ///< "bead_chain": the paper's Gazebo bead chain (tether::presets::bead_chain)
};

/// \brief The controllers' preset (`control.preset`).
enum class ControlPreset {
  /// "kelp" (the default): the boat tracks the ROV's velocity and position
  /// (control::AsvLaw::track), the ROV follows the survey's legs, thrust clip 25 N.
  kelp,
  /// "paper": Buchholz et al.'s pursuit with their gains, thrust clip 15 N.
  paper
};

/// \brief The names of NavigationMode (`navigation.mode`).
inline constexpr ChoiceName<NavigationMode> navigation_mode_names[] = {
    {NavigationMode::perfect, "perfect"}, {NavigationMode::sensors, "sensors"}};
/// \brief The names of Sea (`sea`; "custom" is written, and read, as an object).
inline constexpr ChoiceName<Sea> sea_names[] = {{Sea::calm, "calm"},
                                                {Sea::moderate, "moderate"},
                                                {Sea::rough, "rough"},
                                                {Sea::custom, "custom"}};
/// \brief The names of environment::WaveStretching (`sea.stretching`).
inline constexpr ChoiceName<kelp::environment::WaveStretching> wave_stretching_names[] = {
    {kelp::environment::WaveStretching::vertical, "vertical"},
    {kelp::environment::WaveStretching::wheeler, "wheeler"}};
/// \brief The names of TetherKind (`tether.kind`).
inline constexpr ChoiceName<TetherKind> tether_kind_names[] = {
    {TetherKind::rov_tether, "rov_tether"}, {TetherKind::bead_chain, "bead_chain"}};
/// \brief The names of ControlPreset (`control.preset`).
inline constexpr ChoiceName<ControlPreset> control_preset_names[] = {
    {ControlPreset::kelp, "kelp"}, {ControlPreset::paper, "paper"}};
/// \brief The names of tether::LineModel (`tether.line_model`).
inline constexpr ChoiceName<kelp::tether::LineModel> line_model_names[] = {
    {kelp::tether::LineModel::kelp, "kelp"}, {kelp::tether::LineModel::moordyn, "moordyn"}};
/// \brief The names of control::WinchStrategy (`tether.winch.strategy`; as
/// control::winch_strategy_name spells them).
inline constexpr ChoiceName<kelp::control::WinchStrategy> winch_strategy_names[] = {
    {kelp::control::WinchStrategy::hold, "hold"},
    {kelp::control::WinchStrategy::constant_tension, "constant_tension"},
    {kelp::control::WinchStrategy::slack, "slack"},
    {kelp::control::WinchStrategy::depth_following, "depth_following"}};
/// \brief The names of simd::KernelPath (`kernel`; as simd::kernel_name spells them).
inline constexpr ChoiceName<kelp::simd::KernelPath> kernel_path_names[] = {
    {kelp::simd::KernelPath::automatic, "auto"},
    {kelp::simd::KernelPath::portable, "portable"},
    {kelp::simd::KernelPath::avx2, "avx2"},
    {kelp::simd::KernelPath::avx512, "avx512"}};

/// \name Names of the choices
/// \brief A choice's name in scenario files ("invalid" for a value outside the enumeration).
/// @{

/// \brief The name of a NavigationMode (navigation_mode_names).
/// \param x the mode \return "perfect", "sensors" or "invalid" (static storage)
inline const char* to_string(NavigationMode x) {
  return choice_name(x, navigation_mode_names, "invalid");
}
/// \brief The name of a Sea (sea_names).
/// \param x the sea \return "calm", "moderate", "rough", "custom" or "invalid" (static storage)
inline const char* to_string(Sea x) { return choice_name(x, sea_names, "invalid"); }
/// \brief The name of a TetherKind (tether_kind_names).
/// \param x the kind \return "rov_tether", "bead_chain" or "invalid" (static storage)
inline const char* to_string(TetherKind x) { return choice_name(x, tether_kind_names, "invalid"); }
/// \brief The name of a ControlPreset (control_preset_names).
/// \param x the preset \return "kelp", "paper" or "invalid" (static storage)
inline const char* to_string(ControlPreset x) {
  return choice_name(x, control_preset_names, "invalid");
}
/// \brief The name of a tether::LineModel (line_model_names).
/// \param x the model \return "kelp", "moordyn" or "invalid" (static storage)
inline const char* to_string(kelp::tether::LineModel x) {
  return choice_name(x, line_model_names, "invalid");
}
/// \brief The name of a control::WinchStrategy (winch_strategy_names).
/// \param x the strategy
/// \return "hold", "constant_tension", "slack", "depth_following" or "invalid" (static storage)
inline const char* to_string(kelp::control::WinchStrategy x) {
  return choice_name(x, winch_strategy_names, "invalid");
}
/// \brief The name of a simd::KernelPath (kernel_path_names).
/// \param x the path \return "auto", "portable", "avx2", "avx512" or "invalid" (static storage)
inline const char* to_string(kelp::simd::KernelPath x) {
  return choice_name(x, kernel_path_names, "invalid");
}
/// \brief The name of an environment::WaveStretching (wave_stretching_names).
/// \param x the stretching \return "vertical", "wheeler" or "invalid" (static storage)
inline const char* to_string(kelp::environment::WaveStretching x) {
  return choice_name(x, wave_stretching_names, "invalid");
}
/// @}

/// \brief What the controllers navigate by (the scenario's `navigation` object): the true state
/// (NavigationMode::perfect, the default) or the estimates of kelp::nav's sensors and filters.
struct NavigationSettings {
  NavigationMode mode = NavigationMode::perfect;  ///< `mode`: "perfect" or "sensors"
  std::uint64_t seed = 1;                         ///< seed of the sensors' noise
  PairSensors sensors;  ///< every sensor's parameters (defaults: kelp/nav/sensors.hpp)
};

/// \brief A vehicle's battery in a scenario (`"battery": {"auv": {...}, "asv": {...}}`; see
/// kelp::vehicle::BatteryParameters for the meaning and units of each field).
struct BatteryScenario {
  double capacity_ah;          ///< rated capacity [Ah]
  int cells_in_series;         ///< series cells
  double internal_resistance;  ///< pack resistance [Ω]
  double initial_soc;          ///< state of charge at the start, [0, 1]
  double hotel_current;        ///< electronics and lights [A]
};

/// \brief The boat's winch of a scenario (`"tether": {"winch": {...}}`): the winch
/// (kelp::tether::WinchParameters) and its tether management settings
/// (kelp::control::TetherManagementSettings; the strategy is Scenario::winch_strategy).
/// Lengths in m, speeds in m/s, forces in N.
struct WinchScenario {
  bool enabled = false;        ///< a `winch` object was given
  double max_speed = 0.5,      ///< largest line speed, in or out [m/s] (> 0)
      max_acceleration = 0.5,  ///< largest change of line speed [m/s²] (> 0)
      max_pull = 400;          ///< largest pull it reels in against [N] (> 0)
  double min_length = 5,       ///< shortest line it leaves out [m] (≥ one segment)
      max_length = 60;         ///< longest line it pays out [m] (≥ min_length)
  double tension_low = 5,      ///< constant_tension: the band's low end [N]
      tension_high = 25,       ///< constant_tension: the band's high end [N] (> tension_low)
      tension_gain = 0.02;     ///< constant_tension: payout rate per N outside the band [m/s/N]
  double slack = 0.3;          ///< slack: line out over the attachments' distance, minus 1 [-]
  double extra_length = 3,     ///< depth_following: line out at depth 0 and no offset [m]
      length_per_depth = 1,    ///< depth_following: line out per metre of depth [m/m]
      length_per_offset = 1,   ///< depth_following: per metre of horizontal offset [m/m]
      length_gain = 0.5;       ///< slack, depth_following: payout rate per m of length error [1/s]
};

/// \brief A regular (Airy) wave of a custom sea (`"sea": {"regular": {...}}`;
/// environment::RegularWave): on top of the JONSWAP sea, or alone when significant_height is 0.
/// Exactly one of period and wavelength; deep water, like the scenario's spectral waves.
struct RegularWaveScenario {
  bool enabled = false;          ///< a `regular` object was given
  double height = 0;             ///< crest-to-trough height H [m]
  std::optional<double> period,  ///< period T [s] (unset: from wavelength)
      wavelength;                ///< wavelength λ [m] (unset: from period)
  double direction = 0;          ///< NED azimuth it travels towards [rad]
  double phase = 0;  ///< φ [rad]: ζ = (H/2) cos(k (x cos β + y sin β) − ω t + φ)
};

/// \brief What a fleet vehicle's controller does (`"controller": {"type": ...}`).
enum class FleetControl {
  none,       ///< no controller: its thrusters stay at 0 (an external controller's vehicle)
  hold,       ///< hold `position` and `heading` (an underwater vehicle: AUV controller; a
              ///< surface vehicle: station keeping)
  waypoints,  ///< follow `waypoints` along the legs at `leg_speed`, then hold the last
  follow,     ///< a surface vehicle following another vehicle (`target`) at `offset`
};

/// \brief The names of FleetControl in a scenario file.
inline constexpr ChoiceName<FleetControl> fleet_control_names[] = {
    {FleetControl::none, "none"},
    {FleetControl::hold, "hold"},
    {FleetControl::waypoints, "waypoints"},
    {FleetControl::follow, "follow"}};

/// \brief A fleet vehicle's controller. Units: m, rad, m/s; NED.
struct FleetControllerScenario {
  FleetControl type = FleetControl::none;                          ///< what it does
  kelp::Vector3<double> position = kelp::Vector3<double>::Zero();  ///< hold: the point
  double heading = 0;                                              ///< hold: the heading [rad]
  std::vector<kelp::Vector3<double>> waypoints;                    ///< waypoints: NED [m]
  double leg_speed = 0.5;                                          ///< waypoints [m/s]
  std::string target;                                              ///< follow: a vehicle's name
  kelp::Vector3<double> offset = kelp::Vector3<double>::Zero();    ///< follow: NED offset [m]
};

/// \brief A vehicle of a fleet scenario (`"fleet": {"vehicles": [...]}`).
struct FleetVehicleScenario {
  std::string name;  ///< unique; names its columns, topics and tether ends
  /// A preset's name ("bluerov2_heavy", "blueboat": sim::vehicle_preset) or a vehicle file
  /// (`.json`, docs/vehicle-files.md) or a Gazebo model (`.sdf`), relative to the scenario file.
  std::string vehicle;
  kelp::Vector3<double> start = kelp::Vector3<double>::Zero();  ///< NED position of the CO [m]
  double heading = 0;                                           ///< start heading [rad]
  FleetControllerScenario controller;                           ///< its controller
};

/// \brief A free point mass of a fleet scenario (kelp::system::PointMassParameters).
struct FleetPointMassScenario {
  std::string name;                  ///< unique
  double mass = 0,                   ///< its mass [kg]
      volume = 0,                    ///< its displaced volume [m³] (buoyancy)
      added_mass_coefficient = 0.5;  ///< added mass over displaced water's mass [-]
  double drag_area = 0;              ///< C_d A [m²]
  kelp::Vector3<double> start = kelp::Vector3<double>::Zero();  ///< NED [m]
};

/// \brief A fixed anchor of a fleet scenario: a named NED point [m] tethers end on (a dock on
/// the seabed, a ship's sheave held still).
struct FleetAnchorScenario {
  std::string name;                                                ///< unique
  kelp::Vector3<double> position = kelp::Vector3<double>::Zero();  ///< NED [m]
};

/// \brief A winch at a fleet tether's start end, paying out or reeling in at a constant
/// commanded rate within its limits (kelp::tether::WinchParameters).
struct FleetWinchScenario {
  bool enabled = false;        ///< a `winch` object was given
  double max_speed = 0.5,      ///< largest line speed, in or out [m/s]
      max_acceleration = 0.5,  ///< largest change of line speed [m/s²]
      max_pull = 400;          ///< largest pull it reels in against [N]
  double min_length = 5,       ///< shortest line it leaves out [m]
      max_length = 60;         ///< longest line it pays out [m]
  double payout_rate = 0;      ///< commanded [m/s] (positive: paying out; 0 at either limit)
};

/// \brief A tether of a fleet scenario, between two named ends (a vehicle, a point mass or an
/// anchor; `"free"` for a free end).
struct FleetTetherScenario {
  std::string name;  ///< unique
  std::string from;  ///< the start end's owner (the winch's side)
  std::string to;    ///< the far end's owner
  /// Attachment points on vehicles, body axes [m] (unset: the vehicle's file's attachment).
  std::optional<kelp::Vector3<double>> from_point,
      to_point;        ///< the far end's attachment on a vehicle, body axes [m] (unset: its file's)
  double length = 10;  ///< unstretched [m]
  double segment_length = 0.5;  ///< [m]
  /// The cable: the ROV tether preset (kelp::tether::presets::rov_tether) with these overrides
  /// (unset: the preset's; tether::TetherParameters has their meaning). The diameter [m].
  std::optional<double> diameter,
      mass_per_length,         ///< mass per unstretched length [kg/m]
      axial_stiffness,         ///< EA [N]
      internal_damping_ratio,  ///< internal damping as a ratio of critical [-]
      normal_drag,             ///< normal drag coefficient C_dn [-]
      tangential_drag,         ///< tangential drag coefficient C_dt [-]
      breaking_strength;       ///< tension at which it parts [N] (0: never)
  FleetWinchScenario winch;    ///< a winch at the start end (when enabled)
};

/// \brief A fleet scenario's parts (`"fleet": {...}`): with it, a scenario runs these vehicles,
/// point masses, anchors and tethers in its sea instead of the tethered pair (the pair's keys,
/// `tether`, `vehicles`, `control`, `mission`, `navigation`, `thrusters`, `battery`, do not
/// apply).
struct FleetScenario {
  std::vector<FleetVehicleScenario> vehicles;        ///< at least one
  std::vector<FleetPointMassScenario> point_masses;  ///< any
  std::vector<FleetAnchorScenario> anchors;          ///< any
  std::vector<FleetTetherScenario> tethers;          ///< any
};

/// \brief One run of the tethered pair, as a scenario file describes it (every field has the
/// embedded default run's value until a file sets it). Angles in rad, lengths in m, NED.
struct Scenario {
  double duration = 120.0;  ///< simulated time [s]
  std::uint64_t seed = 1;   ///< seed of the waves and gusts
  /// \name Sea: a preset ("calm", "moderate", "rough": the paper's) or Sea::custom with the
  /// values below (set by a `sea` object in the file; unused for a preset).
  ///@{
  Sea sea = Sea::moderate;
  double significant_height = 0, peak_period = 0, wave_direction = 0;
  double wind_speed = 0, wind_direction = 0, current_speed = 0, current_direction = 0;
  int wave_components = 64;
  /// A regular wave of the custom sea (unused for a preset).
  RegularWaveScenario regular_wave;
  /// Kinematics near the free surface of the custom sea's waves (unused for a preset).
  kelp::environment::WaveStretching wave_stretching = kelp::environment::WaveStretching::vertical;
  ///@}
  /// \name Tether: its length, its kind ("rov_tether" or "bead_chain") and segment length [m].
  ///@{
  double tether_length = 10.0;                      ///< unstretched length [m] (`tether.length`)
  TetherKind tether_kind = TetherKind::rov_tether;  ///< the cable's preset (`tether.kind`)
  double segment_length = 0.5;  ///< nominal segment length [m] (`tether.segment_length`)
  ///@}
  /// \name Cable properties overriding the kind's (unset: keep the preset's; see
  /// tether::TetherParameters for the units).
  ///@{
  std::optional<double> diameter, mass_per_length, axial_stiffness, internal_damping;
  /// The internal damping as a ratio of critical (tether::TetherParameters::
  /// internal_damping_ratio, MoorDyn's `BA/-zeta`); replaces the kind's BA; not with
  /// internal_damping.
  std::optional<double> internal_damping_ratio;
  std::optional<double> normal_drag, tangential_drag;
  /// The line model, "kelp" (default) or "moordyn" (MoorDyn v2's: kelp::tether::LineModel).
  kelp::tether::LineModel line_model = kelp::tether::LineModel::kelp;
  /// Breaking strength [N] (tether::TetherParameters::breaking_strength; 0: never parts; unset:
  /// the kind's, 1557 N for the rov_tether).
  std::optional<double> breaking_strength;
  ///@}
  /// Redo a tether step whose implicit solve fails with RK4 instead of stopping the run
  /// (system::SystemParameters::explicit_fallback; counted in the summary's
  /// `tether_solver.explicit_fallbacks`). Off by default: a run stops with an error instead.
  bool explicit_fallback = false;
  /// The boat's winch (`"tether": {"winch": {...}}`); disabled by default (a fixed length).
  WinchScenario winch;
  /// Its strategy: "hold", "constant_tension", "slack" or "depth_following" (kept here rather
  /// than in WinchScenario, which GCC 12 then warns about as maybe uninitialised in Scenario{}).
  kelp::control::WinchStrategy winch_strategy = kelp::control::WinchStrategy::depth_following;
  /// \name Vehicles: attachment points (body axes from the CO [m]) and the AUV's start (NED;
  /// unset: the paper's start, 5 m down astern of the boat).
  ///@{
  kelp::Vector3<double> asv_attachment{-0.5, 0, 0.08},  ///< on the boat, body axes from its CO [m]
      auv_attachment{-0.2, 0, -0.05};                   ///< on the ROV, body axes from its CO [m]
  /// The ROV's start position, NED [m] (unset: 5 m down astern of the boat, the paper's).
  std::optional<kelp::Vector3<double>> auv_start;
  ///@}
  /// \name Start (`"start": {"ramp": 10, "with_water": true}`): the sea (waves, current, wind)
  /// is ramped in over the first `start_ramp` seconds (environment::Environment::set_ramp; 0:
  /// the full sea at once), and with `start_with_water` the vehicles and the tether's nodes start
  /// moving with the water at their positions (current + wave orbital velocity at t = 0; zero
  /// while the ramp holds the sea at rest) instead of at rest in moving water.
  ///@{
  double start_ramp = 10.0;      ///< ramp-in time of the sea [s], in [0, 1e5] (0: none)
  bool start_with_water = true;  ///< start the bodies moving with the water (else at rest)
  ///@}
  /// \name Control: the preset, the paper's disturbance compensation, the PID gains, the ASV's
  /// thrust clip [N] and the controllers' rates [Hz].
  ///@{
  /// "kelp" (default): the boat tracks the ROV's velocity and position
  /// (control::AsvLaw::track), thrust clip 25 N; "paper": Buchholz et al.'s pursuit with their
  /// gains (`asv_linear`, `asv_angular`, `asv_yaw`: used by this preset only), clip 15 N.
  ControlPreset control_preset = ControlPreset::kelp;
  bool compensation = false;
  Gains asv_linear{0.5, 0.1, 0.05}, asv_angular{4.0, 2.0, 1.0}, asv_yaw{2.0, 0.0, 0.5};
  double asv_thrust_clip = 25.0, asv_rate = 10.0;
  /// The boat keeps station at its start position and heading (`"control": {"asv":
  /// {"station": true}}`) instead of following the ROV (e.g. a ROV working round a pile while
  /// its boat waits off it).
  bool asv_station = false;
  double auv_rate = 50.0;
  Gains auv_surge{40.0, 4.0, 56.0}, auv_sway{40.0, 4.0, 56.0}, auv_heave{60.0, 8.0, 88.0},
      auv_yaw{5.0, 0.2, 3.4};
  ///@}
  /// \name Mission: NED waypoints [m]; empty: a square of side `square_side` at `depth` from the
  /// start.
  ///@{
  std::vector<kelp::Vector3<double>> waypoints;  ///< the ROV's waypoints, NED [m] (empty: square)
  double depth = 5.0,                            ///< the default square's depth, NED z [m]
      square_side = 8.0;                         ///< the default square's side [m]
  ///@}
  /// \name Output: rows of timeseries.csv and snapshots of nodes.csv per simulated second [Hz].
  ///@{
  double log_rate = 10.0, node_rate = 1.0;
  /// Write run.mcap, a ROS 2 bag of the run (kelp/sim/ros2.hpp), beside the CSV log.
  bool mcap = true;
  ///@}
  /// Instruction path of the wave kernel (kelp/core/kernel_path.hpp): "auto" (automatic: the
  /// process' policy, i.e. `KELP_KERNEL`, else the widest the CPU runs), "portable" (the
  /// deterministic mode: the same bits on every CPU; the file's `"deterministic": true`), "avx2"
  /// or "avx512".
  kelp::simd::KernelPath kernel = kelp::simd::KernelPath::automatic;
  /// Navigation: perfect or from sensors.
  NavigationSettings navigation;
  /// \name Propulsion: the thrusters and batteries as part of the system (`"thrusters"`,
  /// `"battery"`): on by default (the controllers' per-thruster commands drive the T200 model
  /// through a first-order lag of `thruster_time_constant` [s] when `thruster_lag`, drawing from
  /// the batteries); `propulsion` false: the controllers' wrench is applied directly (the
  /// behaviour of kelp 0.1.0). Defaults: kelp::vehicle::battery_presets.
  ///@{
  bool propulsion = true;    ///< thrusters and batteries modelled (false: wrench applied directly)
  bool thruster_lag = true;  ///< a first-order lag between command and thrust
  double thruster_time_constant = 0.02;  ///< the lag's time constant [s], in [0, 10]
  BatteryScenario asv_battery{31.2, 4, 0.02, 1.0, 0.0};  ///< the boat's battery (4S, 31.2 Ah)
  BatteryScenario auv_battery{15.6, 4, 0.04, 1.0, 0.0};  ///< the ROV's battery (4S, 15.6 Ah)
  ///@}
  /// \name Obstacles and seabed (`"obstacles": [...]`, `"seabed": {...}`; none by default).
  ///@{
  /// Cylinders (`{"type": "cylinder", "name", "from", "to", "radius"}`), in file order.
  std::vector<kelp::environment::Cylinder> cylinders;
  /// Boxes (`{"type": "box", "name", "center", "half_extents", "yaw"}`, optional `roll`,
  /// `pitch`), in file order. Every obstacle may set `friction` (μ), `stiffness` [Pa/m],
  /// `damping` [Pa s/m] (kelp::environment::ContactProperties).
  std::vector<kelp::environment::Box> boxes;
  /// NED z of a flat seabed [m] (`"seabed": {"depth": m}`); +∞: none.
  double seabed_depth = std::numeric_limits<double>::infinity();
  /// A height-field seabed (`"seabed": {"heightfield": "file"}` in MoorDyn's seafloor format,
  /// kelp::sim::load_heightfield, a path relative to the scenario file; or inline,
  /// `{"origin": [n, e], "spacing": [dn, de], "size": [rows, cols], "depth": [...]}`); unset:
  /// none.
  std::optional<kelp::environment::HeightField> heightfield;
  /// The height field's file as the scenario names it (empty: given inline).
  std::string heightfield_file;
  /// Seabed Coulomb friction μ of the tether on the seabed, flat or height field
  /// (`"seabed": {"friction": μ}`; tether::TetherParameters::seabed_friction); unset: the
  /// tether's.
  std::optional<double> seabed_friction;
  ///@}
  /// The thresholds of the tether's entanglement events (`"entanglement": {"wrap_threshold":
  /// rad, "wrap_hysteresis": rad, "contact_margin": m, "pin_slip_speed": m/s,
  /// "pin_tension_difference": N, "pin_hold_time": s}`; kelp/sim/entanglement.hpp).
  EntanglementSettings entanglement;
  /// Any fleet instead of the pair (`"fleet"`; unset: the tethered pair).
  std::optional<FleetScenario> fleet;
};

/// \brief The scenario's obstacles (cylinders, boxes, height-field seabed) as an ObstacleSet
/// (cylinders first, then boxes: the set's flat indices). Empty when the scenario has none.
/// \param[in] s the scenario (its `cylinders`, `boxes` and `heightfield`; NED [m])
/// \return the set (the flat seabed, `seabed_depth`, is not part of it)
/// \throws kelp::invalid_argument for an obstacle the set refuses (parse_scenario checks them).
KELP_SIM_API kelp::environment::ObstacleSet obstacle_set(const Scenario& s);

/// \brief Reads and validates a scenario from JSON text.
/// \param[in] text the JSON text \param[in] file names the scenario in error messages
/// \return the scenario, every field the text leaves out at its default
/// \throws scenario_error naming the file, the JSON path and what was expected (also for JSON
/// nested too deep or not valid JSON).
KELP_SIM_API Scenario parse_scenario(const std::string& text, const std::string& file);

/// \brief Reads a scenario file (parse_scenario() of its text).
/// \param[in] file the file's path (also names it in errors)
/// \return the scenario \throws scenario_error naming the file (also when it cannot be read).
KELP_SIM_API Scenario load_scenario(const std::string& file);

/// \brief The scenario as JSON text, every field with its value (echoed in the run's summary; it
/// reads back through parse_scenario to the same scenario); `kernel` only when it is not "auto".
/// \param[in] s the scenario
/// \param[in] indent spaces per level, or -1 (the default) for one line.
/// \return the JSON text (UTF-8).
KELP_SIM_API std::string scenario_json(const Scenario& s, int indent = -1);

}  // namespace sim
}  // namespace kelp
