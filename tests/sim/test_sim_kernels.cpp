// kelp::sim's deterministic mode: a scenario with "deterministic": true gives the same summary and
// time series, bit for bit, whichever kernel path the process forces (as a CPU with AVX-512, one
// with AVX2 only and one with neither would choose); without it the forced paths' runs are
// recorded as such and differ where their wave kernels differ. The scenario's "kernel" and
// "deterministic" fields: parsing, echo and errors.
#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "kelp/core/kernel_path.hpp"
#include "kelp/sim.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;
namespace simd = kelp::simd;
using simd::KernelPath;

namespace {

// 30 s in the rough sea: long enough for last-bit differences of the wave kernel to reach the
// printed digits of the time series through the closed loop.
ks::Scenario rough_run() {
  ks::Scenario sc;
  sc.sea = ks::Sea::rough;
  sc.duration = 30.0;
  sc.log_rate = 10.0;
  sc.node_rate = 1.0;
  return sc;
}

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

struct Run {
  nlohmann::json summary;  // without the wall-clock fields
  std::string timeseries, nodes;
};

// The scenario run with the process' policy `p`, its log in `dir`.
Run run_with_policy(const ks::Scenario& sc, KernelPath p, const std::string& dir) {
  simd::set_kernel_policy(p);
  ks::SimulateOptions o;
  o.log_dir = dir;
  Run r;
  r.summary = kelp_test::json_of(ks::simulate(sc, o));
  r.summary.erase("wall_s");
  r.summary.erase("realtime_factor");
  r.timeseries = read(std::filesystem::path(dir) / "timeseries.csv");
  r.nodes = read(std::filesystem::path(dir) / "nodes.csv");
  return r;
}

// True when the wave kernel on path p gives other bits than the portable one for this sea.
bool wave_kernel_differs(const ks::Scenario& sc, KernelPath p) {
  const ks::WorldSetup w = ks::world_setup(sc, "test");
  kelp::environment::WaveFieldd a = w.environment.waves(), b = a;
  a.set_kernel(KernelPath::portable);
  b.set_kernel(p);
  const int n = 21;
  kelp::Matrix3X<double> pts(3, n), va(3, n), aa(3, n), vb(3, n), ab(3, n);
  for (int i = 0; i < n; ++i) pts.col(i) << 0.5 * i, 0.1 * i, 0.5 * i;
  a.kinematics(pts, 7.0, va, aa);
  b.kinematics(pts, 7.0, vb, ab);
  return std::memcmp(va.data(), vb.data(), sizeof(double) * 3 * n) != 0 ||
         std::memcmp(aa.data(), ab.data(), sizeof(double) * 3 * n) != 0;
}

// Restores the automatic policy at the end of a test.
struct AutomaticAfter {
  ~AutomaticAfter() { simd::set_kernel_policy(KernelPath::automatic); }
};

}  // namespace

