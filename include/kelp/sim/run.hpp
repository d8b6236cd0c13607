/// \file
/// \brief What kelp-tethered-pair runs, as a function: a scenario with the command line's
/// overrides (duration, seed, wave kernel), simulated by simulate(), its summary stamped with
/// kelp's version and written as summary.json beside the CSV log.
///
/// The program and the Python package (`kelp.run_scenario`) both call run_scenario(), so the
/// same scenario and seed give the same summary, bit for bit, from either. Part of the optional
/// `kelp::sim` component.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "kelp/core/error.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {

/// \brief What a run may change in its scenario (kelp-tethered-pair's `--duration`, `--seed`,
/// `--kernel`, `--deterministic`); an unset field keeps the scenario's value.
struct ScenarioOverrides {
  double duration = -1;    ///< simulated time [s]; > 0 overrides
  std::int64_t seed = -1;  ///< seed of the waves and gusts; >= 0 overrides
  std::string
      kernel;  ///< wave kernel path ("auto", "portable", "avx2", "avx512"); non-empty overrides
  bool deterministic = false;  ///< true: the kernel "portable" (the same numbers on every CPU)
  int mcap = -1;  ///< run.mcap (the scenario's `output.mcap`): 1 on, 0 off, -1 the scenario's
};

/// \brief The scenario with the overrides applied.
/// \throws kelp::invalid_argument for a non-finite duration, or `deterministic` with a kernel
/// other than "portable".
inline Scenario apply_overrides(Scenario sc, const ScenarioOverrides& o) {
  KELP_CHECK(!std::isnan(o.duration), "ScenarioOverrides::duration must not be NaN");
  KELP_CHECK(
      !o.deterministic || o.kernel.empty() || o.kernel == "portable",
      "ScenarioOverrides: deterministic pins the kernel \"portable\", not \"" + o.kernel + "\"");
  if (o.duration > 0) sc.duration = o.duration;
  if (o.seed >= 0) sc.seed = static_cast<std::uint64_t>(o.seed);
  if (!o.kernel.empty()) sc.kernel = o.kernel;
  if (o.deterministic) sc.kernel = "portable";
  if (o.mcap >= 0) sc.mcap = o.mcap != 0;
  return sc;
}

/// \brief Options of run_scenario().
struct RunOptions {
  /// Directory of the run's files (timeseries.csv and nodes.csv through RunLog, summary.json),
  /// created if needed; empty: nothing is written.
  std::string out;
  std::string scenario_file = "(embedded default)";  ///< named in errors and in the summary
  bool progress = false;                             ///< a progress bar on stderr
  std::string version;  ///< the summary's `kelp_version` (empty: the field is left out)
  /// Called with every sample the log takes (the rows of timeseries.csv, at the scenario's log
  /// rate), whether or not a log is written; empty: nothing is called.
  std::function<void(const LogRow&)> on_sample;
  /// The replay page's template (find_replay_template()): with `out`, replay.html is written
  /// there at the end of the run (write_replay()); empty: no replay.html.
  std::string replay_template;
};

/// \brief A run's ROS 2 bag (BagRecorder), opened at the run's first sample (t = 0, taken when
/// the loop is built), so that a scenario which fails before it, e.g. with a tether too short
/// for its attachment points, leaves no file behind.
class RunBag {
 public:
  /// \brief The bag `file` (its directory created when it opens), markers at `marker_rate` [Hz].
  RunBag(std::filesystem::path file, double marker_rate)
      : file_(std::move(file)), marker_rate_(marker_rate) {}
  /// \brief Records sample `r`, opening the bag first if it is not open yet.
  /// \throws kelp::error when the file cannot be written.
  void record(const LogRow& r) {
    if (!bag_) {
      if (file_.has_parent_path()) std::filesystem::create_directories(file_.parent_path());
      bag_ = std::make_unique<BagRecorder>(file_, marker_rate_);
    }
    bag_->record(r);
  }
  /// \brief Finishes the bag if it was opened.
  void close() {
    if (bag_) bag_->close();
  }

 private:
  std::filesystem::path file_;
  double marker_rate_;
  std::unique_ptr<BagRecorder> bag_;
};

/// \brief The run's ROS 2 bag, run.mcap in `o.out`, when the scenario asks for one
/// (`output.mcap`, the default) and there is an output directory: `on_sample` is wrapped so that
/// every sample is recorded before it is passed on. Close the bag after the run.
/// \returns the bag, or null when none is written.
inline std::unique_ptr<RunBag> open_run_bag(const Scenario& sc, const RunOptions& o,
                                            std::function<void(const LogRow&)>& on_sample) {
  if (!sc.mcap || o.out.empty()) return nullptr;
  auto bag = std::make_unique<RunBag>(std::filesystem::path(o.out) / "run.mcap", sc.node_rate);
  on_sample = [b = bag.get(), user = on_sample](const LogRow& r) {
    b->record(r);
    if (user) user(r);
  };
  return bag;
}

/// \brief What a run leaves after its last step: the summary's `kelp_version`, summary.json
/// (indented by 2) in `o.out` and, with a `replay_template`, replay.html there (write_replay(),
/// `source` named in it). run_scenario() calls it, and so does a program that runs its own loop
/// (kelp-tethered-pair --ros2), so that every run directory has the same files.
/// \throws kelp::error when a file cannot be written (replay_error for replay.html).
inline void finish_run(nlohmann::json& summary, const RunOptions& o,
                       const std::string& source = "kelp-tethered-pair") {
  if (!o.version.empty()) summary["kelp_version"] = o.version;
  if (o.out.empty()) return;
  std::ofstream f(std::filesystem::path(o.out) / "summary.json");
  f << summary.dump(2) << '\n';
  if (!f) throw kelp::error("cannot write summary.json in " + o.out);
  f.close();
  if (!o.replay_template.empty()) {
    ReplayOptions ro;
    ro.source = source;
    write_replay(o.out, o.replay_template, ro);
  }
}

/// \brief Runs a scenario as kelp-tethered-pair does: simulate() (with the CSV log in `out`),
/// then finish_run(): the summary's `kelp_version`, summary.json in `out` and, with a
/// `replay_template`, replay.html (the 3-D replay, docs/replay.md); with the scenario's
/// `output.mcap` (the default) also run.mcap, the run as a ROS 2 bag (open_run_bag(): every
/// sample, the markers at the node rate).
/// \returns the summary (summary.json's content).
/// \throws scenario_error, kelp::invalid_argument, kelp::numerical_error; kelp::error when a
/// file cannot be written (replay_error for replay.html).
inline nlohmann::json run_scenario(const Scenario& sc, const RunOptions& o = {}) {
  SimulateOptions so;
  so.log_dir = o.out;
  so.progress = o.progress;
  so.scenario_file = o.scenario_file;
  so.on_sample = o.on_sample;
  std::unique_ptr<RunBag> bag = open_run_bag(sc, o, so.on_sample);
  nlohmann::json summary = simulate(sc, so);
  if (bag) bag->close();
  finish_run(summary, o);
  return summary;
}

}  // namespace sim
}  // namespace kelp
