// Sweep files of kelp-sweep, their runs and their table.
//
// A sweep is a base scenario (kelp::sim's schema, kelp/sim/scenario.hpp) and axes, each a JSON path
// into the scenario and a list of values; the runs are the Cartesian product of the axes (the first
// axis varies slowest) times the seeds. Each run is keyed by a hash of its scenario as used (every
// field, canonical JSON), so a result found on disk is the result of exactly that scenario.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "kelp/sim/scenario.hpp"

namespace paper_sweep {

using nlohmann::json;

/// A sweep file that cannot be used: the message names the file and the JSON path.
struct sweep_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Axis {
  std::string path;          ///< JSON pointer into the scenario, e.g. /tether/length
  std::vector<json> values;  ///< what it takes
};

struct Run {
  std::size_t index = 0;  ///< position in the sweep (grid point major, seed minor)
  std::size_t point = 0;  ///< grid point (the axes' values)
  std::uint64_t seed = 0;
  kelp::sim::Scenario scenario;  ///< as used
  std::string hash;              ///< 16 hex digits of the canonical scenario JSON
};

struct Sweep {
  json base;  ///< the base scenario (JSON)
  std::vector<Axis> axes;
  std::vector<std::uint64_t> seeds;
  std::vector<Run> runs;
  std::size_t points = 1;  ///< product of the axes' sizes
  json source;             ///< the sweep file as read (written as sweep.json)
};

namespace detail {

// Tracks the JSON path while parsing, to name where a syntax error or an out-of-range number
// (1e999: JSON has no infinity) is.
class PathTracker : public nlohmann::json_sax<json> {
 public:
  std::string error_path;
  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override {
    stack_.push_back({false, 0, ""});
    return true;
  }
  bool key(string_t& k) override {
    stack_.back().key = k;
    return true;
  }
  bool end_object() override { return end(); }
  bool start_array(std::size_t) override {
    stack_.push_back({true, 0, ""});
    return true;
  }
  bool end_array() override { return end(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    error_path.clear();
    for (const Level& l : stack_) error_path += "/" + (l.array ? std::to_string(l.index) : l.key);
    if (error_path.empty()) error_path = "/";
    return false;
  }

 private:
  struct Level {
    bool array;
    std::size_t index;
    std::string key;
  };
  bool value() {
    if (!stack_.empty() && stack_.back().array) ++stack_.back().index;
    return true;
  }
  bool end() {
    stack_.pop_back();
    return value();
  }
  std::vector<Level> stack_;
};

inline std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

/// The reference tokens of a JSON pointer ("/a/b~1c" → a, b/c).
inline std::vector<std::string> pointer_tokens(const std::string& pointer) {
  std::vector<std::string> tokens;
  for (std::size_t i = 0; i < pointer.size();) {
    const std::size_t end = std::min(pointer.find('/', i + 1), pointer.size());
    std::string t;
    for (std::size_t k = i + 1; k < end; ++k) {
      if (pointer[k] == '~' && k + 1 < end && (pointer[k + 1] == '0' || pointer[k + 1] == '1')) {
        t += pointer[k + 1] == '0' ? '~' : '/';
        ++k;
      } else {
        t += pointer[k];
      }
    }
    tokens.push_back(t);
    i = end;
  }
  return tokens;
}

/// The first array index in `pointer` past the end of the array it indexes in `doc` (as it is,
/// or as setting the pointer would create it), or an empty string. nlohmann-json fills such a
/// gap with nulls, and creates a missing array from an index as large as the index: a pointer
/// ending in /99999999999 would allocate gigabytes. An index equal to the size appends.
inline std::string index_past_end(const json& doc, const std::string& pointer) {
  const json* node = &doc;  // nullptr: below here nothing exists yet
  for (const std::string& t : pointer_tokens(pointer)) {
    const bool index = !t.empty() && t.find_first_not_of("0123456789") == std::string::npos &&
                       (t == "0" || t[0] != '0');
    if (node == nullptr || node->is_null()) {
      if (index && t != "0") return t;  // would create an array of t + 1 nulls
      node = nullptr;
    } else if (node->is_object()) {
      const auto it = node->find(t);
      node = it == node->end() ? nullptr : &*it;
    } else if (node->is_array()) {
      if (!index) return "";  // "-" appends; anything else is nlohmann-json's error to report
      if (t.size() > 19 || std::stoull(t) > node->size()) return t;
      const auto i = static_cast<std::size_t>(std::stoull(t));
      node = i == node->size() ? nullptr : &(*node)[i];
    } else {
      return "";  // a number or a string: nlohmann-json refuses to index it
    }
  }
  return "";
}

inline std::string value_text(const json& v) {
  return v.is_string() ? v.get<std::string>() : v.dump();
}

}  // namespace detail

/// The paper's grid: tether length {5, 10, 15} m × sea {moderate, rough} × compensation
/// {off, on} × seeds 1–5, 300 s each, flown by the paper's controllers (the scenario's
/// `"control": {"preset": "paper"}`: the grid reproduces the paper's evaluation of them).
inline json default_sweep_json() {
  return json::parse(R"({
    "base": {"duration": 300, "control": {"preset": "paper"}},
    "axes": [
      {"path": "/tether/length", "values": [5, 10, 15]},
      {"path": "/sea", "values": ["moderate", "rough"]},
      {"path": "/control/compensation", "values": [false, true]}
    ],
    "seeds": [1, 2, 3, 4, 5]
  })");
}

/// The most runs (grid points × seeds) a sweep may expand to: the largest seed count.
inline constexpr std::size_t max_runs = 100000;
/// The most reference tokens in an axis' JSON pointer (a scenario is 4 levels deep).
inline constexpr std::size_t max_pointer_depth = 16;

/// Reads and checks a sweep from JSON text; expands its runs. `file` names it in errors.
/// \throws sweep_error naming the file and the JSON path (of the sweep file, or of a run's
/// scenario for a value the scenario refuses).
inline Sweep parse_sweep(const std::string& text, const std::string& file) {
  const auto fail = [&](const std::string& path, const std::string& what) -> void {
    throw sweep_error(file + ": " + path + ": " + what);
  };
  Sweep s;
  if (kelp::sim::json_depth(text, kelp::sim::max_json_depth) > kelp::sim::max_json_depth)
    fail("/", "arrays and objects nested more than " + std::to_string(kelp::sim::max_json_depth) +
                  " levels deep");
  try {
    s.source = json::parse(text);
  } catch (const json::exception& e) {
    detail::PathTracker tracker;
    json::sax_parse(text, &tracker);
    fail(tracker.error_path, std::string("not valid JSON (") + e.what() + ")");
  }
  const json& j = s.source;
  if (!j.is_object()) fail("/", "expected an object with base, axes and seeds");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "base" && it.key() != "axes" && it.key() != "seeds" &&
        it.key() != "deterministic")
      fail("/" + it.key(), "unknown key (allowed: axes, base, deterministic, seeds)");
  s.base = j.value("base", json::object());
  if (!s.base.is_object()) fail("/base", "expected a scenario object");
  // "deterministic": true pins every run's wave kernel to the portable path (the same numbers on
  // every CPU of a cluster): the base scenario's "deterministic": true.
  if (j.contains("deterministic")) {
    if (!j.at("deterministic").is_boolean())
      fail("/deterministic", "expected true or false, got " + j.at("deterministic").dump());
    if (j.at("deterministic").get<bool>()) s.base["deterministic"] = true;
  }
  if (j.contains("axes")) {
    const json& a = j.at("axes");
    if (!a.is_array()) fail("/axes", "expected an array of {\"path\", \"values\"}");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string p = "/axes/" + std::to_string(i);
      const json& ax = a[i];
      if (!ax.is_object()) fail(p, "expected {\"path\": \"/json/pointer\", \"values\": [...]}");
      for (auto it = ax.begin(); it != ax.end(); ++it)
        if (it.key() != "path" && it.key() != "values")
          fail(p + "/" + it.key(), "unknown key (allowed: path, values)");
      if (!ax.contains("path") || !ax.at("path").is_string())
        fail(p + "/path", "expected a JSON pointer into the scenario, e.g. \"/tether/length\"");
      Axis axis;
      axis.path = ax.at("path").get<std::string>();
      if (axis.path.empty() || axis.path[0] != '/')
        fail(p + "/path", "\"" + axis.path + "\" is not a JSON pointer (it starts with /)");
      if (axis.path == "/seed") fail(p + "/path", "seeds are given by /seeds, not an axis");
      const std::size_t levels = detail::pointer_tokens(axis.path).size();
      if (levels > max_pointer_depth)
        fail(p + "/path", "a JSON pointer of " + std::to_string(levels) +
                              " levels is deeper than any scenario field (at most " +
                              std::to_string(max_pointer_depth) + ")");
      if (!ax.contains("values") || !ax.at("values").is_array() || ax.at("values").empty())
        fail(p + "/values", "expected a non-empty array of values");
      for (std::size_t k = 0; k < ax.at("values").size(); ++k) {
        const json& v = ax.at("values")[k];
        if (v.is_number() && !std::isfinite(v.get<double>()))
          fail(p + "/values/" + std::to_string(k), "not a finite number");
        axis.values.push_back(v);
      }
      if (axis.values.size() > max_runs / s.points)
        fail(p + "/values",
             "the sweep would have more than " + std::to_string(max_runs) + " grid points");
      s.axes.push_back(axis);
      s.points *= axis.values.size();
    }
  }
  const json seeds = j.value("seeds", json::array({1}));
  const auto natural = [](const json& v) {
    return v.is_number_integer() && v.get<std::int64_t>() >= 0;
  };
  if (natural(seeds)) {
    const auto n = seeds.get<std::uint64_t>();
    if (n < 1 || n > 100000) fail("/seeds", "expected a count in [1, 100000] or a list of seeds");
    for (std::uint64_t k = 1; k <= n; ++k) s.seeds.push_back(k);
  } else if (seeds.is_array() && !seeds.empty()) {
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      if (!natural(seeds[k]))
        fail("/seeds/" + std::to_string(k),
             "expected a non-negative integer, got " + seeds[k].dump());
      s.seeds.push_back(seeds[k].get<std::uint64_t>());
    }
  } else {
    fail("/seeds", "expected a count or a non-empty list of non-negative integers");
  }
  if (s.seeds.size() > max_runs / s.points)
    fail("/seeds", std::to_string(s.points) + " grid points × " + std::to_string(s.seeds.size()) +
                       " seeds are more than " + std::to_string(max_runs) + " runs");

  // Expand: each grid point's scenario, validated by the scenario reader (which names the path).
  for (std::size_t point = 0; point < s.points; ++point) {
    json scenario = s.base;
    std::string where;
    std::size_t rest = point;
    for (std::size_t i = s.axes.size(); i-- > 0;) {
      const Axis& ax = s.axes[i];
      const json& v = ax.values[rest % ax.values.size()];
      rest /= ax.values.size();
      const std::string past_end = detail::index_past_end(scenario, ax.path);
      if (!past_end.empty())
        fail("/axes/" + std::to_string(i) + "/path",
             "\"" + ax.path + "\": index " + past_end + " is past the end of its array");
      try {
        scenario[json::json_pointer(ax.path)] = v;
      } catch (const json::exception& e) {
        fail("/axes/" + std::to_string(i) + "/path",
             "\"" + ax.path + "\" cannot be set in the base scenario (" + e.what() + ")");
      }
      where = ax.path + " = " + v.dump() + (where.empty() ? "" : ", ") + where;
    }
    for (const std::uint64_t seed : s.seeds) {
      scenario["seed"] = seed;
      Run r;
      try {
        r.scenario = kelp::sim::parse_scenario(scenario.dump(), file + " (run with " + where + ")");
      } catch (const kelp::sim::scenario_error& e) {
        throw sweep_error(e.what());
      }
      r.index = s.runs.size();
      r.point = point;
      r.seed = seed;
      char h[17];
      std::snprintf(
          h, sizeof h, "%016llx",
          static_cast<unsigned long long>(detail::fnv1a(kelp::sim::scenario_json(r.scenario))));
      r.hash = h;
      s.runs.push_back(std::move(r));
    }
  }
  return s;
}

