/// \file
/// \brief A closed-loop run's checkpoint: everything a run of the tethered pair needs to go on
/// where it was, bit for bit (simulate() and run_scenario() with `checkpoint_every` and `resume`;
/// kelp-tethered-pair's `--checkpoint-every` and `--resume`).
///
/// A checkpoint holds the coupled system's state (as a state file does, kelp/sim/state_io.hpp:
/// the tether's integrator history, the winch, the thrusters' lags and the batteries), the
/// controllers' memory (PID integrals, disturbance observers, waypoint progress, the last
/// commands), the sensors' and filters' memory (random streams, biases, covariances, fixes in
/// flight), the turn counter, the entanglement monitor, the run's statistics and the lengths of its
/// output files (timeseries.csv, nodes.csv, events.csv, and run.mcap with its open chunk and
/// index). It is written atomically (a temporary beside it, fsync, rename) after the output files
/// are flushed to disk, so that a run killed at any point (SIGKILL, a crash, a power loss) leaves
/// its last checkpoint whole and every byte it refers to on disk. Resuming truncates the output
/// files to the lengths it records and runs on: the files a resumed run leaves are byte-identical
/// to those of a run that was never stopped (summary.json less its wall-time fields).
///
/// The file is kelp's binary archive (magic, version, kind 3, tagged sections, CRC-32;
/// docs/checkpoints.md). A checkpoint is refused with a kelp::sim::state_error, and nothing in
/// the run's directory changed, when it is truncated or corrupted, written by another kelp
/// version, of another scenario, or when an output file is shorter than it records.
/// Part of the compiled `kelp::sim` component.
#pragma once

#include <string>

#include "kelp/sim/export.hpp"
#include "kelp/sim/state_error.hpp"

namespace kelp {
namespace sim {

/// \brief The name of a run's checkpoint in its output directory.
inline constexpr const char* checkpoint_file_name = "checkpoint.bin";

/// \brief What a checkpoint says about its run (read_checkpoint_info()).
struct CheckpointInfo {
  std::string kelp_version;   ///< the kelp that wrote it (only the same version resumes it)
  std::string scenario_json;  ///< the run's scenario, as scenario_json() wrote it
  std::string scenario_file;  ///< the scenario file the run named
  long steps_taken = 0;       ///< steps taken when it was written
  long total_steps = 0;       ///< steps of the whole run
  double time = 0;            ///< simulated time when it was written [s]
  /// The interval the run wrote checkpoints at (0: only when stopped) [s].
  double checkpoint_every = 0;
};

/// \brief Reads the checkpoint at `path` (every byte checked: magic, version, kind, CRC-32) and
/// returns what it says about its run, e.g. the scenario to resume it with.
/// \param path the checkpoint file (e.g. a run directory's checkpoint.bin)
/// \returns its run's scenario, steps, time and checkpoint interval
/// \throws state_error for a missing file or one that is not a whole checkpoint of this kelp
/// version; kelp::error when it cannot be read.
KELP_SIM_API CheckpointInfo read_checkpoint_info(const std::string& path);

}  // namespace sim
}  // namespace kelp
