/// \file
/// \brief A run's summary as typed values (RunSummary) and its JSON text (summary_json(): what
/// kelp-tethered-pair writes as summary.json and `kelp.run_scenario` returns as a dict).
///
/// Units are in the field names as in summary.json (`_m`, `_n`, `_s`, `_j`, `_wh`, `_deg`,
/// `_rad`); an unset `std::optional` is a field summary.json leaves out, a NaN a `null`. Part of
/// the compiled `kelp::sim` component.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "kelp/sim/export.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {

/// \brief What a vehicle's battery delivered (with propulsion).
struct BatterySummary {
  double energy_wh = 0;  ///< energy drawn [Wh]
  double final_soc = 0;  ///< state of charge at the end, [0, 1]
};

/// \brief The AUV's tracking of its survey (`auv`).
struct AuvSummary {
  double rms_path_error_m = 0;               ///< RMS distance from the leg it flies [m]
  double max_path_error_m = 0;               ///< largest such distance [m]
  std::size_t waypoints_reached = 0;         ///< index of the waypoint it flies to at the end
  double second_half_max_depth_error_m = 0;  ///< second half: largest |depth − target| [m]
  double second_half_max_path_error_m = 0;   ///< second half: largest path error [m]
  std::optional<BatterySummary> battery;     ///< with propulsion
};

/// \brief The ASV's following of the AUV (`asv`).
struct AsvSummary {
  double rms_distance_to_auv_m = 0;              ///< RMS horizontal distance to the AUV [m]
  double max_distance_to_auv_m = 0;              ///< largest such distance [m]
  double second_half_max_distance_to_auv_m = 0;  ///< second half: the largest [m]
  std::optional<BatterySummary> battery;         ///< with propulsion
};

/// \brief One parting of the line (kelp/tether/failure.hpp).
struct LineFailureSummary {
  double time_s = 0;                   ///< when [s]
  int segment = -1;                    ///< which segment
  std::array<double, 3> position_m{};  ///< where (NED) [m]
  double tension_n = 0;                ///< under what force [N]
};

/// \brief The winch's work over the run (`tether.winch`).
struct WinchSummary {
  std::string strategy;                     ///< its tether management strategy
  int nodes_inserted = 0;                   ///< re-meshing: nodes inserted
  int nodes_removed = 0;                    ///< re-meshing: nodes removed
  double remesh_kinetic_energy_lost_j = 0;  ///< kinetic energy the re-meshing removed [J]
  double min_length_m = 0;                  ///< shortest unstretched length [m]
  double max_length_m = 0;                  ///< longest unstretched length [m]
};

/// \brief The tether over the run (`tether`).
struct TetherSummary {
  double max_tension_n = 0;       ///< largest end force, either end [N]
  double mean_tension_auv_n = 0;  ///< mean end force at the AUV [N]
  double slack_fraction = 0;      ///< fraction of samples under 0.1 N at the AUV
  double net_turns = 0;           ///< the AUV's turns about the tether (TurnCounter)
  double max_abs_turns = 0;       ///< the largest |turns|
  std::vector<LineFailureSummary> line_failures;  ///< partings, in time order
  double line_mass_start_kg = 0;                  ///< structural mass of the line at the start [kg]
  double line_mass_end_kg = 0;                    ///< and at the end [kg]
  double length_start_m = 0;                      ///< unstretched length at the start [m]
  double length_end_m = 0;                        ///< and at the end [m]
  std::optional<WinchSummary> winch;              ///< with a winch
};

/// \brief How hard the tether's solver worked (`tether_solver`): the integrator, the Newton
/// budget and whether the explicit safety net was on, then the counts of the run's statistics
/// (kelp::system::SolverStats). A worst residual is NaN (`null`) when an attempt diverged to a
/// non-finite state.
struct SolverSummary {
  std::string integrator;                             ///< the tether integrator's name
  int newton_budget = 0;                              ///< Newton iterations allowed per solve
  bool explicit_fallback = false;                     ///< the RK4 safety net was on
  long steps = 0;                                     ///< system steps
  long tether_steps = 0;                              ///< tether sub-steps
  long newton_iterations = 0;                         ///< Newton iterations in all
  double newton_iterations_per_step_mean = 0;         ///< per system step
  int newton_iterations_per_step_max = 0;             ///< the most in one system step
  double newton_iterations_per_tether_step_mean = 0;  ///< per tether sub-step
  long retried_steps = 0;                             ///< sub-steps retried shorter
  long explicit_fallbacks = 0;                        ///< sub-steps redone with RK4
  long force_evaluations = 0;                         ///< force passes
  double worst_residual_m_s = 0;                      ///< worst accepted residual [m/s]
  double worst_rejected_residual_m_s = 0;  ///< worst rejected residual [m/s]; NaN: diverged
  double residual_tolerance_m_s = 0;       ///< tolerance of a full tether sub-step [m/s]
};

