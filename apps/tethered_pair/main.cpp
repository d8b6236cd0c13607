// kelp-tethered-pair: a BlueBoat and a BlueROV2 Heavy joined by a 10 m tether in the paper's
// moderate sea. The ROV flies a 10 m square survey at 5 m depth; the boat follows it. Writes a
// time series (CSV), tether node positions (CSV), a JSON summary, the 3-D replay (replay.html)
// and, through plot_run.py, PNG plots into the output directory.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#ifdef KELP_WITH_ROS2
#include "bridge.hpp"
#endif
#include "common/progress.hpp"
#include "common/replay_template.hpp"
#include "kelp/sim/checkpoint.hpp"
#include "kelp/sim/fleet_run.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/run.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/stop.hpp"
#include "kelp/version.hpp"

namespace fs = std::filesystem;

namespace {

struct Options {
  kelp::sim::Scenario scenario;
  std::string scenario_file = "(embedded default)";
  std::string out = "kelp-run";
  bool quiet = false;
  bool no_plots = false;
  bool ros2 = false;            // --ros2: live ROS 2 topics over DDS (apps/ros2_bridge/)
  double checkpoint_every = 0;  // --checkpoint-every [s]
  bool resume = false;          // --resume DIR: `out` is DIR
#ifdef KELP_WITH_ROS2
  kelp_ros2::Ros2Options ros2_options;
#endif
};

std::string plot_script() {
  if (const char* env = std::getenv("KELP_PLOT_SCRIPT")) return env;
  // Installed next to the program's prefix, else the source tree of this build.
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = self.parent_path().parent_path() / "share/kelp/plot_run.py";
    if (fs::exists(installed)) return installed.string();
  }
  return KELP_PLOT_SCRIPT_SOURCE;
}

// The 3-D replay's page template: installed, or this build's (KELP_REPLAY_TEMPLATE_BUILD);
// without one (empty) the run goes on and says once that replay.html is left out.
std::string replay_template() {
  std::string page = kelp_apps::find_replay_template(KELP_REPLAY_TEMPLATE_BUILD);
  if (page.empty())
    std::fprintf(stderr, "kelp-tethered-pair: no replay.html: %s\n",
                 kelp_apps::replay_template_missing_note().c_str());
  return page;
}

// A run stopped by SIGINT or SIGTERM (kelp/sim/stop.hpp): what it left, and the interrupted
// exit status (128 + the signal: 130, 143).
int stopped(const Options& o, double simulated, bool completed, bool plots) {
  const int signal = kelp::sim::stop_signal();
  std::fprintf(stderr,
               "kelp-tethered-pair: stopped by %s at %.2f s of %.0f s simulated; the outputs in %s "
               "are whole (summary.json: \"completed\": %s)%s%s%s\n",
               signal == SIGTERM ? "SIGTERM" : "SIGINT", simulated, o.scenario.duration,
               o.out.c_str(), completed ? "true" : "false",
               plots ? "; no plots (plot_run.py DIR draws them)" : "",
               o.checkpoint_every > 0 ? "; continue it with --resume " : "",
               o.checkpoint_every > 0 ? o.out.c_str() : "");
  return kelp::sim::interrupted_exit_status();
}

// A fleet scenario (`"fleet"`): any vehicles and tethers (kelp/sim/fleet_run.hpp).
int run_fleet(const Options& o) {
  const kelp::sim::FleetRunSummary s = kelp::sim::run_fleet(o.scenario, o.scenario_file, o.out);
  if (kelp::sim::stop_requested()) {
    // The replay of what ran (written atomically: a second signal leaves no half page).
    const std::string page = replay_template();
    if (!page.empty()) kelp::sim::write_replay(o.out, page);
    return stopped(o, s.simulated_s, s.completed, false);
  }
  std::printf(
      "kelp-tethered-pair: fleet of %zu vehicles and %zu tethers: %.0f s simulated in %.2f s "
      "(%.0fx real time); outputs in %s (timeseries.csv, nodes.csv, summary.json%s)\n",
      o.scenario.fleet->vehicles.size(), o.scenario.fleet->tethers.size(), s.simulated_s, s.wall_s,
      s.simulated_s / std::max(s.wall_s, 1e-9), o.out.c_str(), o.scenario.mcap ? ", run.mcap" : "");
  std::printf(
      "kelp-tethered-pair: tether solver: %.2f Newton iterations per step on average, at most %d "
      "in one step; %ld retried steps, %ld explicit fallbacks\n",
      s.newton_mean, s.newton_max, s.retried_steps, s.explicit_fallbacks);
  // The 3-D replay of every vehicle and tether, from the run directory (as the pair's).
  const std::string page = replay_template();
  if (!page.empty())
    std::printf("kelp-tethered-pair: the 3-D replay: %s\n",
                kelp::sim::write_replay(o.out, page).c_str());
  return 0;
}

