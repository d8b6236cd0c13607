/// \file
/// \brief The machinery of the scenario's field table (src/scenario.cpp's `scenario_fields`):
/// each JSON object of a scenario lists its keys once, as calls on a visitor, and three visitors
/// walk that one list: Keys (the keys an object allows, and those it requires), Parser (reads and
/// checks each key through Reader: errors name the file and the JSON path) and Writer (writes
/// each key back, under its when-to-write rule). The shape follows kelp/sim/ros2/messages.hpp's
/// `fields()`. Private to the kelp::sim library.
///
/// A fourth visitor, Reference, lists every key with its type, unit, default and allowed values:
/// docs/scenario-reference.md is generated from it (scenario_reference_markdown()), so the
/// reference cannot drift from the parser.
///
/// A table is a function of a visitor `v` (a generic lambda or a template) that calls, per key:
///
///     v.number(key, member, lo, hi[, rule])     a finite number in [lo, hi]
///     v.integer(key, member, lo, hi[, rule])    an integer in [lo, hi] (std::uint64_t or int)
///     v.whole(key, member, lo, hi[, rule])      a number in [lo, hi] that must be whole (int)
///     v.boolean(key, member[, rule])            true or false
///     v.number(key, optional, lo, hi, if_set)   likewise, into a std::optional<double> (unset
///                                               until the key is read)
///     v.choice(key, member, names[, rule])      one of the names of an enum's table (a
///                                               ChoiceName<E> array, kelp/sim/scenario.hpp: the
///                                               file spells the name, the member is the enum)
///     v.vec3(key, member[, rule])               [x, y, z] within ±1e4 (Vector3, or a
///                                               std::optional<Vector3> unset until read)
///     v.vec3_list(key, member[, rule])          a non-empty array of [x, y, z]
///     v.gains(key, member[, rule])              non-negative [kp, ki, kd]
///     v.object(key, object_rule, body)          a nested object, `body` its own table
///     v.preset_or_object(key, member, names, custom, body)
///                                               a preset's name (any of the table's but
///                                               `custom`), or an object (then member is `custom`
///                                               and `body` reads it)
///     v.custom(key, parse, write)               a key read and written by hand (lists)
///     v.key(key)                                a key read by the caller (allowed, not visited)
///     v.unit(u).number(...)                     the unit of the key that follows (`unit` returns
///                                               the visitor): the reference prints it, reading
///                                               and writing ignore it
///     v.on_read(f)                              parse only: f() at this point of the reading
///     v.check(f)                                parse only: f(reader, path) or f(reader, path,
///                                               object) at this point, for checks between keys
///
/// in the order the keys are read (the first error found is the one reported). The rule says
/// when the writer writes the key: `always` (the default), `never`, `required` (always, and
/// the parser requires it), `unless(value)`, `finite`, `if_set` (a
/// non-empty list, or an optional with a value), or any predicate on the value. An object's rule: a
/// bool (written when true), `unless_default` (only when it differs from the default scenario's) or
/// `non_empty`.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "json_reader.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {
namespace detail {
namespace schema {

/// \brief Rule: always written.
struct Always {
  template <class X>
  bool operator()(const X&) const {
    return true;
  }
};
/// \brief Rule: never written (a key that is read only, e.g. `deterministic`).
struct Never {
  template <class X>
  bool operator()(const X&) const {
    return false;
  }
};
/// \brief Rule: always written, and the parser requires the key (before reading any of the
/// object's keys: `missing "key"`).
struct Required : Always {};
/// \brief Rule: written unless the value is `value` (e.g. a choice's default).
template <class T>
struct Unless {
  T value;  ///< the value not written
  template <class X>
  bool operator()(const X& x) const {
    return !(x == value);
  }
};
/// \brief Rule: written when the value is finite (+∞: unset).
struct Finite {
  bool operator()(double x) const { return std::isfinite(x); }
};
/// \brief Rule: written when the list is not empty, or the optional has a value.
struct IfSet {
  template <class X>
  bool operator()(const X& x) const {
    return !x.empty();
  }
  template <class X>
  bool operator()(const std::optional<X>& x) const {
    return x.has_value();
  }
};
/// \brief Object rule: written only when it differs from the default scenario's.
struct UnlessDefault {};
/// \brief Object rule: written only when it has a key.
struct NonEmpty {};

inline constexpr Always always{};                 ///< \brief Rule: always written.
inline constexpr Never never{};                   ///< \brief Rule: never written.
inline constexpr Required required{};             ///< \brief Rule: required, always written.
inline constexpr Finite finite{};                 ///< \brief Rule: written when finite.
inline constexpr IfSet if_set{};                  ///< \brief Rule: written when set.
inline constexpr UnlessDefault unless_default{};  ///< \brief Object rule: see UnlessDefault.
inline constexpr NonEmpty non_empty{};            ///< \brief Object rule: see NonEmpty.
/// \brief Rule: written unless the value is `v`.
template <class T>
Unless<T> unless(T v) {
  return {v};
}

using Options = std::set<std::string>;  ///< a choice's options

/// \brief The names of a choice's table (all but `except`'s, when given), sorted: what Reader
/// checks the file's string against and lists in its error.
template <class E, std::size_t N>
Options option_names(const ChoiceName<E> (&names)[N], const E* except = nullptr) {
  Options o;
  for (const ChoiceName<E>& n : names)
    if (!except || n.value != *except) o.insert(n.name);
  return o;
}

/// \brief The enumerator named `name` in the table (the name is one of the table's).
template <class E, std::size_t N>
E choice_value(const std::string& name, const ChoiceName<E> (&names)[N]) {
  for (const ChoiceName<E>& n : names)
    if (name == n.name) return n.value;
  return names[0].value;
}

/// \brief The name of `value` in the table, for writing; throws kelp::invalid_argument for a
/// value outside it.
template <class E, std::size_t N>
std::string written_name(const char* key, E value, const ChoiceName<E> (&names)[N]) {
  const char* n = choice_name(value, names);
  if (!n)
    throw kelp::invalid_argument(std::string("scenario_json: \"") + key + "\" is " +
                                 std::to_string(static_cast<long long>(value)) +
                                 ", not one of its choices");
  return n;
}

/// \brief The visitor that collects an object's keys (allowed, and required) from its table.
class Keys {
 public:
  std::set<std::string> allowed;      ///< every key the table lists
  std::vector<std::string> required;  ///< the keys with the `required` rule, in table order

