// A run's checkpoint (kelp/sim/checkpoint.hpp): a run stopped at random steps and resumed from
// its checkpoint writes the files of a run never stopped, byte for byte (the default scenario
// with its bag, the winch dive, navigation from sensors, the pile wrap's entanglement); a
// checkpoint that is truncated, corrupted, of another scenario or another kelp version, or that
// does not match its run's files is refused with a state_error and changes nothing.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "kelp/sim.hpp"
#include "kelp/sim/checkpoint.hpp"
#include "kelp/sim/ros2/mcap.hpp"  // kelp::ros2::crc32
#include "sim_test_support.hpp"

namespace ks = kelp::sim;
namespace fs = std::filesystem;

// (A named namespace: the sim tests are one unity build, whose files have helpers of these names.)
namespace ckpt {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spill(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << bytes;
}

// summary.json less its wall-time fields (the only ones a resumed run may change).
nlohmann::json summary_less_wall(const fs::path& dir) {
  nlohmann::json j = nlohmann::json::parse(slurp(dir / "summary.json"));
  j.erase("wall_s");
  j.erase("realtime_factor");
  return j;
}

const std::vector<std::string> outputs = {"timeseries.csv", "nodes.csv", "events.csv", "run.mcap"};

// Every output file of the run in `dir` (a missing one as empty).
std::vector<std::string> files_of(const fs::path& dir) {
  std::vector<std::string> v;
  for (const auto& f : outputs) v.push_back(fs::exists(dir / f) ? slurp(dir / f) : std::string());
  v.push_back(fs::exists(dir / "checkpoint.bin") ? slurp(dir / "checkpoint.bin") : "");
  return v;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("kelp_test_checkpoint_" + name);
  fs::remove_all(d);
  return d;
}

// The run in `dir`, stopped before step `stop_at` (never when negative), resumed or started.
ks::RunSummary run(const ks::Scenario& sc, const fs::path& dir, double every, bool resume,
                   long stop_at) {
  ks::RunOptions o;
  o.out = dir.string();
  o.checkpoint_every = every;
  o.resume = resume;
  // Polled once before every step: a run (started or resumed) stops after `stop_at` steps.
  long polls = 0;
  if (stop_at >= 0) o.should_stop = [&polls, stop_at] { return polls++ >= stop_at; };
  return ks::run_scenario(sc, o);
}

ks::Scenario scenario_file(const std::string& name, double duration) {
  ks::Scenario sc = ks::load_scenario(std::string(KELP_SCENARIO_DIR) + "/" + name);
  sc.duration = duration;
  return sc;
}

// Runs `sc` uninterrupted, then again stopped at `stops` random moments and resumed after each:
// every output file and the summary (less its wall time) must be the same.
void check_resumed_equals_uninterrupted(const ks::Scenario& sc, const std::string& name, int stops,
                                        std::uint32_t seed) {
  const fs::path ref = fresh_dir(name + "_ref"), cut = fresh_dir(name + "_cut");
  const ks::RunSummary whole = run(sc, ref, 0, false, -1);
  REQUIRE(whole.completed);
  const long steps = std::lround(sc.duration / ks::ClosedLoop::dt);
  std::mt19937 rng(seed);
  // Stop moments in increasing order, each a number of steps after the previous one.
  std::vector<long> at;
  for (int i = 0; i < stops; ++i)
    at.push_back(std::uniform_int_distribution<long>(1, steps - 2)(rng));
  std::sort(at.begin(), at.end());
  at.erase(std::unique(at.begin(), at.end()), at.end());
  long done = 0;
  bool resume = false;
  for (long k : at) {
    const ks::RunSummary s = run(sc, cut, 1.0, resume, k - done);
    REQUIRE_FALSE(s.completed);
    CHECK(s.simulated_s == Approx(k * ks::ClosedLoop::dt).margin(1e-9));
    REQUIRE(fs::exists(cut / "checkpoint.bin"));
    const ks::CheckpointInfo info = ks::read_checkpoint_info((cut / "checkpoint.bin").string());
    CHECK(info.steps_taken == k);
    CHECK(info.total_steps == steps);
    CHECK(info.checkpoint_every == 1.0);
    done = k;
    resume = true;
  }
  const ks::RunSummary last = run(sc, cut, 1.0, resume, -1);
  CHECK(last.completed);
  CHECK_FALSE(fs::exists(cut / "checkpoint.bin"));  // a completed run removes it
  for (const auto& f : outputs) {
    INFO(name << ": " << f << " after " << at.size() << " stops");
    CHECK(fs::exists(ref / f) == fs::exists(cut / f));
    if (fs::exists(ref / f)) CHECK(slurp(ref / f) == slurp(cut / f));
  }
  CHECK(summary_less_wall(ref) == summary_less_wall(cut));
  fs::remove_all(ref);
  fs::remove_all(cut);
}

}  // namespace ckpt

