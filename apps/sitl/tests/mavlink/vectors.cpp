// kelp-mavlink-vectors: the codec's side of the cross-check against node-mavlink
// (node/crosscheck.js drives it).
//
//   kelp-mavlink-vectors encode SEED COUNT
//       prints, for every message and COUNT random instances each (the first one all zeros),
//       one JSON line {"name", "msgid", "seq", "sysid", "compid", "hex", "fields"}.
//   kelp-mavlink-vectors decode
//       reads lines of hex frames on stdin and prints one JSON line per input line:
//       {"ok": true, "name", "msgid", "seq", "sysid", "compid", "len", "fields"} or
//       {"ok": false, "stats": {...}} when the parser did not accept exactly one frame.
//
// Field values in JSON: integers up to 32 bits as numbers, 64-bit integers as decimal strings,
// float / double as the hexadecimal of their IEEE-754 bits (so the comparison is bit-exact),
// char[N] as the text up to the first NUL.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "mavlink/mavlink.hpp"
#include "message_utils.hpp"

using namespace kelp_sitl::mavlink;
using nlohmann::json;

namespace {

std::string hex_of(std::uint64_t bits, int digits) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%0*llx", digits, static_cast<unsigned long long>(bits));
  return buf;
}

template <class T>
json to_json_value(const T& v) {
  if constexpr (std::is_same_v<T, float>) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &v, 4);
    return hex_of(bits, 8);
  } else if constexpr (std::is_same_v<T, double>) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    return hex_of(bits, 16);
  } else if constexpr (std::is_integral_v<T> && sizeof(T) == 8) {
    return std::to_string(v);
  } else if constexpr (std::is_integral_v<T>) {
    return static_cast<std::int64_t>(v);
  } else {
    return to_string(v);
  }
}

template <class M>
json fields_json(const M& m) {
  json j = json::object();
  for_each_field(m, [&](const char* name, const auto& v) { j[name] = to_json_value(v); });
  return j;
}

std::string to_hex(const std::vector<std::uint8_t>& bytes) {
  std::string s;
  for (std::uint8_t b : bytes) s += hex_of(b, 2);
  return s;
}

int run_encode(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  for_each_message_type([&](auto tag) {
    using M = decltype(tag);
    for (int k = 0; k < count; ++k) {
      test::RandomOptions opt;
      opt.finite_floats = true;
      opt.zero_probability = (k % 3) * 0.4;
      const M msg = k == 0 ? M{} : test::random_message<M>(rng, opt);
      const auto seq = static_cast<std::uint8_t>(rng());
      const auto sysid = static_cast<std::uint8_t>(rng());
      const auto compid = static_cast<std::uint8_t>(rng());
      json line = {{"name", M::name},
                   {"msgid", M::msg_id},
                   {"seq", seq},
                   {"sysid", sysid},
                   {"compid", compid},
                   {"hex", to_hex(encode_v2(msg, seq, sysid, compid))},
                   {"fields", fields_json(msg)}};
      std::cout << line.dump() << '\n';
    }
  });
  return 0;
}

int run_decode() {
  std::string line;
  while (std::getline(std::cin, line)) {
    std::vector<std::uint8_t> bytes;
    for (std::size_t i = 0; i + 1 < line.size(); i += 2)
      bytes.push_back(static_cast<std::uint8_t>(std::stoul(line.substr(i, 2), nullptr, 16)));
    Parser p;
    const auto frames = p.feed(bytes);
    json out;
    if (frames.size() != 1 || p.buffered() != 0) {
      const ParserStats& s = p.stats();
      out = {{"ok", false},
             {"stats",
              {{"frames", s.frames},
               {"bad_crc", s.bad_crc},
               {"unknown_msgid", s.unknown_msgid},
               {"bad_length", s.bad_length},
               {"bad_flags", s.bad_flags},
               {"junk_bytes", s.junk_bytes},
               {"buffered", p.buffered()}}}};
    } else {
      const Frame& f = frames[0];
      out = {{"ok", true},         {"msgid", f.msg_id}, {"seq", f.seq},        {"sysid", f.sysid},
             {"compid", f.compid}, {"len", f.len},      {"version", f.version}};
      for_each_message_type([&](auto tag) {
        using M = decltype(tag);
        if (auto m = decode<M>(f)) {
          out["name"] = M::name;
          out["fields"] = fields_json(*m);
        }
      });
    }
    std::cout << out.dump() << '\n';
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string cmd = argc > 1 ? argv[1] : "";
  if (cmd == "encode" && argc == 4) return run_encode(std::stoull(argv[2]), std::stoi(argv[3]));
  if (cmd == "decode" && argc == 2) return run_decode();
  std::cerr << "usage: kelp-mavlink-vectors encode SEED COUNT | kelp-mavlink-vectors decode\n";
  return 2;
}
