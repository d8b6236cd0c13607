// A closed-loop run's checkpoint, as simulate() writes and resumes it (the public side is
// kelp/sim/checkpoint.hpp; the format docs/checkpoints.md). Private to the kelp::sim library.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/run.hpp"
#include "kelp/sim/state_error.hpp"

namespace kelp {
namespace sim {

// Flushes the log's and the bag's files to disk, then writes the checkpoint of `loop` with their
// lengths to `path` atomically. `log` and `bag` may be null; `every` is the interval [s] the run
// writes them at (kept in the checkpoint, the default of a resumed run).
// \throws kelp::error when a file cannot be written (the old checkpoint is then unchanged).
void write_checkpoint(const std::string& path, const ClosedLoop& loop, RunLog* log, RunBag* bag,
                      double every);

// The checkpoint of `loop` alone (no files: as if run without a log or a bag), e.g. the fuzz
// target's seeds.
std::string checkpoint_bytes(const ClosedLoop& loop);

// Restores `loop` (built from the scenario the checkpoint is of) from a checkpoint's `bytes`
// (untrusted), touching no file: what resume_checkpoint does before it reopens the files, for a
// run without a log or a bag. `input` names the bytes in errors.
// \throws state_error naming what is wrong (the loop is then not to be stepped).
void restore_checkpoint(std::string_view bytes, const std::string& input, ClosedLoop& loop);

// Removes the temporary files a process killed while it wrote the checkpoint `path` left beside
// it (`path`.tmp.*: write_checkpoint's, never renamed). A run calls it before its first
// checkpoint: one directory holds one run.
void remove_checkpoint_temporaries(const std::string& path);

// The output files of a resumed run, reopened where the checkpoint left them.
struct ResumedFiles {
  std::unique_ptr<RunLog> log;
  std::unique_ptr<RunBag> bag;
};

// Restores `loop` (just built from the same scenario and world, without a log or an on_sample:
// its first sample is not taken again) from the checkpoint at `path`, then reopens the run's
// files in `log_dir` at the lengths it records (and its bag at `mcap`, unless empty), truncating
// what was written after it. Every check comes first: a checkpoint that is refused leaves the files
// as they were. Then gives the loop `log` and `on_sample` (the bag's recorder first) from here on.
// \throws state_error for a checkpoint that is corrupted, of another kelp version or scenario,
// or that does not match the files; kelp::error when a file cannot be read or written.
ResumedFiles resume_checkpoint(const std::string& path, ClosedLoop& loop,
                               const std::string& log_dir, const std::string& mcap,
                               double marker_rate, std::function<void(const LogRow&)> on_sample);

}  // namespace sim
}  // namespace kelp
