// kelp-sweep: the paper's evaluation (tether length × sea state × compensation × seeds) or any
// sweep over kelp-tethered-pair scenarios, in parallel on one machine, sharded over a cluster
// (--shard I/N, then `kelp-sweep merge`), resumable (results keyed by the run's scenario hash),
// with a table (CSV and Markdown) of mean ± standard deviation over seeds and a figure.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "kelp/sim/checkpoint.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/stop.hpp"
#include "sweep.hpp"

namespace fs = std::filesystem;
using paper_sweep::json;

namespace {

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw paper_sweep::sweep_error(p.string() + ": cannot be read");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A stored result of run `hash`, or null when there is none (or it is unreadable: rerun it).
json stored_result(const fs::path& dir, const std::string& hash) {
  const fs::path p = dir / "runs" / (hash + ".json");
  std::ifstream in(p);
  if (!in) return nullptr;
  try {
    json j = json::parse(in);
    if (j.value("hash", "") == hash && j.contains("summary")) return j;
  } catch (const json::exception&) {
  }
  return nullptr;
}

void write_atomically(const fs::path& p, const std::string& text) {
  const fs::path tmp = p.string() + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, p);  // a preempted job leaves no half-written result
}

std::string plot_script() {
  if (const char* env = std::getenv("KELP_SWEEP_PLOT_SCRIPT")) return env;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = self.parent_path().parent_path() / "share/kelp/plot_sweep.py";
    if (fs::exists(installed)) return installed.string();
  }
  return KELP_SWEEP_PLOT_SCRIPT_SOURCE;
}

// Table and figure of a complete set of results in `dir`. When the results were computed on
// different kernel paths or C library math (`where`: each run's source directory), a warning on
// stderr and at the end of table.md.
int finish(const paper_sweep::Sweep& s, const std::map<std::string, json>& results,
           const fs::path& dir, bool plot, const std::map<std::string, std::string>& where = {}) {
  paper_sweep::write_table(s, results, dir);
  const std::string warning = paper_sweep::mixed_platforms_warning(results, where);
  if (!warning.empty()) {
    std::fprintf(stderr, "kelp-sweep: %s\n", warning.c_str());
    std::ofstream(dir / "table.md", std::ios::app) << "\n> **" << warning << "**\n";
  }
  // The tether solver over the whole sweep: its mean work, its worst run and any fallback.
  double newton = 0, newton_max = 0, retried = 0, fallbacks = 0;
  std::string worst;
  for (const auto& [hash, result] : results) {
    const paper_sweep::Metrics m = paper_sweep::metrics_of(result.at("summary"));
    newton += m.newton_mean / static_cast<double>(results.size());
    if (worst.empty() || m.newton_max > newton_max) {
      newton_max = m.newton_max;
      worst = "run " + std::to_string(result.value("index", 0)) + " (" + hash + ")";
    }
    retried += m.retried;
    fallbacks += m.fallbacks;
  }
  std::printf(
      "kelp-sweep: tether solver: %.3g Newton iterations per step on average, at most %.0f in "
      "one step (%s); %.0f retried steps, %.0f explicit fallbacks\n",
      newton, newton_max, worst.c_str(), retried, fallbacks);
  if (plot) {
    const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    const std::string cmd = python + " '" + plot_script() + "' '" + dir.string() + "'";
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "kelp-sweep: the plotting script failed (%s)\n", cmd.c_str());
      return 2;
    }
  }
  std::printf("kelp-sweep: table in %s (table.csv, table.md%s)\n", dir.string().c_str(),
              plot ? ", errors.png" : "");
  return 0;
}

struct RunOptions {
  std::string sweep_file, out = "kelp-sweep";
  std::string shard;
  unsigned jobs = 0;
  bool quiet = false, no_plot = false;
  bool keep_series = false;     // runs/<hash>/: timeseries.csv, nodes.csv, summary.json
  bool mcap = false;            // each run's ROS 2 bag, runs/<hash>.mcap
  bool dry_run = false;         // list the runs (JSON lines on stdout); run and write nothing
  double checkpoint_every = 0;  // runs/<hash>.checkpoint.bin every this many simulated s
};

