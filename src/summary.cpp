// A run's summary as JSON (kelp/sim/summary.hpp): summary.json's one writer. nlohmann-json's
// objects keep their keys sorted, so the text does not depend on the order written here.
#include "kelp/sim/summary.hpp"

#include <cmath>
#include <string>

#include "scenario_json.hpp"
#include "summary_json.hpp"

namespace kelp {
namespace sim {

namespace {

nlohmann::json number_or_null(double x) {
  return std::isnan(x) ? nlohmann::json(nullptr) : nlohmann::json(x);
}

nlohmann::json position_json(const std::array<double, 3>& p) {
  return nlohmann::json::array({p[0], p[1], p[2]});
}

void battery_json(const std::optional<BatterySummary>& b, nlohmann::json& out) {
  if (!b) return;
  out["energy_wh"] = b->energy_wh;
  out["final_soc"] = b->final_soc;
}

nlohmann::json event_json(const EntanglementEventSummary& v) {
  nlohmann::json j = {{"event", v.event},
                      {"time_s", v.time_s},
                      {"obstacle", v.obstacle},
                      {"position_m", position_json(v.position_m)}};
  if (v.event == "entangled")
    j["winding_rad"] = v.value;
  else
    j["tension_difference_n"] = v.value;
  return j;
}

nlohmann::json navigation_json(const NavigationSummary& n) {
  nlohmann::json j = {{"mode", to_string(n.mode)}};
  if (!n.errors) return j;
  const NavigationErrorsSummary& e = *n.errors;
  j["seed"] = e.seed;
  j["auv_rms_position_error_m"] = e.auv_rms_position_error_m;
  j["auv_rms_horizontal_error_m"] = e.auv_rms_horizontal_error_m;
  j["auv_max_position_error_m"] = e.auv_max_position_error_m;
  j["auv_rms_heading_error_deg"] = e.auv_rms_heading_error_deg;
  j["auv_rms_velocity_error_m_s"] = e.auv_rms_velocity_error_m_s;
  j["asv_rms_position_error_m"] = e.asv_rms_position_error_m;
  j["asv_rms_horizontal_error_m"] = e.asv_rms_horizontal_error_m;
  j["asv_max_position_error_m"] = e.asv_max_position_error_m;
  j["asv_rms_heading_error_deg"] = e.asv_rms_heading_error_deg;
  j["asv_rms_velocity_error_m_s"] = e.asv_rms_velocity_error_m_s;
  j["usbl"] = {
      {"pings", e.usbl_pings}, {"dropouts", e.usbl_dropouts}, {"fixes_used", e.usbl_fixes_used}};
  j["dvl_pings"] = {
      {"bottom", e.dvl_pings_bottom}, {"water", e.dvl_pings_water}, {"none", e.dvl_pings_none}};
  return j;
}

nlohmann::json entanglement_json(const EntanglementSummary& e) {
  const EntanglementSettings& x = e.settings;
  nlohmann::json j;
  j["settings"] = {{"wrap_threshold_rad", x.wrap_threshold},
                   {"wrap_hysteresis_rad", x.wrap_hysteresis},
                   {"contact_margin_m", x.contact_margin},
                   {"pin_slip_speed_m_s", x.pin_slip_speed},
                   {"pin_tension_difference_n", x.pin_tension_difference},
                   {"pin_hold_time_s", x.pin_hold_time}};
  nlohmann::json obstacles = nlohmann::json::array();
  for (const ObstacleWindingSummary& w : e.obstacles) {
    nlohmann::json events = nlohmann::json::array();
    for (const EntanglementEventSummary& v : w.events) events.push_back(event_json(v));
    obstacles.push_back({{"name", w.name},
                         {"index", w.index},
                         {"max_abs_winding_rad", w.max_abs_winding_rad},
                         {"final_winding_rad", w.final_winding_rad},
                         {"entangled_s", number_or_null(w.entangled_s)},
                         {"pinned_s", number_or_null(w.pinned_s)},
                         {"events", events}});
  }
  j["obstacles"] = obstacles;
  nlohmann::json all = nlohmann::json::array();
  for (const EntanglementEventSummary& v : e.events) all.push_back(event_json(v));
  j["events"] = all;
  j["dropped_events"] = e.dropped_events;
  return j;
}

}  // namespace

nlohmann::json solver_summary_to_json(const SolverSummary& s) {
  nlohmann::json j;
  j["integrator"] = s.integrator;
  j["newton_budget"] = s.newton_budget;
  j["explicit_fallback"] = s.explicit_fallback;
  j["steps"] = s.steps;
  j["tether_steps"] = s.tether_steps;
  j["newton_iterations"] = s.newton_iterations;
  j["newton_iterations_per_step_mean"] = s.newton_iterations_per_step_mean;
  j["newton_iterations_per_step_max"] = s.newton_iterations_per_step_max;
  j["newton_iterations_per_tether_step_mean"] = s.newton_iterations_per_tether_step_mean;
  j["retried_steps"] = s.retried_steps;
  j["explicit_fallbacks"] = s.explicit_fallbacks;
  j["force_evaluations"] = s.force_evaluations;
  j["worst_residual_m_s"] = number_or_null(s.worst_residual_m_s);
  j["worst_rejected_residual_m_s"] = number_or_null(s.worst_rejected_residual_m_s);
  j["residual_tolerance_m_s"] = s.residual_tolerance_m_s;
  return j;
}

nlohmann::json summary_to_json(const RunSummary& s) {
  nlohmann::json j;
  j["completed"] = s.completed;
  j["simulated_s"] = s.simulated_s;
  j["auv"] = {{"rms_path_error_m", s.auv.rms_path_error_m},
              {"max_path_error_m", s.auv.max_path_error_m},
              {"waypoints_reached", s.auv.waypoints_reached},
              {"second_half_max_depth_error_m", s.auv.second_half_max_depth_error_m},
              {"second_half_max_path_error_m", s.auv.second_half_max_path_error_m}};
  battery_json(s.auv.battery, j["auv"]);
  j["asv"] = {{"rms_distance_to_auv_m", s.asv.rms_distance_to_auv_m},
              {"max_distance_to_auv_m", s.asv.max_distance_to_auv_m},
              {"second_half_max_distance_to_auv_m", s.asv.second_half_max_distance_to_auv_m}};
  battery_json(s.asv.battery, j["asv"]);
  const TetherSummary& t = s.tether;
  nlohmann::json& tj = j["tether"];
  tj = {{"max_tension_n", t.max_tension_n},
        {"mean_tension_auv_n", t.mean_tension_auv_n},
        {"slack_fraction", t.slack_fraction},
        {"net_turns", t.net_turns},
        {"max_abs_turns", t.max_abs_turns}};
  nlohmann::json parted = nlohmann::json::array();
  for (const LineFailureSummary& f : t.line_failures)
    parted.push_back({{"time_s", f.time_s},
                      {"segment", f.segment},
                      {"position_m", position_json(f.position_m)},
                      {"tension_n", f.tension_n}});
  tj["line_failures"] = parted;
  tj["line_mass_start_kg"] = t.line_mass_start_kg;
  tj["line_mass_end_kg"] = t.line_mass_end_kg;
  tj["length_start_m"] = t.length_start_m;
  tj["length_end_m"] = t.length_end_m;
  if (t.winch)
    tj["winch"] = {{"strategy", t.winch->strategy},
                   {"nodes_inserted", t.winch->nodes_inserted},
                   {"nodes_removed", t.winch->nodes_removed},
                   {"remesh_kinetic_energy_lost_j", t.winch->remesh_kinetic_energy_lost_j},
                   {"min_length_m", t.winch->min_length_m},
                   {"max_length_m", t.winch->max_length_m}};
  j["tether_solver"] = solver_summary_to_json(s.tether_solver);
  j["energy_j"] = s.energy_j;
  j["kernel"] = s.kernel;
  j["math_library"] = s.math_library;
  j["navigation"] = navigation_json(s.navigation);
  j["entanglement"] = entanglement_json(s.entanglement);
  j["scenario_file"] = s.scenario_file;
  j["scenario"] = scenario_to_json(s.scenario);
  if (s.wall_s) j["wall_s"] = *s.wall_s;
  if (s.realtime_factor) j["realtime_factor"] = *s.realtime_factor;
  if (s.kelp_version) j["kelp_version"] = *s.kelp_version;
  return j;
}

std::string summary_json(const RunSummary& s, int indent) {
  return summary_to_json(s).dump(indent);
}

std::string solver_summary_json(const SolverSummary& s, int indent) {
  return solver_summary_to_json(s).dump(indent);
}

}  // namespace sim
}  // namespace kelp