  template <class X, class R = Always>
  void number(const char* k, X&, double, double, R rule = {}) {
    add(k, rule);
  }
  template <class X, class R = Always>
  void integer(const char* k, X&, double, double, R rule = {}) {
    add(k, rule);
  }
  template <class R = Always>
  void whole(const char* k, int&, double, double, R rule = {}) {
    add(k, rule);
  }
  template <class R = Always>
  void boolean(const char* k, bool&, R rule = {}) {
    add(k, rule);
  }
  template <class E, std::size_t N, class R = Always>
  void choice(const char* k, E&, const ChoiceName<E> (&)[N], R rule = {}) {
    add(k, rule);
  }
  template <class X, class R = Always>
  void vec3(const char* k, X&, R rule = {}) {
    add(k, rule);
  }
  template <class X, class R = Always>
  void vec3_list(const char* k, X&, R rule = {}) {
    add(k, rule);
  }
  template <class R = Always>
  void gains(const char* k, Gains&, R rule = {}) {
    add(k, rule);
  }
  template <class R, class Body>
  void object(const char* k, R, Body&&) {
    allowed.insert(k);
  }
  template <class E, std::size_t N, class Body>
  void preset_or_object(const char* k, E&, const ChoiceName<E> (&)[N], E, Body&&) {
    allowed.insert(k);
  }
  template <class P, class W>
  void custom(const char* k, P&&, W&&) {
    allowed.insert(k);
  }
  void key(const char* k) { allowed.insert(k); }
  /// \brief The unit of the next key (for the reference; ignored here).
  Keys& unit(const char*) { return *this; }
  template <class F>
  void on_read(F&&) {}
  template <class F>
  void check(F&&) {}

