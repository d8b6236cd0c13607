// Test helpers: random field values and bit-exact comparison of messages.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "mavlink/mavlink.hpp"

namespace kelp_sitl::mavlink::test {

struct RandomOptions {
  bool finite_floats = false;     // no NaN or infinity (JavaScript cannot carry NaN payloads)
  double zero_probability = 0.0;  // chance that a field is left zero (exercises truncation)
  bool printable_text = true;     // char[N]: printable ASCII then NUL padding
};

template <class T>
void randomize(T& v, std::mt19937_64& rng, const RandomOptions& opt) {
  if constexpr (std::is_integral_v<T>) {
    v = static_cast<T>(rng());
  } else if constexpr (std::is_same_v<T, float>) {
    do {
      const auto bits = static_cast<std::uint32_t>(rng());
      std::memcpy(&v, &bits, 4);
    } while (opt.finite_floats && !std::isfinite(v));
  } else if constexpr (std::is_same_v<T, double>) {
    do {
      const std::uint64_t bits = rng();
      std::memcpy(&v, &bits, 8);
    } while (opt.finite_floats && !std::isfinite(v));
  } else {  // std::array<char, N>
    v.fill('\0');
    if (opt.printable_text) {
      const std::size_t n = rng() % (v.size() + 1);
      for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<char>(0x20 + rng() % 95);
    } else {
      for (auto& c : v) c = static_cast<char>(rng());
    }
  }
}

template <class M>
M random_message(std::mt19937_64& rng, const RandomOptions& opt = {}) {
  M m{};
  for_each_field(m, [&](const char*, auto& v) {
    if (opt.zero_probability > 0.0 &&
        std::uniform_real_distribution<double>(0.0, 1.0)(rng) < opt.zero_probability)
      return;
    randomize(v, rng, opt);
  });
  return m;
}

// Field-by-field equality of the wire bytes (floats compared bit for bit, NaN included).
template <class M>
bool same_fields(const M& a, const M& b, std::string* first_difference = nullptr) {
  std::array<std::uint8_t, 255> pa{}, pb{};
  encode_payload(a, pa.data());
  encode_payload(b, pb.data());
  std::size_t offset = 0;
  bool same = true;
  for_each_field(a, [&](const char* name, const auto& v) {
    const std::size_t size = WireType<Bare<decltype(v)>>::size;
    if (same && std::memcmp(pa.data() + offset, pb.data() + offset, size) != 0) {
      same = false;
      if (first_difference != nullptr) *first_difference = name;
    }
    offset += size;
  });
  return same;
}

}  // namespace kelp_sitl::mavlink::test