int run(const RunOptions& o) {
  kelp::simd::kernel_policy();  // a bad KELP_KERNEL stops here, named, not in every run
  const paper_sweep::Sweep s =
      o.sweep_file.empty() ? paper_sweep::parse_sweep(paper_sweep::default_sweep_json().dump(),
                                                      "(embedded paper sweep)")
                           : paper_sweep::load_sweep(o.sweep_file);
  if (o.dry_run) {
    // One JSON object per run: what would run, with the scenario exactly as it would be used
    // (the same text whose hash names the run), so that a sweep file's grid can be checked
    // without running it.
    for (const paper_sweep::Run& r : s.runs) {
      const json line = {{"index", r.index},
                         {"hash", r.hash},
                         {"point", paper_sweep::point_values(s, r.point)},
                         {"seed", r.seed},
                         {"scenario", json::parse(kelp::sim::scenario_json(r.scenario))}};
      std::printf("%s\n", line.dump().c_str());
    }
    std::printf("kelp-sweep: %zu runs (%zu grid points x %zu seeds); dry run, nothing ran\n",
                s.runs.size(), s.points, s.seeds.size());
    return 0;
  }
  std::size_t shard = 0, shards = 1;
  if (!o.shard.empty()) {
    unsigned long i = 0, n = 0;
    char tail = 0;
    if (std::sscanf(o.shard.c_str(), "%lu/%lu%c", &i, &n, &tail) != 2 || n < 1 || i >= n)
      throw CLI::ValidationError("--shard", "expected I/N with 0 <= I < N, got " + o.shard);
    shard = i;
    shards = n;
  }
  const fs::path out(o.out);
  fs::create_directories(out / "runs");
  write_atomically(out / "sweep.json", s.source.dump(2) + "\n");

  std::vector<const paper_sweep::Run*> todo;
  std::map<std::string, json> results;
  std::size_t mine = 0;
  for (const paper_sweep::Run& r : s.runs) {
    if (r.index % shards != shard) continue;
    ++mine;
    json stored = stored_result(out, r.hash);
    // With --keep-series, a stored result without its series runs again (to write them).
    if (stored.is_null() || (o.keep_series && !fs::exists(out / "runs" / r.hash / "summary.json")))
      todo.push_back(&r);
    else
      results[r.hash] = std::move(stored);
  }
  const std::size_t reused = results.size();
  const unsigned jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
  const bool bar = !o.quiet && isatty(2);
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex mutex;
  std::vector<std::string> failures;
  // What became of each run of this shard, for status.json: done (a stored result), interrupted
  // (stopped by a signal: rerun on resume), failed; the rest did not start.
  std::vector<std::size_t> done_runs, failed_runs;
  json interrupted_runs = json::array();
  for (const auto& [hash, result] : results)
    done_runs.push_back(result.value("index", std::size_t(0)));
  double simulated = 0;
  const auto wall0 = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  };
  const auto worker = [&] {
    // A signal (kelp/sim/stop.hpp) stops the runs under way after their step and starts no more.
    for (std::size_t k; !kelp::sim::stop_requested() && (k = next++) < todo.size();) {
      const paper_sweep::Run& r = *todo[k];
      json result = {{"hash", r.hash},
                     {"index", r.index},
                     {"point", paper_sweep::point_values(s, r.point)},
                     {"seed", r.seed}};
      std::string error, note;
      bool completed = true;
      bool checkpointed = false;  // an interrupted run left runs/<hash>.checkpoint.bin
      double reached = 0;
      try {
        kelp::sim::SimulateOptions so;
        // --keep-series: the run's time series in runs/<hash>/ as kelp-tethered-pair writes them
        // (summary.json last, so a directory with one is complete: kelp-replay reads it).
        const fs::path series = out / "runs" / r.hash;
        if (o.keep_series) so.log_dir = series.string();
        // With --mcap, each run's ROS 2 bag beside its result (runs/<hash>.mcap).
        so.mcap = o.mcap;
        so.mcap_file = (out / "runs" / (r.hash + ".mcap")).string();
        // A run stopped or killed before resumes from its checkpoint (kelp/sim/checkpoint.hpp),
        // at the interval it was written at unless --checkpoint-every says otherwise.
        so.checkpoint_file = (out / "runs" / (r.hash + ".checkpoint.bin")).string();
        so.checkpoint_every = o.checkpoint_every;
        so.resume = fs::exists(so.checkpoint_file);
        if (so.resume) {
          try {
            const kelp::sim::CheckpointInfo info =
                kelp::sim::read_checkpoint_info(so.checkpoint_file);
            if (so.checkpoint_every == 0) so.checkpoint_every = info.checkpoint_every;
            char at[64];
            std::snprintf(at, sizeof at, "%.2f", info.time);
            note = std::string("resumed from its checkpoint at ") + at + " s";
          } catch (const kelp::error&) {  // refused below, by the resume itself
          }
        }
        kelp::sim::RunSummary summary;
        try {
          summary = kelp::sim::simulate(r.scenario, so);
        } catch (const kelp::sim::state_error& e) {
          if (!so.resume) throw;
          // A checkpoint that cannot be resumed (another kelp version, a damaged file): the run
          // starts again from its beginning.
          note = std::string("its checkpoint is refused (") + e.what() + "); it started again";
          fs::remove(so.checkpoint_file);
          so.resume = false;
          summary = kelp::sim::simulate(r.scenario, so);
        }
        completed = summary.completed;
        reached = summary.simulated_s;
        checkpointed = !completed && fs::exists(so.checkpoint_file);
        result["summary"] = nlohmann::json::parse(kelp::sim::summary_json(summary));
        if (completed) fs::remove(so.checkpoint_file);
        // A stopped run's series and bag are whole, its summary.json says "completed": false;
        // it stores no result, so that a resumed sweep runs it again.
        if (o.keep_series)
          write_atomically(series / "summary.json", result["summary"].dump(2) + "\n");
        if (completed) write_atomically(out / "runs" / (r.hash + ".json"), result.dump(1) + "\n");
      } catch (const std::exception& e) {
        error = e.what();
      }
      std::lock_guard<std::mutex> lock(mutex);
      if (!note.empty())
        std::fprintf(stderr, "kelp-sweep: run %zu (%s): %s\n", r.index, r.hash.c_str(),
                     note.c_str());
      if (!error.empty()) {
        failures.push_back("run " + std::to_string(r.index) + " (" + r.hash + "): " + error);
        failed_runs.push_back(r.index);
      } else if (!completed) {
        simulated += reached;
        interrupted_runs.push_back({{"index", r.index},
                                    {"hash", r.hash},
                                    {"simulated_s", reached},
                                    {"checkpoint", checkpointed}});
      } else {
        simulated += r.scenario.duration;
        results[r.hash] = std::move(result);
        done_runs.push_back(r.index);
      }
      const std::size_t d = ++done;
      if (bar) {
        const double t = elapsed();
        std::fprintf(stderr, "\r[%-40s] %zu/%zu runs, %.0f s, about %.0f s left ",
                     std::string(40 * d / todo.size(), '#').c_str(), d, todo.size(), t,
                     t / static_cast<double>(d) * static_cast<double>(todo.size() - d));
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 0; i < std::min<std::size_t>(jobs, std::max<std::size_t>(1, todo.size())); ++i)
    pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  if (bar && !todo.empty()) std::fprintf(stderr, "\n");
  const double wall = elapsed();
  const bool stopped = kelp::sim::stop_requested();
  std::printf(
      "kelp-sweep: %zu runs%s: %zu ran, %zu reused, %zu failed; %.0f s simulated in %.1f s wall "
      "on %u threads (%.0fx real time)\n",
      mine, shards > 1 ? (" in shard " + o.shard).c_str() : "", done_runs.size() - reused, reused,
      failures.size(), simulated, wall, jobs, wall > 0 ? simulated / wall : 0.0);
  for (const std::string& f : failures) std::fprintf(stderr, "kelp-sweep: failed: %s\n", f.c_str());
  // status.json: which of this shard's runs are done, which a signal interrupted, which did not
  // start (a resumed sweep runs all but the done ones).
  {
    std::sort(done_runs.begin(), done_runs.end());
    std::sort(failed_runs.begin(), failed_runs.end());
    std::vector<std::size_t> not_started;
    std::set<std::size_t> seen(done_runs.begin(), done_runs.end());
    seen.insert(failed_runs.begin(), failed_runs.end());
    for (const json& i : interrupted_runs) seen.insert(i.at("index").get<std::size_t>());
    for (const paper_sweep::Run& r : s.runs)
      if (r.index % shards == shard && !seen.count(r.index)) not_started.push_back(r.index);
    json status = {{"completed", !stopped && failures.empty()},
                   {"runs", mine},
                   {"done", done_runs},
                   {"interrupted", interrupted_runs},
                   {"failed", failed_runs},
                   {"not_started", not_started}};
    if (shards > 1) status["shard"] = o.shard;
    if (stopped) status["stopped_by"] = kelp::sim::stop_signal() == SIGTERM ? "SIGTERM" : "SIGINT";
    write_atomically(out / "status.json", status.dump(1) + "\n");
    if (stopped) {
      std::fprintf(stderr,
                   "kelp-sweep: stopped by %s: %zu of %zu runs done, %zu interrupted, %zu not "
                   "started (status.json); run it again to resume\n",
                   kelp::sim::stop_signal() == SIGTERM ? "SIGTERM" : "SIGINT", done_runs.size(),
                   mine, interrupted_runs.size(), not_started.size());
      return kelp::sim::interrupted_exit_status();
    }
  }
  if (!failures.empty()) return 1;
  if (shards > 1) return 0;  // the table comes from `kelp-sweep merge`
  return finish(s, results, out, !o.no_plot);
}

int merge(const std::vector<std::string>& dirs, const std::string& out_dir, bool plot) {
  const std::string text = read_file(fs::path(dirs.at(0)) / "sweep.json");
  const paper_sweep::Sweep s = paper_sweep::parse_sweep(text, dirs[0] + "/sweep.json");
  for (const std::string& d : dirs)
    if (json::parse(read_file(fs::path(d) / "sweep.json")) != s.source)
      throw paper_sweep::sweep_error(d + "/sweep.json: not the same sweep as " + dirs[0] +
                                     "/sweep.json");
  const fs::path out(out_dir);
  fs::create_directories(out / "runs");
  write_atomically(out / "sweep.json", s.source.dump(2) + "\n");
  std::map<std::string, json> results;
  std::map<std::string, std::string> where;  // run hash → the directory its result came from
  std::size_t missing = 0;
  for (const paper_sweep::Run& r : s.runs) {
    for (const std::string& d : dirs) {
      json j = stored_result(d, r.hash);
      if (j.is_null()) continue;
      if (fs::path(d) != out) write_atomically(out / "runs" / (r.hash + ".json"), j.dump(1) + "\n");
      results[r.hash] = std::move(j);
      where[r.hash] = d;
      break;
    }
    if (!results.count(r.hash)) ++missing;
  }
  if (missing > 0) {
    std::fprintf(stderr,
                 "kelp-sweep merge: %zu of %zu runs have no result in the given directories "
                 "(a shard did not finish: run it again, it resumes)\n",
                 missing, s.runs.size());
    return 1;
  }
  std::printf("kelp-sweep merge: %zu runs from %zu directories\n", s.runs.size(), dirs.size());
  return finish(s, results, out, plot, where);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "kelp-sweep: kelp-tethered-pair over a grid of scenarios (default: the paper's tether "
      "length x sea state x compensation x 5 seeds, 300 s each), in parallel, shardable, "
      "resumable"};
  RunOptions o;
  app.add_option("--sweep", o.sweep_file, "sweep file (JSON; see apps/sweep/README.md)");
  app.add_option("--out", o.out, "output directory (runs/, table.csv, table.md, errors.png)")
      ->capture_default_str();
  app.add_option("--jobs", o.jobs, "parallel runs (default: the number of cores)");
  app.add_option("--shard", o.shard, "run only shard I of N (0-based, I/N); no table");
  app.add_flag("--quiet", o.quiet, "no progress bar");
  app.add_flag("--no-plot", o.no_plot, "no figure");
  app.add_flag("--keep-series", o.keep_series,
               "keep each run's time series in runs/<hash>/ (timeseries.csv, nodes.csv, "
               "summary.json; kelp-replay makes its 3-D replay)");
  app.add_flag("--mcap", o.mcap,
               "also write each run as a ROS 2 bag, runs/<hash>.mcap (off by default: a bag is "
               "a few MB a simulated minute, a sweep has many runs)");
  app.add_option("--checkpoint-every", o.checkpoint_every,
                 "write each run's checkpoint (runs/<hash>.checkpoint.bin) every this many "
                 "simulated seconds and when stopped: a stopped or killed sweep run again resumes "
                 "its interrupted runs from there instead of from their start [s]")
      ->check(CLI::Range(1e-2, 1e7));
  app.add_flag("--dry-run", o.dry_run,
               "check and expand the sweep, print its runs (one JSON object a line: index, "
               "hash, grid point, seed, scenario as used) and exit; runs and writes nothing");
  app.footer(
      "Exit status: 0 done, 1 a run failed, 2 the plotting script failed, 3 an invalid sweep file "
      "or option, 130 / 143 stopped by SIGINT / SIGTERM (the runs under way stopped with their "
      "files whole and no result stored; status.json lists the runs done; run again to resume: "
      "with --checkpoint-every, the interrupted runs go on from their checkpoints).");
  CLI::App* m = app.add_subcommand("merge", "combine shard directories into one table");
  std::vector<std::string> dirs;
  std::string merged = "kelp-sweep-merged";
  bool merge_no_plot = false;
  m->add_option("dirs", dirs, "shard output directories")
      ->required()
      ->check(CLI::ExistingDirectory);
  m->add_option("--out", merged, "merged output directory")->capture_default_str();
  m->add_flag("--no-plot", merge_no_plot, "no figure");
  CLI11_PARSE(app, argc, argv);
  try {
    if (*m) return merge(dirs, merged, !merge_no_plot);
    // SIGINT and SIGTERM stop the runs under way cleanly (their files whole, no result stored)
    // and start no more; a second signal stops at once.
    kelp::sim::install_stop_handlers();
    return run(o);
  } catch (const paper_sweep::sweep_error& e) {
    std::fprintf(stderr, "kelp-sweep: invalid sweep: %s\n", e.what());
    return 3;
  } catch (const CLI::ValidationError& e) {
    std::fprintf(stderr, "kelp-sweep: %s\n", e.what());
    return 3;
  } catch (const kelp::invalid_argument& e) {  // e.g. a bad KELP_KERNEL
    std::fprintf(stderr, "kelp-sweep: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kelp-sweep: %s\n", e.what());
    return 1;
  }
}