int run(const Options& o) {
  if (o.scenario.fleet) return run_fleet(o);
  // What kelp.run_scenario (Python) runs too: the same summary from the same scenario.
  kelp::sim::RunOptions ro;
  ro.out = o.out;
  const bool progress = !o.quiet && isatty(2);
  if (progress) ro.on_progress = kelp_apps::progress_bar(o.scenario.duration);
  ro.scenario_file = o.scenario_file;
  ro.version = KELP_VERSION_STRING;
  ro.checkpoint_every = o.checkpoint_every;
  ro.resume = o.resume;
  ro.replay_template = replay_template();
#ifdef KELP_WITH_ROS2
  const kelp::sim::RunSummary summary =
      o.ros2 ? kelp_ros2::run_with_ros2(o.scenario, ro, o.ros2_options)
             : kelp::sim::run_scenario(o.scenario, ro);
#else
  const kelp::sim::RunSummary summary = kelp::sim::run_scenario(o.scenario, ro);
#endif
  if (progress) kelp_apps::progress_done();
  // Stopped by a signal: the files are whole (summary.json and replay.html written, atomically);
  // the plots are left out.
  if (kelp::sim::stop_requested())
    return stopped(o, summary.simulated_s, summary.completed, !o.no_plots);
  const double duration = summary.simulated_s, wall = summary.wall_s.value_or(0.0);
  const double auv_rms = summary.auv.rms_path_error_m, asv_rms = summary.asv.rms_distance_to_auv_m,
               t_max = summary.tether.max_tension_n;

  std::string plots;
  if (!o.no_plots) {
    const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    const std::string cmd = python + " '" + plot_script() + "' '" + o.out + "'";
    const int rc = std::system(cmd.c_str());
    // A signal while plotting (Ctrl-C reaches the script too): the run itself is whole.
    if (kelp::sim::stop_requested())
      return stopped(o, summary.simulated_s, summary.completed, true);
    if (rc != 0) {
      std::fprintf(stderr, "kelp-tethered-pair: the plotting script failed (%s)\n", cmd.c_str());
      return 2;
    }
    plots = ", plots";
  }
  std::printf(
      "kelp-tethered-pair: %.0f s simulated in %.2f s (%.0fx real time); AUV path error RMS "
      "%.2f m, boat %.2f m from the AUV RMS, peak tension %.1f N; outputs in %s (timeseries.csv, "
      "nodes.csv, summary.json%s%s%s)\n",
      duration, wall, duration / wall, auv_rms, asv_rms, t_max, o.out.c_str(),
      o.scenario.mcap ? ", run.mcap" : "", ro.replay_template.empty() ? "" : ", replay.html",
      plots.c_str());
  const kelp::sim::SolverSummary& ts = summary.tether_solver;
  std::printf(
      "kelp-tethered-pair: tether solver (%s): %.2f Newton iterations per step on average, at "
      "most %d in one step; %ld retried steps, %ld explicit fallbacks\n",
      ts.integrator.c_str(), ts.newton_iterations_per_step_mean, ts.newton_iterations_per_step_max,
      ts.retried_steps, ts.explicit_fallbacks);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "kelp-tethered-pair: a BlueBoat and a BlueROV2 Heavy joined by a tether in waves, "
      "wind and current (the embedded default: the paper's moderate sea, a square "
      "survey)"};
  app.footer(
      "Exit status: 0 done, 1 a simulation or file error, 2 the plotting script failed, 3 an "
      "invalid scenario, option or checkpoint (nothing written), 130 / 143 stopped by SIGINT / "
      "SIGTERM (the run's files whole, summary.json \"completed\": false; with "
      "--checkpoint-every, checkpoint.bin to --resume from; a second signal stops at once).");
  std::string file;
  double duration = -1;
  std::int64_t seed = -1;
  app.add_option("--scenario", file, "scenario file (JSON; see apps/tethered_pair/README.md)");
  app.add_option("--duration", duration, "simulated time [s] (overrides the scenario)")
      ->check(CLI::Range(1e-3, 1e7));
  app.add_option("--seed", seed, "seed of the waves and gusts (overrides the scenario)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--out", o.out, "output directory");
  app.add_flag("--quiet", o.quiet, "no progress bar");
  std::string resume_dir;
  auto* every = app.add_option("--checkpoint-every", o.checkpoint_every,
                               "write OUT/checkpoint.bin every this many simulated seconds and "
                               "when stopped, to continue the run from with --resume [s]")
                    ->check(CLI::Range(1e-2, 1e7));
  app.add_option("--resume", resume_dir,
                 "continue the stopped or killed run in DIR from its checkpoint.bin (its "
                 "scenario and options are the checkpoint's; its files end as an uninterrupted "
                 "run's)");
  app.add_flag("--no-plots", o.no_plots, "do not run the plotting script");
  std::string kernel;
  bool deterministic = false;
  app.add_option("--kernel", kernel,
                 "instruction path of the wave kernel (overrides the scenario; portable: the "
                 "same numbers on every CPU)")
      ->check(CLI::IsMember({"auto", "portable", "avx2", "avx512"}));
  bool mcap = false, no_mcap = false;
  app.add_flag("--mcap", mcap,
               "write run.mcap, the run as a ROS 2 bag (the default; the scenario's output.mcap)");
  app.add_flag("--no-mcap", no_mcap, "do not write run.mcap");
  app.add_flag("--deterministic", deterministic,
               "the same numbers on every CPU: --kernel portable (see docs/deterministic.md)");
  bool lockstep = false;
  double ros2_speed = 1.0, clock_timeout = 10.0;
  app.add_flag("--ros2", o.ros2,
               "publish the run live as ROS 2 topics over DDS and take commands from ROS 2 "
               "(paced to real time; see README, \"With ROS 2\")");
  app.add_flag("--ros2-lockstep", lockstep,
               "with --ros2: step in lockstep with /clock (each rosgraph_msgs/Clock received is a "
               "time to simulate to) instead of real time");
  app.add_option("--ros2-speed", ros2_speed, "with --ros2: simulated seconds per second")
      ->check(CLI::Range(1e-3, 1e3));
  app.add_option("--ros2-clock-timeout", clock_timeout,
                 "with --ros2-lockstep: end the run after this long without /clock [s]")
      ->check(CLI::Range(1e-3, 1e6));
  CLI11_PARSE(app, argc, argv);
  if (lockstep && !o.ros2) o.ros2 = true;