TEST_CASE("a run stopped and resumed from its checkpoint writes an uninterrupted run's files",
          "[sim][checkpoint]") {
  SECTION("the default scenario, with its bag (run.mcap)") {
    ks::Scenario sc;
    sc.duration = 12.0;
    REQUIRE(sc.mcap);
    ckpt::check_resumed_equals_uninterrupted(sc, "default", 3, 1);
  }
  SECTION("the winch dive: the winch re-meshes the line, the strategy's command") {
    ckpt::check_resumed_equals_uninterrupted(ckpt::scenario_file("winch_dive.json", 20.0), "winch",
                                             3, 2);
  }
  SECTION("navigation from sensors: random streams, filters, USBL fixes in flight") {
    ks::Scenario sc = kelp_test::short_calm_run();
    sc.sea = ks::Sea::moderate;
    sc.duration = 12.0;
    sc.navigation.mode = ks::NavigationMode::sensors;
    sc.navigation.seed = 7;
    ckpt::check_resumed_equals_uninterrupted(sc, "navigation", 3, 3);
  }
  SECTION("the pile wrap: the entanglement monitor's winding and events") {
    ckpt::check_resumed_equals_uninterrupted(ckpt::scenario_file("pile_wrap.json", 30.0), "pile", 2,
                                             4);
  }
}

TEST_CASE("a checkpoint that cannot be resumed is refused and changes nothing",
          "[sim][checkpoint]") {
  ks::Scenario sc = kelp_test::short_calm_run();
  sc.duration = 3.0;
  const fs::path dir = ckpt::fresh_dir("refused");
  REQUIRE_FALSE(ckpt::run(sc, dir, 0.5, false, 150).completed);
  const fs::path cp = dir / "checkpoint.bin";
  const std::string good = ckpt::slurp(cp);
  REQUIRE(good.size() > 100);
  const std::vector<std::string> before = ckpt::files_of(dir);

  // Resuming with `bytes` as the checkpoint must throw a state_error and leave every file as it
  // was (the checkpoint is put back as `bytes` for the comparison).
  const auto refused = [&](const std::string& bytes, const ks::Scenario& s, const char* what) {
    INFO(what);
    ckpt::spill(cp, bytes);
    std::vector<std::string> expect = before;
    expect.back() = bytes;
    CHECK_THROWS_AS(ckpt::run(s, dir, 0.5, true, -1), ks::state_error);
    CHECK(ckpt::files_of(dir) == expect);
  };
  SECTION("truncated at every tenth of its length") {
    for (int i = 0; i < 10; ++i) refused(good.substr(0, good.size() * i / 10), sc, "truncated");
  }
  SECTION("one flipped bit, anywhere") {
    std::mt19937 rng(5);
    for (int i = 0; i < 20; ++i) {
      std::string b = good;
      const std::size_t at = std::uniform_int_distribution<std::size_t>(0, b.size() - 1)(rng);
      b[at] = char(b[at] ^ (1 << (i % 8)));
      refused(b, sc, "a flipped bit");
    }
  }
  SECTION("of another scenario") {
    ks::Scenario other = sc;
    other.seed += 1;
    refused(good, other, "another seed");
    other = sc;
    other.duration = 4.0;
    refused(good, other, "another duration");
  }
  SECTION("written by another kelp version (its CRC made right)") {
    std::string b = good;
    const std::size_t n = static_cast<unsigned char>(b[12]);
    REQUIRE(n > 0);
    b[13] = b[13] == '9' ? '8' : '9';  // the writer's version string starts at byte 13
    const std::uint32_t crc = kelp::ros2::crc32(b.data(), b.size() - 4);
    for (int i = 0; i < 4; ++i) b[b.size() - 4 + std::size_t(i)] = char((crc >> (8 * i)) & 0xFF);
    refused(b, sc, "another version");
    CHECK_THROWS_WITH(ks::read_checkpoint_info(cp.string()),
                      Catch::Contains("a checkpoint resumes only in the kelp that wrote it"));
  }
  SECTION("its run's files shorter than it counts, or missing") {
    ckpt::spill(cp, good);
    const std::string ts = ckpt::slurp(dir / "timeseries.csv");
    ckpt::spill(dir / "timeseries.csv", ts.substr(0, ts.size() / 2));
    const std::vector<std::string> cut = ckpt::files_of(dir);
    CHECK_THROWS_WITH(ckpt::run(sc, dir, 0.5, true, -1), Catch::Contains("timeseries.csv holds"));
    CHECK(ckpt::files_of(dir) == cut);
    ckpt::spill(dir / "timeseries.csv", ts);
    fs::remove(dir / "nodes.csv");
    CHECK_THROWS_WITH(ckpt::run(sc, dir, 0.5, true, -1), Catch::Contains("nodes.csv is missing"));
  }
  SECTION("no checkpoint at all") {
    fs::remove(cp);
    CHECK_THROWS_AS(ckpt::run(sc, dir, 0.5, true, -1), ks::state_error);
    CHECK_THROWS_WITH(ckpt::run(sc, dir, 0.5, true, -1), Catch::Contains("no checkpoint"));
  }
  fs::remove_all(dir);
}