 private:
  template <class R>
  void add(const char* k, const R&) {
    allowed.insert(k);
    if (std::is_same<R, Required>::value) required.push_back(k);
  }
};

/// \brief Reads the object `o` at `path` through its table `body`: the keys it allows first,
/// then the required ones, then each key in table order.
template <class Body>
void parse_object(const Reader& r, const nlohmann::json& o, const std::string& path, Body& body);

/// \brief The visitor that reads an object's keys (each through Reader, as the table orders them).
class Parser {
 public:
  /// \brief Reads the keys of `j`, the object at `path`.
  Parser(const Reader& r, const nlohmann::json& j, std::string path)
      : r_(r), j_(j), path_(std::move(path)) {}

  template <class R = Always>
  void number(const char* k, double& x, double lo, double hi, R = {}) {
    r_.number(j_, path_, k, x, lo, hi);
  }
  template <class R = Always>
  void number(const char* k, std::optional<double>& x, double lo, double hi, R = {}) {
    if (!j_.contains(k)) return;
    double v = 0;
    r_.number(j_, path_, k, v, lo, hi);
    x = v;
  }
  template <class R = Always>
  void integer(const char* k, std::uint64_t& x, double lo, double hi, R = {}) {
    r_.integer(j_, path_, k, x, lo, hi);
  }
  template <class R = Always>
  void integer(const char* k, int& x, double lo, double hi, R = {}) {
    std::uint64_t u = std::uint64_t(x);
    r_.integer(j_, path_, k, u, lo, hi);
    x = int(u);
  }
  template <class R = Always>
  void whole(const char* k, int& x, double lo, double hi, R = {}) {
    double n = x;
    r_.number(j_, path_, k, n, lo, hi);
    if (n != std::floor(n)) r_.fail(path_ + "/" + k, "expected an integer");
    x = static_cast<int>(n);
  }
  template <class R = Always>
  void boolean(const char* k, bool& x, R = {}) {
    r_.boolean(j_, path_, k, x);
  }
  template <class E, std::size_t N, class R = Always>
  void choice(const char* k, E& x, const ChoiceName<E> (&names)[N], R = {}) {
    if (!j_.contains(k)) return;
    std::string name;
    r_.choice(j_, path_, k, name, option_names(names));
    x = choice_value(name, names);
  }
  template <class R = Always>
  void vec3(const char* k, kelp::Vector3<double>& x, R = {}) {
    if (j_.contains(k)) x = r_.vec3(j_.at(k), path_ + "/" + k);
  }
  template <class R = Always>
  void vec3(const char* k, std::optional<kelp::Vector3<double>>& x, R = {}) {
    if (j_.contains(k)) x = r_.vec3(j_.at(k), path_ + "/" + k);
  }
  template <class R = Always>
  void vec3_list(const char* k, std::vector<kelp::Vector3<double>>& x, R = {}) {
    if (!j_.contains(k)) return;
    const auto& w = j_.at(k);
    const std::string p = path_ + "/" + k;
    if (!w.is_array()) r_.fail(p, "expected an array of [x, y, z]");
    if (w.empty()) r_.fail(p, "expected at least one waypoint, got []");
    for (std::size_t i = 0; i < w.size(); ++i)
      x.push_back(r_.vec3(w[i], p + "/" + std::to_string(i)));
  }
  template <class R = Always>
  void gains(const char* k, Gains& x, R = {}) {
    r_.gains(j_, path_, k, x);
  }
  template <class R, class Body>
  void object(const char* k, R, Body&& body) {
    if (j_.contains(k)) parse_object(r_, j_.at(k), path_ + "/" + k, body);
  }
  template <class E, std::size_t N, class Body>
  void preset_or_object(const char* k, E& x, const ChoiceName<E> (&names)[N], E custom,
                        Body&& body) {
    if (!j_.contains(k)) return;
    if (j_.at(k).is_string()) {
      std::string name;
      r_.choice(j_, path_, k, name, option_names(names, &custom));
      x = choice_value(name, names);
    } else {
      parse_object(r_, j_.at(k), path_ + "/" + k, body);
    }
  }
  /// `parse(value, reader, path)` when the key is given.
  template <class P, class W>
  void custom(const char* k, P&& parse, W&&) {
    if (j_.contains(k)) parse(j_.at(k), r_, path_ + "/" + k);
  }
  void key(const char*) {}
  /// \brief The unit of the next key (for the reference; ignored here).
  Parser& unit(const char*) { return *this; }
  template <class F>
  void on_read(F&& f) {
    f();
  }
  template <class F>
  void check(F&& f) {
    if constexpr (std::is_invocable<F&, const Reader&, const std::string&>::value)
      f(r_, path_);
    else
      f(r_, path_, j_);
  }