/// \brief The estimates' errors of the sensors-and-filters navigation (`navigation` with mode
/// "sensors"): RMS over every step after t = 0.
struct NavigationErrorsSummary {
  std::uint64_t seed = 0;                 ///< the sensors' seed
  double auv_rms_position_error_m = 0;    ///< 3-D [m]
  double auv_rms_horizontal_error_m = 0;  ///< north and east [m]
  double auv_max_position_error_m = 0;    ///< largest 3-D [m]
  double auv_rms_heading_error_deg = 0;   ///< [deg]
  double auv_rms_velocity_error_m_s = 0;  ///< body velocity [m/s]
  double asv_rms_position_error_m = 0;    ///< 3-D [m]
  double asv_rms_horizontal_error_m = 0;  ///< north and east [m]
  double asv_max_position_error_m = 0;    ///< largest 3-D [m]
  double asv_rms_heading_error_deg = 0;   ///< [deg]
  double asv_rms_velocity_error_m_s = 0;  ///< body velocity [m/s]
  long usbl_pings = 0;                    ///< USBL pings
  long usbl_dropouts = 0;                 ///< USBL pings lost
  long usbl_fixes_used = 0;               ///< USBL fixes fused
  long dvl_pings_bottom = 0;              ///< DVL pings locked on the bottom
  long dvl_pings_water = 0;               ///< DVL pings water-tracking
  long dvl_pings_none = 0;                ///< DVL pings with no lock
};

/// \brief What the controllers navigated by (`navigation`).
struct NavigationSummary {
  NavigationMode mode = NavigationMode::perfect;  ///< "perfect" or "sensors" (to_string)
  std::optional<NavigationErrorsSummary> errors;  ///< with "sensors"
};

/// \brief One entanglement event (`entanglement.events`).
struct EntanglementEventSummary {
  std::string event;                   ///< "entangled" or "pinned"
  double time_s = 0;                   ///< when [s]
  std::string obstacle;                ///< the cylinder's name
  std::array<double, 3> position_m{};  ///< the contact's middle node (NED) [m]
  /// entangled: the winding [rad] (`winding_rad`); pinned: the tension difference [N]
  /// (`tension_difference_n`).
  double value = 0;
};

/// \brief The tether's winding about one cylinder (`entanglement.obstacles`).
struct ObstacleWindingSummary {
  std::string name;                ///< the cylinder's name
  int index = 0;                   ///< its index in the scenario's obstacles
  double max_abs_winding_rad = 0;  ///< largest |winding| [rad]
  double final_winding_rad = 0;    ///< winding at the end [rad]
  double entangled_s = 0;          ///< first `entangled` event [s]; NaN (`null`): none
  double pinned_s = 0;             ///< first `pinned` event [s]; NaN (`null`): none
  std::vector<EntanglementEventSummary> events;  ///< its events
};

/// \brief The tether's entanglement (`entanglement`): the thresholds, each cylinder and every
/// event in time order.
struct EntanglementSummary {
  EntanglementSettings settings;                  ///< the thresholds
  std::vector<ObstacleWindingSummary> obstacles;  ///< every cylinder
  std::vector<EntanglementEventSummary> events;   ///< all events, in time order
  long dropped_events = 0;                        ///< events past the monitor's capacity
};

/// \brief A run's summary (summary.json).
struct RunSummary {
  /// The run simulated its whole duration (`completed`); false: it was stopped (a signal,
  /// kelp/sim/stop.hpp) or the summary was taken before its end.
  bool completed = true;
  /// Simulated time [s]: the scenario's duration when completed, else the time reached.
  double simulated_s = 0;
  AuvSummary auv;                           ///< the AUV
  AsvSummary asv;                           ///< the ASV
  TetherSummary tether;                     ///< the tether
  SolverSummary tether_solver;              ///< the tether's solver
  double energy_j = 0;                      ///< the system's total energy at the end [J]
  std::string kernel;                       ///< the wave kernel's instruction path
  std::string math_library;                 ///< fingerprint of the C library's math
  NavigationSummary navigation;             ///< the navigation
  EntanglementSummary entanglement;         ///< the entanglement
  std::string scenario_file;                ///< the scenario's file, or "(embedded default)"
  Scenario scenario;                        ///< the scenario, every field as used
  std::optional<double> wall_s;             ///< wall-clock time of the run [s] (simulate())
  std::optional<double> realtime_factor;    ///< simulated / wall-clock time (simulate())
  std::optional<std::string> kelp_version;  ///< the program's version (finish_run())
};

/// \brief The summary as JSON text (objects' keys sorted), as summary.json holds it.
/// \param[in] s the summary. \param[in] indent spaces per level, or -1 for one line.
/// \return the JSON text (UTF-8; SI units, as the summary's fields say).
KELP_SIM_API std::string summary_json(const RunSummary& s, int indent = -1);

/// \brief The solver's summary as JSON text (`tether_solver`'s object).
/// \param[in] s the solver's summary. \param[in] indent spaces per level, or -1 for one line.
/// \return the JSON text.
KELP_SIM_API std::string solver_summary_json(const SolverSummary& s, int indent = -1);

}  // namespace sim
}  // namespace kelp
