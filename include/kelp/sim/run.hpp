/// \file
/// \brief What kelp-tethered-pair runs, as a function: a scenario with the command line's
/// overrides (duration, seed, wave kernel), simulated by simulate(), its summary stamped with
/// kelp's version and written as summary.json beside the CSV log.
///
/// The program and the Python package (`kelp.run_scenario`) both call run_scenario(), so the
/// same scenario and seed give the same summary, bit for bit, from either. Part of the optional
/// `kelp::sim` component.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/summary.hpp"

namespace kelp {
namespace sim {

class BagRecorder;

/// \brief What a run may change in its scenario (kelp-tethered-pair's `--duration`, `--seed`,
/// `--kernel`, `--deterministic`); an unset field keeps the scenario's value.
struct ScenarioOverrides {
  double duration = -1;    ///< simulated time [s]; > 0 overrides (0.001 to 1e7)
  std::int64_t seed = -1;  ///< seed of the waves and gusts; >= 0 overrides
  std::string
      kernel;  ///< wave kernel path ("auto", "portable", "avx2", "avx512"); non-empty overrides
  bool deterministic = false;  ///< true: the kernel "portable" (the same numbers on every CPU)
  int mcap = -1;  ///< run.mcap (the scenario's `output.mcap`): 1 on, 0 off, -1 the scenario's
};

/// \brief The scenario with the overrides applied.
/// \param sc the scenario (a copy, returned changed) \param o the overrides
/// \return the scenario with every set override applied
/// \throws kelp::invalid_argument for a NaN duration or one > 0 outside [0.001, 1e7] s, an unknown
/// kernel name, or `deterministic` with a kernel other than "portable".
KELP_SIM_API Scenario apply_overrides(Scenario sc, const ScenarioOverrides& o);

/// \brief Options of run_scenario().
struct RunOptions {
  /// Directory of the run's files (timeseries.csv and nodes.csv through RunLog, summary.json),
  /// created if needed; empty: nothing is written.
  std::string out;
  std::string scenario_file = "(embedded default)";  ///< named in errors and in the summary
  /// Called after every step with the steps taken, the run's steps and the simulation time
  /// (SimulateOptions::on_progress, e.g. a program's progress bar); empty: nothing is called.
  std::function<void(long steps_taken, long total_steps, double time)> on_progress;
  std::string version;  ///< the summary's `kelp_version` (empty: the field is left out)
  /// Called with every sample the log takes (the rows of timeseries.csv, at the scenario's log
  /// rate), whether or not a log is written; empty: nothing is called.
  std::function<void(const LogRow&)> on_sample;
  /// The replay page's template (find_replay_template()): with `out`, replay.html is written
  /// there at the end of the run (write_replay()); empty: no replay.html.
  std::string replay_template;
  /// Polled before every step with stop_requested() (SimulateOptions::should_stop,
  /// kelp/sim/stop.hpp): true stops the run there; empty: stop_requested() alone.
  std::function<bool()> should_stop;
  /// Writes `out`/checkpoint.bin every this many simulated seconds and when the run is stopped
  /// (SimulateOptions::checkpoint_every, kelp/sim/checkpoint.hpp); 0: none. A run that completes
  /// removes its checkpoint once summary.json is written. [s]
  double checkpoint_every = 0;
  /// Continues the run in `out` from its checkpoint (SimulateOptions::resume).
  bool resume = false;
};

/// \brief A run's ROS 2 bag (BagRecorder), opened at the run's first sample (t = 0, taken when
/// the loop is built), so that a scenario which fails before it, e.g. with a tether too short
/// for its attachment points, leaves no file behind.
class KELP_SIM_API RunBag {
 public:
  /// \brief The bag `file` (its directory created when it opens), markers at `marker_rate` [Hz].
  /// Nothing is created until the first record().
  /// \param file the bag's path (e.g. `out`/run.mcap) \param marker_rate markers per second, > 0
  RunBag(std::filesystem::path file, double marker_rate);
  ~RunBag();
  RunBag(const RunBag&) = delete;
  RunBag& operator=(const RunBag&) = delete;
  /// \brief Records sample `r`, opening the bag first if it is not open yet.
  /// \param r the sample (with both vehicles, the tether and its end forces: Ros2Sampler)
  /// \throws kelp::error when the file cannot be written; kelp::invalid_argument as
  /// BagRecorder (a rate that is not finite and > 0, a row that lacks what the messages need),
  /// checked before the bag's directory and file are created: a refused first record creates
  /// neither; std::filesystem::filesystem_error when the directory cannot be created.
  void record(const LogRow& r);
  /// \brief Finishes the bag if it was opened.
  void close();

