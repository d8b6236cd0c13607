// libFuzzer target: kelp-sweep's sweep reader and expansion (apps/sweep/sweep.hpp).
//
// Oracle: parse_sweep(input) either throws paper_sweep::sweep_error (the documented error, whose
// message names the file) or returns a sweep with points = the product of the axes' sizes,
// runs = points × seeds, each run's scenario valid (it re-reads) and its hash 16 hex digits,
// and point_values() of every point one value per axis. Any other exception, crash or
// sanitizer report is a finding. Inputs expanding to 2001..max_runs runs are skipped (cost).
#include <string>

#include "fuzz_common.hpp"
#include "sweep.hpp"

namespace {

// Cost bound of the harness, not of the code under test: a valid sweep of thousands of runs
// takes seconds under ASan (parse_scenario per run) and covers nothing a small one does not.
// Returns true for inputs that would expand to more than kMaxFuzzRuns but at most max_runs
// runs; those are skipped. Larger ones are run: they must be refused before the expansion.
constexpr std::size_t kMaxFuzzRuns = 2000;

bool too_costly(const std::string& text) {
  if (kelp::sim::json_depth(text, kelp::sim::max_json_depth) > kelp::sim::max_json_depth)
    return false;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) return false;
  const auto saturated = [](std::size_t a, std::size_t b) {
    return b != 0 && a > paper_sweep::max_runs / b ? paper_sweep::max_runs + 1 : a * b;
  };
  std::size_t runs = 1;
  if (j.contains("axes") && j["axes"].is_array())
    for (const auto& a : j["axes"])
      if (a.is_object() && a.contains("values") && a["values"].is_array())
        runs = saturated(runs, a["values"].size());
  if (j.contains("seeds")) {
    const auto& s = j["seeds"];
    if (s.is_array())
      runs = saturated(runs, s.size());
    else if (s.is_number_unsigned())
      runs = saturated(runs, static_cast<std::size_t>(
                                 std::min<std::uint64_t>(s.get<std::uint64_t>(), 1u << 30)));
  }
  return runs > kMaxFuzzRuns && runs <= paper_sweep::max_runs;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (too_costly(text)) return 0;
  paper_sweep::Sweep s;
  try {
    s = paper_sweep::parse_sweep(text, "fuzz.json");
  } catch (const paper_sweep::sweep_error& e) {
    KELP_FUZZ_REQUIRE(std::string(e.what()).rfind("fuzz.json", 0) == 0,
                      "sweep_error does not name the file");
    return 0;
  }
  std::size_t points = 1;
  for (const paper_sweep::Axis& a : s.axes) {
    KELP_FUZZ_REQUIRE(!a.values.empty() && !a.path.empty() && a.path[0] == '/', "axis");
    points *= a.values.size();
  }
  KELP_FUZZ_REQUIRE(s.points == points, "points is not the product of the axes' sizes");
  KELP_FUZZ_REQUIRE(!s.seeds.empty(), "no seeds");
  KELP_FUZZ_REQUIRE(s.runs.size() == s.points * s.seeds.size(), "runs = points x seeds");
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    const paper_sweep::Run& r = s.runs[i];
    KELP_FUZZ_REQUIRE(r.index == i && r.point < s.points, "run index");
    KELP_FUZZ_REQUIRE(
        r.hash.size() == 16 && r.hash.find_first_not_of("0123456789abcdef") == std::string::npos,
        "run hash");
    KELP_FUZZ_REQUIRE(r.scenario.seed == r.seed, "run seed");
  }
  for (std::size_t p = 0; p < s.points && p < 64; ++p)
    KELP_FUZZ_REQUIRE(paper_sweep::point_values(s, p).size() == s.axes.size(), "point_values");
  return 0;
}
