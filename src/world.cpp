// The world of a scenario: its system, sea and start (kelp/sim/world.hpp).
#include "kelp/sim/world.hpp"

#include "cable.hpp"

#include <cmath>
#include <limits>
#include <string>
#include "kelp/core/kernel_path.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/system.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/surroundings.hpp"

namespace kelp {
namespace sim {

namespace {
// A Scenario built by hand may hold a value cast from an integer: named as the file's error.
[[noreturn]] void refuse(const std::string& file, const char* path, int value) {
  throw scenario_error(file + ": " + path + ": " + std::to_string(value) +
                       " is not one of its choices");
}
}  // namespace

void apply_cable(const CableOverrides& c, kelp::tether::TetherParametersd& p) {
  if (c.internal_damping && c.internal_damping_ratio)
    throw kelp::invalid_argument(
        "tether: internal_damping and internal_damping_ratio are both given: give BA [N s] or "
        "the damping ratio, not both");
  if (c.diameter) p.diameter = *c.diameter;
  if (c.mass_per_length) p.mass_per_length = *c.mass_per_length;
  if (c.axial_stiffness) p.axial_stiffness = *c.axial_stiffness;
  if (c.internal_damping) p.internal_damping = *c.internal_damping;
  if (c.internal_damping_ratio) {
    p.internal_damping = 0.0;  // the kind's BA gives way to the ratio
    p.internal_damping_ratio = *c.internal_damping_ratio;
  }
  if (c.normal_drag) p.normal_drag = *c.normal_drag;
  if (c.tangential_drag) p.tangential_drag = *c.tangential_drag;
  if (c.breaking_strength) p.breaking_strength = *c.breaking_strength;
}

kelp::environment::Environmentd scenario_environment(const Scenario& sc, const std::string& file) {
  namespace ke = kelp::environment;
  if (!choice_name(sc.sea, sea_names)) refuse(file, "/sea", static_cast<int>(sc.sea));
  if (!choice_name(sc.kernel, kernel_path_names))
    refuse(file, "/kernel", static_cast<int>(sc.kernel));
  if (!choice_name(sc.wave_stretching, wave_stretching_names))
    refuse(file, "/sea/stretching", static_cast<int>(sc.wave_stretching));
  ke::SeaStateOptions sea_options;
  sea_options.seed = sc.seed;
  sea_options.wave_components = sc.wave_components;
  sea_options.ramp = sc.start_ramp;
  ke::SeaState sea = ke::presets::calm();
  if (sc.sea == Sea::moderate) sea = ke::presets::moderate();
  if (sc.sea == Sea::rough) sea = ke::presets::rough();
  if (sc.sea == Sea::custom) {
    sea = ke::SeaState{};  // no waves unless a height is given
    sea.significant_height = sc.significant_height;
    sea.peak_period = sc.peak_period;
    if (sc.significant_height > 0)
      sea.peak_enhancement = ke::dnv_peak_enhancement(sc.significant_height, sc.peak_period);
    sea.wind_speed = sc.wind_speed;
    sea.current_speed = sc.current_speed;
    sea.wave_direction = sc.wave_direction;
    sea.wind_direction = sc.wind_direction;
    sea.current_direction = sc.current_direction;
    sea_options.stretching = sc.wave_stretching;
    if (sc.regular_wave.enabled) {
      const RegularWaveScenario& r = sc.regular_wave;
      ke::RegularWave w;
      w.height = r.height;
      w.period = r.period.value_or(0.0);
      w.wavelength = r.wavelength.value_or(0.0);
      w.direction = r.direction;
      w.phase = r.phase;
      // The environment's checks (exactly one of period and wavelength, the breaking limit),
      // in deep water as the scenario's waves are, named as the file's error.
      try {
        ke::validate(w, kelp::standard_gravity, std::numeric_limits<double>::infinity());
      } catch (const kelp::invalid_argument& e) {
        throw scenario_error(file + ": /sea/regular: " + e.what());
      }
      sea.regular_waves.push_back(w);
    }
  }
  ke::Environmentd env = ke::make_environment<double>(sea, sea_options);
  // The wave kernel's instruction path: pinned by the scenario (a path this CPU lacks is named
  // as the file's error), else the process' policy (a bad KELP_KERNEL throws
  // kelp::invalid_argument naming it); resolved here, before the run's first step.
  if (sc.kernel != kelp::simd::KernelPath::automatic) {
    ke::WaveFieldd waves = env.waves();
    try {
      waves.set_kernel(sc.kernel);
    } catch (const kelp::invalid_argument& e) {
      throw scenario_error(file + ": /kernel: " + e.what());
    }
    env.set_waves(waves);
  }
  env.waves().active_kernel();
  // Seabed and obstacles (kelp/environment/obstacles.hpp; the tether touches them through the
  // environment, kelp/tether/contact.hpp).
  if (std::isfinite(sc.seabed_depth)) env.set_seabed_depth(sc.seabed_depth);
  env.set_obstacles(obstacle_set(sc));
  return env;
}

WorldSetup world_setup(const Scenario& sc, const std::string& file) {
  if (sc.fleet)
    throw scenario_error(file +
                         ": /fleet: a fleet scenario runs with kelp-tethered-pair "
                         "(kelp::sim::run_fleet), not in the tethered pair's world");
  namespace sp = kelp::system::presets;
  namespace ke = kelp::environment;
  const sp::TetherKind kind = sc.tether_kind == TetherKind::bead_chain ? sp::TetherKind::bead_chain
                                                                       : sp::TetherKind::rov_tether;
  kelp::system::SystemParametersd params = sp::paper_system(sc.tether_length, kind);
  if (kind == sp::TetherKind::rov_tether)
    params.tether = kelp::tether::presets::rov_tether(sc.tether_length, sc.segment_length);
  auto& tp = params.tether;
  apply_cable({sc.diameter, sc.mass_per_length, sc.axial_stiffness, sc.internal_damping,
               sc.internal_damping_ratio, sc.normal_drag, sc.tangential_drag, sc.breaking_strength},
              tp);
  params.explicit_fallback = sc.explicit_fallback;
  // A Scenario built by hand may hold a value cast from an integer: named as the file's error.
  if (!choice_name(sc.line_model, line_model_names))
    refuse(file, "/tether/line_model", static_cast<int>(sc.line_model));
  if (!choice_name(sc.tether_kind, tether_kind_names))
    refuse(file, "/tether/kind", static_cast<int>(sc.tether_kind));
  // (the sea's choices: scenario_environment)
  tp.line_model = sc.line_model;
  if (sc.winch.enabled) {
    kelp::tether::WinchParameters<double> w;
    w.max_speed = sc.winch.max_speed;
    w.max_acceleration = sc.winch.max_acceleration;
    w.max_pull = sc.winch.max_pull;
    w.min_length = sc.winch.min_length;
    w.max_length = sc.winch.max_length;
    params.winch = w;
  }
  params.asv_attachment = sc.asv_attachment;
  params.auv_attachment = sc.auv_attachment;
  // Propulsion: the paper preset's (thrusters, batteries) with the scenario's lag and batteries,
  // or none.
  if (!sc.propulsion) {
    params.asv_propulsion.reset();
    params.auv_propulsion.reset();
  } else {
    const auto apply = [&](kelp::vehicle::PropulsionParametersd& p, const BatteryScenario& b) {
      p.time_constant = sc.thruster_lag ? sc.thruster_time_constant : 0.0;
      p.battery.capacity_ah = b.capacity_ah;
      p.battery.cells_in_series = b.cells_in_series;
      p.battery.internal_resistance = b.internal_resistance;
      p.battery.initial_soc = b.initial_soc;
      p.battery.hotel_current = b.hotel_current;
    };
    apply(*params.asv_propulsion, sc.asv_battery);
    apply(*params.auv_propulsion, sc.auv_battery);
  }
  sp::StartPoses<double> start = sp::paper_start(sc.tether_length);
  if (sc.auv_start) start.auv.position = *sc.auv_start;
  const double span = (start.auv.point_position(params.auv_attachment) -
                       start.asv.point_position(params.asv_attachment))
                          .norm();
  if (span > sc.tether_length)
    throw scenario_error(file + ": /tether/length: " + std::to_string(sc.tether_length) +
                         " m is shorter than the initial distance between its ends (" +
                         std::to_string(span) + " m)");
  ke::Environmentd env = scenario_environment(sc, file);
  if (sc.seabed_friction) tp.seabed_friction = *sc.seabed_friction;
  // The hulls against the seabed and the obstacles (kelp/system/hull_contact.hpp), when there is
  // something to touch: in open water without a seabed a run is as it was.
  if (env.obstacles() != nullptr || std::isfinite(env.seabed_depth())) {
    params.asv_hull = kelp::system::blueboat_hull<double>();
    params.auv_hull = kelp::system::bluerov2_heavy_hull<double>();
  }
  return {params, env, start};
}

kelp::system::SystemStated start_state(const kelp::system::SystemModeld& model,
                                       kelp::system::SystemWorkspaced& ws, const WorldSetup& world,
                                       const Scenario& sc) {
  kelp::system::SystemStated s =
      kelp::system::initial_state(model, ws, world.start.asv, world.start.auv);
  if (sc.start_with_water) {
    const auto& env = model.environment();
    for (kelp::vehicle::VehicleState<double>* v : {&s.asv, &s.auv}) {
      const auto e = env.sample(v->position, s.time, false);
      v->nu.head<3>() = v->attitude.conjugate() * (e.current + e.wave_velocity);
      v->nu.tail<3>().setZero();
    }
    kelp::tether::move_with_water(model.tether(), env, s.tether);
  }
  return s;
}

}  // namespace sim
}  // namespace kelp