 private:
  friend struct CheckpointAccess;  // a run's checkpoint
  std::filesystem::path file_;
  double marker_rate_;
  std::unique_ptr<BagRecorder> bag_;
};

/// \brief The run's ROS 2 bag, run.mcap in `o.out`, when the scenario asks for one
/// (`output.mcap`, the default) and there is an output directory: `on_sample` is wrapped so that
/// every sample is recorded before it is passed on. Close the bag after the run.
/// \param sc the scenario (its `mcap` and node rate) \param o the run's options (`out`)
/// \param on_sample the run's sample callback, replaced by one that records, then calls it
/// \returns the bag, or null when none is written.
KELP_SIM_API std::unique_ptr<RunBag> open_run_bag(const Scenario& sc, const RunOptions& o,
                                                  std::function<void(const LogRow&)>& on_sample);

/// \brief What a run leaves after its last step: the summary's `kelp_version`, summary.json
/// (indented by 2; written atomically, write_file_atomically()) in `o.out` and, with a
/// `replay_template`, replay.html there (write_replay(), `source` named in it). run_scenario()
/// calls it, and so does a program that runs its own loop (kelp-tethered-pair --ros2), so that
/// every run directory has the same files. \throws kelp::error when a file cannot be written
/// (replay_error for replay.html).
/// \param summary the run's summary (its `kelp_version` set from `o.version`)
/// \param o the run's options (`out`, `version`, `replay_template`; nothing without `out`)
/// \param source the program named in replay.html
KELP_SIM_API void finish_run(RunSummary& summary, const RunOptions& o,
                             const std::string& source = "kelp-tethered-pair");

/// \brief finish_run() for a program whose summary holds more than RunSummary (e.g. the live
/// ROS 2 run's `ros2` object): `summary_text` is written as summary.json as it is (no
/// `kelp_version` is added), then replay.html as finish_run() writes it.
/// \throws kelp::error when a file cannot be written (replay_error for replay.html).
/// \param summary_text summary.json's text \param o the run's options (`out`, `replay_template`)
/// \param source the program named in replay.html
KELP_SIM_API void finish_run_with(const std::string& summary_text, const RunOptions& o,
                                  const std::string& source = "kelp-tethered-pair");

/// \brief Runs a scenario as kelp-tethered-pair does: simulate() (with the CSV log in `out`),
/// then finish_run(): the summary's `kelp_version`, summary.json in `out` and, with a
/// `replay_template`, replay.html (the 3-D replay, docs/replay.md); with the scenario's
/// `output.mcap` (the default) also run.mcap, the run as a ROS 2 bag (open_run_bag(): every
/// sample, the markers at the node rate).
///
/// A run stopped early (stop_requested() or `o.should_stop`, kelp/sim/stop.hpp) ends after the
/// step it was in and leaves the same files, whole: the CSV files end on a full line, run.mcap
/// has its summary and footer, summary.json says `"completed": false` and the time reached.
/// With `o.checkpoint_every` it also leaves checkpoint.bin, from which `o.resume` continues it
/// (kelp/sim/checkpoint.hpp): the files of a resumed run are those of a run never stopped.
/// \param sc the scenario (apply_overrides() first for a command line's)
/// \param o the output directory, version, observers, replay, stop and checkpoint options
/// \returns the summary (summary.json's content: summary_json()).
/// \throws scenario_error, kelp::invalid_argument, kelp::numerical_error; kelp::error when a
/// file cannot be written (replay_error for replay.html).
KELP_SIM_API RunSummary run_scenario(const Scenario& sc, const RunOptions& o = {});

}  // namespace sim
}  // namespace kelp
