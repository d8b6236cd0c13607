// CRC-16/MCRF4XX, the checksum MAVLink calls "X.25": init 0xFFFF, polynomial 0x1021 reflected,
// no final XOR. The byte step is the one of MAVLink's C library
// (pymavlink/generator/C/include_v2.0/checksum.h, crc_accumulate). constexpr, so the CRC_EXTRA
// of every message can be checked at compile time (messages.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

namespace kelp_sitl::mavlink {

inline constexpr std::uint16_t kCrcInit = 0xFFFF;

constexpr std::uint16_t crc_accumulate(std::uint8_t byte, std::uint16_t crc) {
  std::uint8_t tmp = static_cast<std::uint8_t>(byte ^ static_cast<std::uint8_t>(crc & 0xFF));
  tmp = static_cast<std::uint8_t>(tmp ^ static_cast<std::uint8_t>(tmp << 4));
  return static_cast<std::uint16_t>((crc >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
}

constexpr std::uint16_t crc_accumulate(const std::uint8_t* data, std::size_t n, std::uint16_t crc) {
  for (std::size_t i = 0; i < n; ++i) crc = crc_accumulate(data[i], crc);
  return crc;
}

// Accumulates a NUL-terminated string without its terminator.
constexpr std::uint16_t crc_accumulate_str(const char* s, std::uint16_t crc) {
  for (; *s != '\0'; ++s) crc = crc_accumulate(static_cast<std::uint8_t>(*s), crc);
  return crc;
}

constexpr std::uint16_t x25(const char* s) { return crc_accumulate_str(s, kCrcInit); }

static_assert(x25("123456789") == 0x6F91, "CRC-16/MCRF4XX check value");

}  // namespace kelp_sitl::mavlink
