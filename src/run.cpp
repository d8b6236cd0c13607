// What kelp-tethered-pair runs, as a function (kelp/sim/run.hpp): simulate() (the closed loop with
// its log, its bag and its checkpoints), the scenario's overrides, its summary.json and
// replay.html.
#include "kelp/sim/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <utility>

#include "checkpoint.hpp"
#include "kelp/core/error.hpp"
#include "kelp/sim/checkpoint.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/stop.hpp"

namespace kelp {
namespace sim {

Scenario apply_overrides(Scenario sc, const ScenarioOverrides& o) {
  // The scenario file's range for "duration" (scenario.cpp), so that an override cannot pass
  // what a file may not: an infinite or huge duration has no step count.
  KELP_CHECK(
      !std::isnan(o.duration) && (o.duration <= 0 || (o.duration >= 1e-3 && o.duration <= 1e7)),
      "ScenarioOverrides::duration must be in [0.001, 1e7] s (or <= 0: the scenario's)");
  KELP_CHECK(
      !o.deterministic || o.kernel.empty() || o.kernel == "portable",
      "ScenarioOverrides: deterministic pins the kernel \"portable\", not \"" + o.kernel + "\"");
  if (o.duration > 0) sc.duration = o.duration;
  if (o.seed >= 0) sc.seed = static_cast<std::uint64_t>(o.seed);
  if (!o.kernel.empty()) sc.kernel = kelp::simd::parse_kernel_path(o.kernel);
  if (o.deterministic) sc.kernel = kelp::simd::KernelPath::portable;
  if (o.mcap >= 0) sc.mcap = o.mcap != 0;
  return sc;
}

RunSummary simulate(const Scenario& sc, const SimulateOptions& o) {
  KELP_CHECK(std::isfinite(o.checkpoint_every) && o.checkpoint_every >= 0,
             "SimulateOptions::checkpoint_every must be finite and >= 0");
  const std::string checkpoint =
      !o.checkpoint_file.empty()
          ? o.checkpoint_file
          : (o.log_dir.empty()
                 ? std::string()
                 : (std::filesystem::path(o.log_dir) / checkpoint_file_name).string());
  KELP_CHECK(!checkpoint.empty() || (o.checkpoint_every == 0 && !o.resume),
             "SimulateOptions: checkpoints need a log_dir or a checkpoint_file");
  const WorldSetup setup = world_setup(sc, o.scenario_file);
  std::unique_ptr<RunLog> log;
  std::unique_ptr<RunBag> bag;
  ClosedLoopOptions lo;
  lo.scenario_file = o.scenario_file;
  lo.on_step = o.on_step;
  lo.on_sample = o.on_sample;
  const std::string mcap =
      !o.mcap
          ? std::string()
          : (!o.mcap_file.empty()
                 ? o.mcap_file
                 : (o.log_dir.empty() ? std::string()
                                      : (std::filesystem::path(o.log_dir) / "run.mcap").string()));
  if (!o.resume) {
    if (!o.log_dir.empty()) log = std::make_unique<RunLog>(o.log_dir);
    lo.log = log.get();
    if (!mcap.empty()) {
      bag = std::make_unique<RunBag>(mcap, sc.node_rate);
      lo.on_sample = [b = bag.get(), user = o.on_sample](const LogRow& r) {
        b->record(r);
        if (user) user(r);
      };
    }
  } else {
    lo.on_sample = nullptr;  // the first sample is the checkpoint's, taken before
  }
  ClosedLoop loop(sc, setup, lo);
  if (o.resume) {
    ResumedFiles files =
        resume_checkpoint(checkpoint, loop, o.log_dir, mcap, sc.node_rate, o.on_sample);
    log = std::move(files.log);
    bag = std::move(files.bag);
  }
  if (!checkpoint.empty() && (o.resume || o.checkpoint_every > 0))
    remove_checkpoint_temporaries(checkpoint);
  const double resumed_at = loop.time();  // 0 unless resumed
  const long steps = loop.total_steps();
  const long every =
      o.checkpoint_every > 0 ? std::max(1L, std::lround(o.checkpoint_every / ClosedLoop::dt)) : 0;
  const auto wall0 = std::chrono::steady_clock::now();
  bool stopped = false;
  while (!loop.done()) {
    // A stop (kelp/sim/stop.hpp): the run ends here, between two steps.
    if (stop_requested() || (o.should_stop && o.should_stop())) {
      stopped = true;
      break;
    }
    const long k = loop.steps_taken();
    const double t = loop.time();
    loop.step();
    if (o.on_progress) o.on_progress(k, steps, t);
    if (every > 0 && loop.steps_taken() % every == 0 && !loop.done())
      write_checkpoint(checkpoint, loop, log.get(), bag.get(), o.checkpoint_every);
  }
  // A stopped run resumes from where it stopped (before its files are closed: the bag's summary
  // and footer come after the bytes the checkpoint counts).
  if (stopped && every > 0)
    write_checkpoint(checkpoint, loop, log.get(), bag.get(), o.checkpoint_every);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (log) log->close();
  if (bag) bag->close();
  RunSummary summary = loop.summary();
  summary.wall_s = wall;
  // What this process simulated (a resumed run: from its checkpoint on) over its wall time.
  summary.realtime_factor = (summary.simulated_s - resumed_at) / wall;
  return summary;
}

void finish_run_with(const std::string& summary_text, const RunOptions& o,
                     const std::string& source) {
  if (o.out.empty()) return;
  // Atomically: a run directory with summary.json has all of it (a kill leaves none or the whole).
  write_file_atomically(std::filesystem::path(o.out) / "summary.json", summary_text + '\n');
  if (!o.replay_template.empty()) {
    ReplayOptions ro;
    ro.source = source;
    write_replay(o.out, o.replay_template, ro);
  }
}

void finish_run(RunSummary& summary, const RunOptions& o, const std::string& source) {
  if (!o.version.empty()) summary.kelp_version = o.version;
  if (o.out.empty()) return;
  finish_run_with(summary_json(summary, 2), o, source);
}

RunSummary run_scenario(const Scenario& sc, const RunOptions& o) {
  SimulateOptions so;
  so.log_dir = o.out;
  so.on_progress = o.on_progress;
  so.scenario_file = o.scenario_file;
  so.on_sample = o.on_sample;
  so.should_stop = o.should_stop;
  so.mcap = sc.mcap;
  so.checkpoint_every = o.checkpoint_every;
  so.resume = o.resume;
  RunSummary summary = simulate(sc, so);
  finish_run(summary, o);
  // A completed run needs its checkpoint no more (removed after summary.json: a kill in between
  // leaves a run that resumes to its end).
  if (summary.completed && !o.out.empty()) {
    std::error_code ignored;
    std::filesystem::remove(std::filesystem::path(o.out) / checkpoint_file_name, ignored);
  }
  return summary;
}

}  // namespace sim
}  // namespace kelp