#ifdef KELP_WITH_ROS2
  o.ros2_options.lockstep = lockstep;
  o.ros2_options.speed = ros2_speed;
  o.ros2_options.clock_timeout = clock_timeout;
#else
  if (o.ros2) {
    std::fprintf(stderr,
                 "kelp-tethered-pair: built without ROS 2 topics (configure with "
                 "-DKELP_BUILD_ROS2=ON; needs Cyclone DDS)\n");
    return 3;
  }
  (void)ros2_speed;
  (void)clock_timeout;
#endif
  if (deterministic && !kernel.empty() && kernel != "portable") {
    std::fprintf(stderr, "kelp-tethered-pair: --deterministic pins --kernel portable, not %s\n",
                 kernel.c_str());
    return 3;
  }
  try {
    kelp::simd::kernel_policy();  // a bad KELP_KERNEL stops here, named
  } catch (const kelp::invalid_argument& e) {
    std::fprintf(stderr, "kelp-tethered-pair: %s\n", e.what());
    return 3;
  }
  try {
    if (!resume_dir.empty()) {
      // The run's scenario is in its checkpoint (read whole and checked here: a corrupted or
      // foreign one stops the program before anything is written); with --scenario, the
      // checkpoint must be of that scenario (simulate() compares them).
      if (app.count("--out") > 0 && fs::path(o.out) != fs::path(resume_dir))
        throw CLI::ValidationError("--out", "--resume continues the run in its own directory");
      o.out = resume_dir;
      o.resume = true;
      const kelp::sim::CheckpointInfo info = kelp::sim::read_checkpoint_info(
          (fs::path(resume_dir) / kelp::sim::checkpoint_file_name).string());
      if (file.empty()) {
        o.scenario = kelp::sim::parse_scenario(info.scenario_json, info.scenario_file);
        o.scenario_file = info.scenario_file;
      }
      if (every->count() == 0) o.checkpoint_every = info.checkpoint_every;
    }
    if (!file.empty()) {
      o.scenario = kelp::sim::load_scenario(file);
      o.scenario_file = file;
    }
    kelp::sim::ScenarioOverrides overrides;
    overrides.duration = duration;
    overrides.seed = seed;
    overrides.kernel = kernel;
    overrides.deterministic = deterministic;
    if (mcap || no_mcap) overrides.mcap = mcap && !no_mcap ? 1 : 0;
    o.scenario = kelp::sim::apply_overrides(o.scenario, overrides);
    if ((o.checkpoint_every > 0 || o.resume) && (o.scenario.fleet || o.ros2))
      throw CLI::ValidationError(o.resume ? "--resume" : "--checkpoint-every",
                                 "checkpoints are for a pair's run without --ros2 (a fleet's run "
                                 "and a live ROS 2 run cannot be checkpointed yet)");
    // SIGINT and SIGTERM stop the run cleanly after the step they land in; a second one at once.
    kelp::sim::install_stop_handlers();
    return run(o);
  } catch (const kelp::sim::scenario_error& e) {
    std::fprintf(stderr, "kelp-tethered-pair: invalid scenario: %s\n", e.what());
    return 3;
  } catch (const kelp::sim::state_error& e) {
    std::fprintf(stderr, "kelp-tethered-pair: cannot resume: %s\n", e.what());
    return 3;
  } catch (const CLI::ValidationError& e) {
    std::fprintf(stderr, "kelp-tethered-pair: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kelp-tethered-pair: %s\n", e.what());
    return 1;
  }
}