inline Sweep load_sweep(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw sweep_error(file + ": cannot be read");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_sweep(text, file);
}

/// The values of grid point `point`, one per axis.
inline std::vector<json> point_values(const Sweep& s, std::size_t point) {
  std::vector<json> v(s.axes.size());
  for (std::size_t i = s.axes.size(); i-- > 0;) {
    v[i] = s.axes[i].values[point % s.axes[i].values.size()];
    point /= s.axes[i].values.size();
  }
  return v;
}

/// What a run's numbers depend on beyond its scenario: the wave kernel's instruction path and
/// the C library's math, as its summary records them ("unrecorded" for results written before
/// kelp recorded them).
inline std::string platform_of(const json& result) {
  const json& s = result.at("summary");
  return s.value("kernel", std::string("unrecorded")) + " kernel, math library " +
         s.value("math_library", std::string("unrecorded"));
}

/// A warning when the results were computed on different instruction paths or C library math
/// (e.g. shards run on different CPUs), else an empty string. `where` names each result's source
/// (by run hash; e.g. its shard directory), or is empty.
inline std::string mixed_platforms_warning(const std::map<std::string, json>& results,
                                           const std::map<std::string, std::string>& where = {}) {
  std::map<std::string, std::size_t> runs;
  std::map<std::string, std::set<std::string>> sources;
  for (const auto& [hash, result] : results) {
    const std::string p = platform_of(result);
    ++runs[p];
    const auto it = where.find(hash);
    if (it != where.end()) sources[p].insert(it->second);
  }
  if (runs.size() < 2) return "";
  std::string w =
      "warning: the runs were computed on different instruction paths or C library math, so "
      "their numbers may differ from what one machine would give (";
  bool first = true;
  for (const auto& [p, n] : runs) {
    w += (first ? "" : "; ") + p + ": " + std::to_string(n) + " run" + (n == 1 ? "" : "s");
    if (!sources[p].empty()) {
      w += " from";
      for (const std::string& d : sources[p]) w += " " + d;
    }
    first = false;
  }
  return w +
         "). For the same numbers on every CPU run the sweep with \"deterministic\": true "
         "(docs/deterministic.md).";
}

