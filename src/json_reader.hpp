/// \file
/// \brief The JSON schema checker behind parse_scenario and the readers of files that embed
/// scenarios: every failure a scenario_error naming the file and the JSON path. Private to the
/// kelp::sim library (it is what includes nlohmann-json).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "kelp/core/types.hpp"
#include "kelp/sim/scenario_reader.hpp"

namespace kelp {
namespace sim {

namespace detail {

/// Checks JSON values against the schema; every failure names the file and the JSON path.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  /// The file the errors name (a seabed's height-field file is relative to its directory).
  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw scenario_error(file_ + ": " + (path.empty() ? "/" : path) + ": " + what);
  }
  // Checks that `j` at `path` is an object with only the given keys.
  void object(const nlohmann::json& j, const std::string& path,
              const std::set<std::string>& keys) const {
    if (!j.is_object()) fail(path, "expected an object, got " + type(j));
    for (auto it = j.begin(); it != j.end(); ++it)
      if (!keys.count(it.key())) {
        std::string allowed;
        for (const auto& k : keys) allowed += (allowed.empty() ? "" : ", ") + k;
        fail(path + "/" + it.key(), "unknown key (allowed: " + allowed + ")");
      }
  }
  void number(const nlohmann::json& j, const std::string& path, const std::string& key, double& out,
              double lo, double hi) const {
    if (!j.contains(key)) return;
    const auto& v = j.at(key);
    const std::string p = path + "/" + key;
    if (!v.is_number()) fail(p, "expected a number, got " + type(v));
    const double x = v.get<double>();
    if (!std::isfinite(x) || x < lo || x > hi)
      fail(p, "expected a number in [" + fmt(lo) + ", " + fmt(hi) + "], got " + v.dump());
    out = x;
  }
  void integer(const nlohmann::json& j, const std::string& path, const std::string& key,
               std::uint64_t& out, double lo, double hi) const {
    if (!j.contains(key)) return;
    const auto& v = j.at(key);
    const std::string p = path + "/" + key;
    if (!v.is_number_integer() || v.get<double>() < lo || v.get<double>() > hi)
      fail(p, "expected an integer in [" + fmt(lo) + ", " + fmt(hi) + "], got " + v.dump());
    out = v.get<std::uint64_t>();
  }
  void boolean(const nlohmann::json& j, const std::string& path, const std::string& key,
               bool& out) const {
    if (!j.contains(key)) return;
    const auto& v = j.at(key);
    if (!v.is_boolean()) fail(path + "/" + key, "expected true or false, got " + v.dump());
    out = v.get<bool>();
  }
  void choice(const nlohmann::json& j, const std::string& path, const std::string& key,
              std::string& out, const std::set<std::string>& options) const {
    if (!j.contains(key)) return;
    const auto& v = j.at(key);
    std::string all;
    for (const auto& o : options) all += (all.empty() ? "" : ", ") + ("\"" + o + "\"");
    if (!v.is_string() || !options.count(v.get<std::string>()))
      fail(path + "/" + key, "expected one of " + all + ", got " + v.dump());
    out = v.get<std::string>();
  }
  kelp::Vector3<double> vec3(const nlohmann::json& v, const std::string& p) const {
    if (!v.is_array() || v.size() != 3)
      fail(p, "expected an array of 3 numbers [x, y, z], got " + v.dump());
    kelp::Vector3<double> out;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number() || !std::isfinite(v[i].get<double>()) ||
          std::abs(v[i].get<double>()) > 1e4)
        fail(p + "/" + std::to_string(i),
             "expected a finite number within ±1e4, got " + v[i].dump());
      out(i) = v[i].get<double>();
    }
    return out;
  }
  /// The value of a key the object must have (a missing key fails naming it).
  const nlohmann::json& require(const nlohmann::json& j, const std::string& path,
                                const std::string& key) const {
    if (!j.contains(key)) fail(path + "/" + key, "missing (required)");
    return j.at(key);
  }
  /// A finite number within ±`bound` at `p`.
  double finite(const nlohmann::json& v, const std::string& p, double bound = 1e12) const {
    if (!v.is_number() || !std::isfinite(v.get<double>()) || std::abs(v.get<double>()) > bound)
      fail(p, "expected a finite number within ±" + fmt(bound) + ", got " + v.dump());
    return v.get<double>();
  }
  /// An array of finite numbers at `p`, of one of the sizes allowed (none given: any size).
  std::vector<double> numbers(const nlohmann::json& v, const std::string& p,
                              const std::set<std::size_t>& sizes = {}) const {
    if (!v.is_array() || (!sizes.empty() && !sizes.count(v.size()))) {
      std::string n;
      for (std::size_t s : sizes) n += (n.empty() ? "" : " or ") + std::to_string(s);
      fail(p, "expected an array of " + (n.empty() ? std::string("numbers") : n + " numbers") +
                  ", got " + v.dump());
    }
    std::vector<double> out;
    for (std::size_t i = 0; i < v.size(); ++i)
      out.push_back(finite(v[i], p + "/" + std::to_string(i)));
    return out;
  }
  void gains(const nlohmann::json& j, const std::string& path, const std::string& key,
             Gains& out) const {
    if (!j.contains(key)) return;
    const kelp::Vector3<double> g = vec3(j.at(key), path + "/" + key);
    if ((g.array() < 0).any())
      fail(path + "/" + key, "expected non-negative gains [kp, ki, kd], got " + j.at(key).dump());
    out = {g(0), g(1), g(2)};
  }

 private:
  static std::string type(const nlohmann::json& j) { return std::string(j.type_name()); }
  static std::string fmt(double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", x);
    return b;
  }
  std::string file_;
};

}  // namespace detail

}  // namespace sim
}  // namespace kelp