 private:
  const Reader& r_;
  const nlohmann::json& j_;
  std::string path_;
};

template <class Body>
void parse_object(const Reader& r, const nlohmann::json& o, const std::string& path, Body& body) {
  Keys keys;
  body(keys);
  r.object(o, path, keys.allowed);
  for (const auto& k : keys.required)
    if (!o.contains(k)) r.fail(path, "missing \"" + k + "\"");
  Parser p(r, o, path);
  body(p);
}

/// \brief The visitor that writes an object's keys, each under its rule.
class Writer {
 public:
  /// \brief Writes into `out`; `defaults` is the default scenario's JSON at the same place (for
  /// `unless_default`), or nullptr to write every such object (when writing the defaults).
  Writer(nlohmann::json& out, const nlohmann::json* defaults) : out_(out), defaults_(defaults) {}

  template <class X, class R = Always>
  void number(const char* k, X& x, double, double, R rule = {}) {
    put(k, x, rule);
  }
  template <class X, class R = Always>
  void integer(const char* k, X& x, double, double, R rule = {}) {
    put(k, x, rule);
  }
  template <class R = Always>
  void whole(const char* k, int& x, double, double, R rule = {}) {
    put(k, x, rule);
  }
  template <class R = Always>
  void boolean(const char* k, bool& x, R rule = {}) {
    put(k, x, rule);
  }
  template <class E, std::size_t N, class R = Always>
  void choice(const char* k, E& x, const ChoiceName<E> (&names)[N], R rule = {}) {
    if (rule(x)) out_[k] = written_name(k, x, names);
  }
  template <class R = Always>
  void vec3(const char* k, kelp::Vector3<double>& x, R rule = {}) {
    if (rule(x)) out_[k] = v3(x);
  }
  template <class R = Always>
  void vec3(const char* k, std::optional<kelp::Vector3<double>>& x, R rule = {}) {
    if (x && rule(x)) out_[k] = v3(*x);
  }
  template <class R = Always>
  void vec3_list(const char* k, std::vector<kelp::Vector3<double>>& x, R rule = {}) {
    if (!rule(x)) return;
    nlohmann::json a = nlohmann::json::array();
    for (const auto& p : x) a.push_back(v3(p));
    out_[k] = a;
  }
  template <class R = Always>
  void gains(const char* k, Gains& x, R rule = {}) {
    if (rule(x)) out_[k] = nlohmann::json::array({x.kp, x.ki, x.kd});
  }
  template <class Body>
  void object(const char* k, bool when, Body&& body) {
    if (when) out_[k] = sub(k, body);
  }
  template <class Body>
  void object(const char* k, NonEmpty, Body&& body) {
    nlohmann::json o = sub(k, body);
    if (!o.empty()) out_[k] = std::move(o);
  }
  template <class Body>
  void object(const char* k, UnlessDefault, Body&& body) {
    nlohmann::json o = sub(k, body);
    if (!defaults_ || !defaults_->contains(k) || o != defaults_->at(k)) out_[k] = std::move(o);
  }
  template <class E, std::size_t N, class Body>
  void preset_or_object(const char* k, E& x, const ChoiceName<E> (&names)[N], E custom,
                        Body&& body) {
    if (x == custom)
      out_[k] = sub(k, body);
    else
      out_[k] = written_name(k, x, names);
  }
  /// `write()`'s value, unless null.
  template <class P, class W>
  void custom(const char* k, P&&, W&& write) {
    nlohmann::json v = write();
    if (!v.is_null()) out_[k] = std::move(v);
  }
  void key(const char*) {}
  /// \brief The unit of the next key (for the reference; ignored here).
  Writer& unit(const char*) { return *this; }
  template <class F>
  void on_read(F&&) {}
  template <class F>
  void check(F&&) {}