/// The numbers the table summarises, from a run's summary.
struct Metrics {
  double auv = 0, asv = 0, combined = 0, max_tension = 0, slack = 0;
  /// The tether solver's work (summary's `tether_solver`; NaN in a result written before it
  /// was reported): mean and most Newton iterations per step, retried steps, explicit
  /// fallbacks.
  double newton_mean = NAN, newton_max = NAN, retried = NAN, fallbacks = NAN;
};
inline Metrics metrics_of(const json& summary) {
  Metrics m;
  m.auv = summary.at("auv").at("rms_path_error_m").get<double>();
  m.asv = summary.at("asv").at("rms_distance_to_auv_m").get<double>();
  m.combined = std::sqrt(0.5 * (m.auv * m.auv + m.asv * m.asv));
  m.max_tension = summary.at("tether").at("max_tension_n").get<double>();
  m.slack = summary.at("tether").at("slack_fraction").get<double>();
  if (summary.contains("tether_solver")) {
    const json& t = summary.at("tether_solver");
    m.newton_mean = t.at("newton_iterations_per_step_mean").get<double>();
    m.newton_max = t.at("newton_iterations_per_step_max").get<double>();
    m.retried = t.at("retried_steps").get<double>();
    m.fallbacks = t.at("explicit_fallbacks").get<double>();
  }
  return m;
}

