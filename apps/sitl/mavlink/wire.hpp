// Field types of MAVLink payloads and their little-endian wire form.
//
// Every message struct (messages.hpp) lists its fields once, in wire order, in two static
// functions: base_fields(msg, f) and extension_fields(msg, f) call f(name, member) per field.
// Everything else is derived from that list: payload encode/decode, the lengths, and the
// CRC_EXTRA seed, computed the way pymavlink's generator does it (generator/mavparse.py,
// message_checksum): x25 over "NAME ", then per base field "type " "name " and, for an array,
// one byte with its length; folded to 8 bits as (crc & 0xFF) ^ (crc >> 8).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include "crc.hpp"

namespace kelp_sitl::mavlink {

// MAVLink type name, bytes on the wire, and array length (0 for a scalar) of a member type.
template <class T>
struct WireType;

#define KELP_MAVLINK_SCALAR(T)                          \
  template <>                                           \
  struct WireType<std::T> {                             \
    static constexpr const char* name = #T;             \
    static constexpr std::size_t size = sizeof(std::T); \
    static constexpr std::size_t array_length = 0;      \
  };
KELP_MAVLINK_SCALAR(uint8_t)
KELP_MAVLINK_SCALAR(int8_t)
KELP_MAVLINK_SCALAR(uint16_t)
KELP_MAVLINK_SCALAR(int16_t)
KELP_MAVLINK_SCALAR(uint32_t)
KELP_MAVLINK_SCALAR(int32_t)
KELP_MAVLINK_SCALAR(uint64_t)
KELP_MAVLINK_SCALAR(int64_t)
#undef KELP_MAVLINK_SCALAR

template <>
struct WireType<float> {
  static constexpr const char* name = "float";
  static constexpr std::size_t size = 4;
  static constexpr std::size_t array_length = 0;
};
template <>
struct WireType<double> {
  static constexpr const char* name = "double";
  static constexpr std::size_t size = 8;
  static constexpr std::size_t array_length = 0;
};
// char[N]: NUL-padded text, not necessarily NUL-terminated (PARAM_SET.param_id, STATUSTEXT.text).
template <std::size_t N>
struct WireType<std::array<char, N>> {
  static constexpr const char* name = "char";
  static constexpr std::size_t size = N;
  static constexpr std::size_t array_length = N;
};

template <class T>
using Bare = std::remove_cv_t<std::remove_reference_t<T>>;

// Bytes of one element: the key by which mavgen sorts the base fields (descending, stable).
template <class T>
constexpr std::size_t element_size() {
  using W = WireType<Bare<T>>;
  return W::array_length == 0 ? W::size : W::size / W::array_length;
}

// ---- little-endian scalars -------------------------------------------------------------------
template <class T>
void put(std::uint8_t* p, const T& v) {
  if constexpr (std::is_integral_v<T>) {
    const auto u = static_cast<std::make_unsigned_t<T>>(v);
    for (std::size_t i = 0; i < sizeof(T); ++i) p[i] = static_cast<std::uint8_t>(u >> (8 * i));
  } else if constexpr (std::is_same_v<T, float>) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &v, 4);
    put(p, bits);
  } else if constexpr (std::is_same_v<T, double>) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    put(p, bits);
  } else {  // std::array<char, N>
    for (std::size_t i = 0; i < v.size(); ++i) p[i] = static_cast<std::uint8_t>(v[i]);
  }
}

template <class T>
void get(const std::uint8_t* p, T& v) {
  if constexpr (std::is_integral_v<T>) {
    std::make_unsigned_t<T> u = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      u = static_cast<std::make_unsigned_t<T>>(
          u | (static_cast<std::make_unsigned_t<T>>(p[i]) << (8 * i)));
    v = static_cast<T>(u);
  } else if constexpr (std::is_same_v<T, float>) {
    std::uint32_t bits = 0;
    get(p, bits);
    std::memcpy(&v, &bits, 4);
  } else if constexpr (std::is_same_v<T, double>) {
    std::uint64_t bits = 0;
    get(p, bits);
    std::memcpy(&v, &bits, 8);
  } else {
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<char>(p[i]);
  }
}

// ---- derived from a message's field list ---------------------------------------------------
template <class M, class F>
void for_each_field(M& msg, F&& f) {
  Bare<M>::base_fields(msg, f);
  Bare<M>::extension_fields(msg, f);
}

// Payload length without extensions (the minimum length) or with them (the full length).
template <class M>
constexpr std::size_t field_bytes(bool with_extensions) {
  M m{};
  std::size_t n = 0;
  auto add = [&n](const char*, auto& v) { n += WireType<Bare<decltype(v)>>::size; };
  M::base_fields(m, add);
  if (with_extensions) M::extension_fields(m, add);
  return n;
}

// CRC_EXTRA from the field list (mavparse.py message_checksum).
template <class M>
constexpr std::uint8_t compute_crc_extra() {
  M m{};
  std::uint16_t crc = crc_accumulate_str(M::name, kCrcInit);
  crc = crc_accumulate(static_cast<std::uint8_t>(' '), crc);
  M::base_fields(m, [&crc](const char* field, auto& v) {
    using W = WireType<Bare<decltype(v)>>;
    crc = crc_accumulate_str(W::name, crc);
    crc = crc_accumulate(static_cast<std::uint8_t>(' '), crc);
    crc = crc_accumulate_str(field, crc);
    crc = crc_accumulate(static_cast<std::uint8_t>(' '), crc);
    if (W::array_length != 0) crc = crc_accumulate(static_cast<std::uint8_t>(W::array_length), crc);
  });
  return static_cast<std::uint8_t>((crc & 0xFF) ^ (crc >> 8));
}

// True when the base fields are in mavgen's wire order, i.e. sorted by element size,
// largest first (a necessary condition: the XML order itself is not recorded here).
template <class M>
constexpr bool base_fields_in_wire_order() {
  M m{};
  std::size_t last = 8;
  bool ok = true;
  M::base_fields(m, [&](const char*, auto& v) {
    const std::size_t s = element_size<decltype(v)>();
    if (s > last) ok = false;
    last = s;
  });
  return ok;
}

// Writes the full payload (M::length bytes) to out; returns M::length.
template <class M>
std::size_t encode_payload(const M& msg, std::uint8_t* out) {
  std::size_t offset = 0;
  for_each_field(msg, [&](const char*, const auto& v) {
    put(out + offset, v);
    offset += WireType<Bare<decltype(v)>>::size;
  });
  return offset;
}

// Reads a full payload (M::length bytes; a truncated payload must be zero-filled first).
template <class M>
M decode_payload(const std::uint8_t* in) {
  M msg{};
  std::size_t offset = 0;
  for_each_field(msg, [&](const char*, auto& v) {
    get(in + offset, v);
    offset += WireType<Bare<decltype(v)>>::size;
  });
  return msg;
}

// Text of a char[N] field: up to the first NUL or all N characters.
template <std::size_t N>
std::string to_string(const std::array<char, N>& a) {
  std::size_t n = 0;
  while (n < N && a[n] != '\0') ++n;
  return std::string(a.data(), n);
}

// Sets a char[N] field: truncated to N characters, NUL-padded.
template <std::size_t N>
std::array<char, N> to_chars(std::string_view s) {
  std::array<char, N> a{};
  for (std::size_t i = 0; i < N && i < s.size(); ++i) a[i] = s[i];
  return a;
}

}  // namespace kelp_sitl::mavlink