 private:
  static nlohmann::json v3(const kelp::Vector3<double>& v) {
    return nlohmann::json::array({v(0), v(1), v(2)});
  }
  template <class X, class R>
  void put(const char* k, const X& x, const R& rule) {
    if (rule(x)) out_[k] = x;
  }
  template <class X, class R>
  void put(const char* k, const std::optional<X>& x, const R& rule) {
    if (x && rule(x)) out_[k] = *x;
  }
  template <class Body>
  nlohmann::json sub(const char* k, Body& body) {
    nlohmann::json o = nlohmann::json::object();
    const nlohmann::json* d = defaults_ && defaults_->contains(k) ? &defaults_->at(k)
                              : defaults_                         ? &null_
                                                                  : nullptr;
    Writer w(o, d);
    body(w);
    return o;
  }
  nlohmann::json& out_;
  const nlohmann::json* defaults_;
  const nlohmann::json null_;
};

/// \brief The visitor that lists an object's keys for the scenario reference: each key's path,
/// type, unit, default (the value in the scenario the table is walked over: the default one)
/// and allowed values. Nested objects are walked with their path.
class Reference {
 public:
  /// \brief One key of the reference.
  struct Row {
    std::string path;     ///< JSON pointer, e.g. /tether/length
    std::string type;     ///< number, integer, boolean, string, [x, y, z], object, ...
    std::string unit;     ///< SI unit, "1" for a ratio, empty when none applies
    std::string value;    ///< the default
    std::string allowed;  ///< range or choices
    std::string note;     ///< required, written when ..., read by the list
  };

  /// \brief Appends the rows of the object at `path` to `rows`.
  Reference(std::vector<Row>& rows, std::string path) : rows_(rows), path_(std::move(path)) {}