TEST_CASE("deterministic runs give the same summary and logs, bit for bit, on every kernel path",
          "[sim][kernel]") {
  AutomaticAfter restore;
  const auto paths = simd::supported_kernels();
  if (paths.size() == 1) WARN("this CPU runs only the portable path: the runs cannot differ here");
  for (KernelPath p : {KernelPath::avx2, KernelPath::avx512})
    if (!simd::kernel_supported(p))
      WARN("skipped " << simd::kernel_name(p) << ": this CPU lacks it");

  ks::Scenario det = rough_run();
  det.kernel = KernelPath::portable;  // what "deterministic": true gives
  const std::string root = "sim_kernels";
  const Run reference = run_with_policy(det, KernelPath::portable, root + "/det_portable");
  CHECK(reference.summary.at("kernel") == "portable");
  CHECK(reference.summary.at("math_library") == simd::math_library_fingerprint());
  CHECK(reference.summary.at("scenario").at("kernel") == "portable");
  CHECK(reference.timeseries.size() > 1000);

  const Run free_portable = run_with_policy(rough_run(), KernelPath::portable, root + "/portable");
  CHECK(free_portable.summary.at("kernel") == "portable");
  for (KernelPath p : paths) {
    const std::string name = simd::kernel_name(p);
    INFO("process policy " << name);
    const Run d = run_with_policy(det, p, root + "/det_" + name);
    CHECK(d.summary == reference.summary);
    CHECK(d.timeseries == reference.timeseries);
    CHECK(d.nodes == reference.nodes);

    // Without the deterministic mode the run takes the forced path and says so.
    const Run f = run_with_policy(rough_run(), p, root + "/" + name);
    CHECK(f.summary.at("kernel") == name);
    CHECK(!f.summary.at("scenario").contains("kernel"));
    if (p == KernelPath::portable) continue;
    const bool kernel_differs = wave_kernel_differs(rough_run(), p);
    // The summaries without the field that names the path (which always differs).
    nlohmann::json a = f.summary, b = free_portable.summary;
    a.erase("kernel");
    b.erase("kernel");
    const bool run_differs = a != b;
    WARN("without the deterministic mode the " << name << " path's run "
                                               << (run_differs ? "differs from" : "equals")
                                               << " the portable one on this CPU");
    // Where the wave kernels differ, the closed loop carries the difference into the summary's
    // numbers: the deterministic runs above would have differed without the mode. (Not always
    // into the time series' printed digits: since the calm start and the "kelp" controllers the
    // two paths' runs stay within ~1e-15 relative of each other over these 30 s.)
    if (kernel_differs) CHECK(run_differs);
  }
}

TEST_CASE("a scenario's kernel and deterministic fields: parsing, echo and errors",
          "[sim][kernel]") {
  CHECK(ks::parse_scenario("{}", "s.json").kernel == KernelPath::automatic);
  CHECK(!kelp_test::json_of(ks::parse_scenario("{}", "s.json")).contains("kernel"));
  CHECK(ks::parse_scenario(R"({"deterministic": true})", "s.json").kernel == KernelPath::portable);
  CHECK(ks::parse_scenario(R"({"deterministic": false})", "s.json").kernel ==
        KernelPath::automatic);
  CHECK(ks::parse_scenario(R"({"deterministic": true, "kernel": "portable"})", "s.json").kernel ==
        KernelPath::portable);
  for (const char* k : {"auto", "portable", "avx2", "avx512"}) {
    const ks::Scenario s = ks::parse_scenario(std::string(R"({"kernel": ")") + k + "\"}", "s.json");
    CHECK(std::string(ks::to_string(s.kernel)) == k);
    // The echo reads back to the same scenario.
    CHECK(ks::parse_scenario(kelp_test::json_of(s).dump(), "echo").kernel == s.kernel);
  }
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"kernel": "sse2"})", "s.json"),
                    Catch::Contains("s.json: /kernel: expected one of"));
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"deterministic": "yes"})", "s.json"),
                    Catch::Contains("/deterministic: expected true or false"));
  CHECK_THROWS_AS(ks::parse_scenario(R"({"deterministic": true, "kernel": "avx2"})", "s.json"),
                  ks::scenario_error);
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"deterministic": true, "kernel": "avx512"})", "s.json"),
                    Catch::Contains("/deterministic") && Catch::Contains("avx512"));

  // A pinned path reaches the world's wave field; one this CPU lacks is the file's error.
  for (KernelPath p : {KernelPath::portable, KernelPath::avx2, KernelPath::avx512}) {
    ks::Scenario sc;
    sc.kernel = p;
    if (simd::kernel_supported(p)) {
      CHECK(ks::world_setup(sc, "s.json").environment.waves().kernel() == p);
    } else {
      CHECK_THROWS_AS(ks::world_setup(sc, "s.json"), ks::scenario_error);
      CHECK_THROWS_WITH(ks::world_setup(sc, "s.json"), Catch::Contains("s.json: /kernel:"));
    }
  }
}