/// Writes table.csv and table.md: per grid point, mean and sample standard deviation over the
/// seeds, and the tether solver's work in the grid point's worst run (the most Newton
/// iterations in one step, retried steps and explicit fallbacks, each the largest over the
/// seeds) beside the mean Newton iterations per step over all its runs. `results` maps run
/// hashes to their stored result ({"summary": ...}).
inline void write_table(const Sweep& s, const std::map<std::string, json>& results,
                        const std::filesystem::path& dir) {
  std::ofstream csv(dir / "table.csv"), md(dir / "table.md");
  const char* names[] = {"auv_rms_error_m", "asv_rms_error_m", "combined_rms_error_m",
                         "max_tension_n", "slack_fraction"};
  for (const Axis& a : s.axes) csv << a.path << ',';
  csv << "seeds";
  for (const char* n : names) csv << ',' << n << "_mean," << n << "_sd";
  csv << ",newton_iterations_per_step_mean,worst_newton_iterations_per_step_max,"
         "worst_retried_steps,worst_explicit_fallbacks\n";
  md << '|';
  for (const Axis& a : s.axes) md << ' ' << a.path << " |";
  md << " seeds | AUV RMS error [m] | ASV RMS error [m] | combined [m] | max tension [N] | slack "
        "fraction | Newton it./step: mean (worst max) | worst run: retried / fallbacks |\n|";
  for (std::size_t i = 0; i < s.axes.size() + 8; ++i) md << "---|";
  md << '\n';
  char b[64];
  for (std::size_t point = 0; point < s.points; ++point) {
    std::vector<Metrics> ms;
    for (const Run& r : s.runs)
      if (r.point == point) ms.push_back(metrics_of(results.at(r.hash).at("summary")));
    const auto stat = [&](double Metrics::*f, double& mean, double& sd) {
      mean = 0;
      for (const Metrics& m : ms) mean += m.*f;
      mean /= static_cast<double>(ms.size());
      double ss = 0;
      for (const Metrics& m : ms) ss += (m.*f - mean) * (m.*f - mean);
      sd = ms.size() > 1 ? std::sqrt(ss / static_cast<double>(ms.size() - 1)) : 0.0;
    };
    const std::vector<json> values = point_values(s, point);
    md << '|';
    for (const json& v : values) {
      csv << detail::value_text(v) << ',';
      md << ' ' << detail::value_text(v) << " |";
    }
    csv << ms.size();
    md << ' ' << ms.size() << " |";
    for (double Metrics::*f : {&Metrics::auv, &Metrics::asv, &Metrics::combined,
                               &Metrics::max_tension, &Metrics::slack}) {
      double mean, sd;
      stat(f, mean, sd);
      std::snprintf(b, sizeof b, ",%.9g,%.9g", mean, sd);
      csv << b;
      std::snprintf(b, sizeof b, " %.3g ± %.2g |", mean, sd);
      md << b;
    }
    // The solver: the mean over the runs, the worst run's maxima (NaN propagates: a result
    // without the solver's figures shows as nan).
    double newton_mean = 0, newton_max = 0, retried = 0, fallbacks = 0;
    for (const Metrics& m : ms) {
      newton_mean += m.newton_mean / static_cast<double>(ms.size());
      newton_max = std::isnan(m.newton_max) ? m.newton_max : std::max(newton_max, m.newton_max);
      retried = std::isnan(m.retried) ? m.retried : std::max(retried, m.retried);
      fallbacks = std::isnan(m.fallbacks) ? m.fallbacks : std::max(fallbacks, m.fallbacks);
    }
    char line[1200];  // %.0f of a double takes up to 309 digits
    std::snprintf(line, sizeof line, ",%.9g,%.9g,%.9g,%.9g", newton_mean, newton_max, retried,
                  fallbacks);
    csv << line;
    std::snprintf(line, sizeof line, " %.3g (%.0f) | %.0f / %.0f |", newton_mean, newton_max,
                  retried, fallbacks);
    md << line;
    csv << '\n';
    md << '\n';
  }
}

}  // namespace paper_sweep
