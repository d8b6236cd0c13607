// What kelp-tethered-pair runs, as a function (kelp/sim/run.hpp): the scenario's overrides, its
// bag, its summary.json and replay.html.
#include "kelp/sim/run.hpp"

#include <cmath>
#include <utility>

#include "kelp/core/error.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/ros2.hpp"

namespace kelp {
namespace sim {

Scenario apply_overrides(Scenario sc, const ScenarioOverrides& o) {
  KELP_CHECK(!std::isnan(o.duration), "ScenarioOverrides::duration must not be NaN");
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

RunBag::RunBag(std::filesystem::path file, double marker_rate)
    : file_(std::move(file)), marker_rate_(marker_rate) {}

RunBag::~RunBag() = default;

void RunBag::record(const LogRow& r) {
  if (!bag_) {
    if (file_.has_parent_path()) std::filesystem::create_directories(file_.parent_path());
    bag_ = std::make_unique<BagRecorder>(file_, marker_rate_);
  }
  bag_->record(r);
}

void RunBag::close() {
  if (bag_) bag_->close();
}

std::unique_ptr<RunBag> open_run_bag(const Scenario& sc, const RunOptions& o,
                                     std::function<void(const LogRow&)>& on_sample) {
  if (!sc.mcap || o.out.empty()) return nullptr;
  auto bag = std::make_unique<RunBag>(std::filesystem::path(o.out) / "run.mcap", sc.node_rate);
  on_sample = [b = bag.get(), user = on_sample](const LogRow& r) {
    b->record(r);
    if (user) user(r);
  };
  return bag;
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
  std::unique_ptr<RunBag> bag = open_run_bag(sc, o, so.on_sample);
  RunSummary summary = simulate(sc, so);
  if (bag) bag->close();
  finish_run(summary, o);
  return summary;
}

}  // namespace sim
}  // namespace kelp