  /// \brief The unit of the next key.
  Reference& unit(const char* u) {
    unit_ = u;
    return *this;
  }
  template <class R = Always>
  void number(const char* k, double& x, double lo, double hi, R rule = {}) {
    add(k, "number", num(x), range(lo, hi), note(rule));
  }
  template <class R = Always>
  void number(const char* k, std::optional<double>& x, double lo, double hi, R rule = {}) {
    add(k, "number", x ? num(*x) : "unset", range(lo, hi), note(rule));
  }
  template <class X, class R = Always>
  void integer(const char* k, X& x, double lo, double hi, R rule = {}) {
    add(k, "integer", std::to_string(x), range(lo, hi), note(rule));
  }
  template <class R = Always>
  void whole(const char* k, int& x, double lo, double hi, R rule = {}) {
    add(k, "integer", std::to_string(x), range(lo, hi), note(rule));
  }
  template <class R = Always>
  void boolean(const char* k, bool& x, R rule = {}) {
    add(k, "boolean", x ? "true" : "false", "true, false", note(rule));
  }
  template <class E, std::size_t N, class R = Always>
  void choice(const char* k, E& x, const ChoiceName<E> (&names)[N], R rule = {}) {
    const char* n = choice_name(x, names);
    add(k, "string", n ? quoted(n) : "unset", choices(option_names(names)), note(rule));
  }
  template <class R = Always>
  void vec3(const char* k, kelp::Vector3<double>& x, R rule = {}) {
    add(k, "[x, y, z]", v3(x), "each within ±1e4", note(rule));
  }
  template <class R = Always>
  void vec3(const char* k, std::optional<kelp::Vector3<double>>& x, R rule = {}) {
    add(k, "[x, y, z]", x ? v3(*x) : "unset", "each within ±1e4", note(rule));
  }
  template <class R = Always>
  void vec3_list(const char* k, std::vector<kelp::Vector3<double>>& x, R rule = {}) {
    std::string v = x.empty() ? "[]" : std::to_string(x.size()) + " points";
    add(k, "array of [x, y, z]", v, "at least one; each within ±1e4", note(rule));
  }
  template <class R = Always>
  void gains(const char* k, Gains& x, R rule = {}) {
    add(k, "[kp, ki, kd]", "[" + num(x.kp) + ", " + num(x.ki) + ", " + num(x.kd) + "]", "each ≥ 0",
        note(rule));
  }
  template <class R, class Body>
  void object(const char* k, R, Body&& body) {
    add(k, "object", "", "", "");
    Reference sub(rows_, path_ + "/" + k);
    body(sub);
  }
  template <class E, std::size_t N, class Body>
  void preset_or_object(const char* k, E& x, const ChoiceName<E> (&names)[N], E custom,
                        Body&& body) {
    const char* n = choice_name(x, names);
    add(k, "string or object", n ? quoted(n) : "", choices(option_names(names, &custom)),
        "a preset's name, or an object of the keys below");
    Reference sub(rows_, path_ + "/" + k);
    body(sub);
  }
  template <class P, class W>
  void custom(const char* k, P&&, W&&) {
    add(k, "see below", "none", "", "");
  }
  /// \brief A key read by the list that holds the object (a name, a type, a reference).
  void key(const char* k) { add(k, "string", "", "", "read by the list"); }
  /// \brief Runs f() as the parser does: the defaults listed after it are those of an object
  /// given in the file (a custom sea's peak period, an enabled winch).
  template <class F>
  void on_read(F&& f) {
    f();
  }
  template <class F>
  void check(F&&) {}

  /// \brief A number as the shortest text that reads back to it.
  static std::string num(double x) {
    if (std::isinf(x)) return x > 0 ? "∞" : "−∞";
    char b[40];
    if (x == std::floor(x) && std::abs(x) < 1e15) {
      std::snprintf(b, sizeof b, "%.0f", x);
      return b;
    }
    for (int p = 1; p <= 17; ++p) {
      std::snprintf(b, sizeof b, "%.*g", p, x);
      if (std::strtod(b, nullptr) == x) break;
    }
    return b;
  }

 private:
  static std::string quoted(const std::string& s) { return "\"" + s + "\""; }
  static std::string range(double lo, double hi) { return "[" + num(lo) + ", " + num(hi) + "]"; }
  static std::string v3(const kelp::Vector3<double>& v) {
    return "[" + num(v(0)) + ", " + num(v(1)) + ", " + num(v(2)) + "]";
  }
  static std::string choices(const Options& o) {
    std::string s;
    for (const auto& n : o) s += (s.empty() ? "" : ", ") + quoted(n);
    return s;
  }
  template <class R>
  static std::string note(const R&) {
    if (std::is_same<R, Required>::value) return "required";
    if (std::is_same<R, Never>::value) return "read only (not echoed)";
    if (std::is_same<R, IfSet>::value) return "written back when set";
    return "";
  }
  void add(const char* k, std::string type, std::string value, std::string allowed,
           std::string note) {
    rows_.push_back({path_ + "/" + k, std::move(type), unit_, std::move(value), std::move(allowed),
                     std::move(note)});
    unit_.clear();
  }
  std::vector<Row>& rows_;
  std::string path_;
  std::string unit_;
};

/// \brief The object written by the table `body` (every `unless_default` object written).
template <class Body>
nlohmann::json write_object(Body&& body) {
  nlohmann::json o = nlohmann::json::object();
  Writer w(o, nullptr);
  body(w);
  return o;
}

}  // namespace schema
}  // namespace detail
}  // namespace sim
}  // namespace kelp
