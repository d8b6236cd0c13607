// ArduPilot SITL's JSON physics interface, the wire formats (ArduPilot
// libraries/SITL/SIM_JSON.h and SIM_JSON.cpp, libraries/SITL/examples/JSON/readme.md):
//
// - SITL → physics, UDP: a binary servo packet, little-endian, packed:
//     uint16 magic (18458 with 16 channels, 29569 with 32 when SERVO_32_ENABLE = 1),
//     uint16 frame_rate [Hz], uint32 frame_count, uint16 pwm[16 or 32] [µs]  (40 or 72 bytes).
//   pwm[i] is SERVO(i+1); 0 means no pulse on that channel.
// - physics → SITL, UDP, to the packet's source address: one JSON object per servo packet,
//   "\n" + json + "\n". SITL's parser is not a JSON parser: it finds each key with strstr (the
//   first match anywhere wins), skips exactly the two characters `":` after it and reads vectors
//   with sscanf("[%f, %f, %f]"). So: no whitespace between a key and its value, vectors start
//   with `[` right after the colon, and no other key may contain a mandatory key's name before
//   it. Mandatory: timestamp [s] (absolute; SITL advances its clock by the difference),
//   imu.gyro [rad/s] and imu.accel_body [m/s²] (specific force) in body FRD, position [m] NED
//   from home, velocity [m/s] NED, and attitude or quaternion ([w, x, y, z], body → NED).
//   Optional here: rng_1 [m] (the first rangefinder, for RNGFND1_TYPE = 100).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "kelp/core/types.hpp"

namespace kelp_sitl {

inline constexpr std::uint16_t servo_magic_16 = 18458;  ///< 16-channel servo packet
inline constexpr std::uint16_t servo_magic_32 = 29569;  ///< 32-channel servo packet
inline constexpr std::size_t servo_packet_16_size = 8 + 2 * 16;
inline constexpr std::size_t servo_packet_32_size = 8 + 2 * 32;

struct ServoPacket {
  std::uint16_t magic = 0;
  std::uint16_t frame_rate = 0;         ///< [Hz]
  std::uint32_t frame_count = 0;        ///< SITL's count of accepted replies
  int channels = 0;                     ///< 16 or 32
  std::array<std::uint16_t, 32> pwm{};  ///< [µs]; channels beyond `channels` are 0
};

/// Why a datagram is not a servo packet.
enum class PacketError { none, size, magic, size_mismatch };

inline const char* to_string(PacketError e) {
  switch (e) {
    case PacketError::none:
      return "none";
    case PacketError::size:
      return "not 40 or 72 bytes";
    case PacketError::magic:
      return "unknown magic";
    case PacketError::size_mismatch:
      return "size does not match the magic";
  }
  return "?";
}

/// Reads a servo packet from a datagram of `n` bytes. Only exact sizes are accepted: 40 bytes
/// with the 16-channel magic, 72 bytes with the 32-channel one.
inline PacketError parse_servo_packet(const std::uint8_t* d, std::size_t n, ServoPacket& out) {
  if (n != servo_packet_16_size && n != servo_packet_32_size) return PacketError::size;
  const auto u16 = [d](std::size_t i) {
    return static_cast<std::uint16_t>(d[i] | (static_cast<unsigned>(d[i + 1]) << 8));
  };
  const std::uint16_t magic = u16(0);
  int channels = 0;
  if (magic == servo_magic_16)
    channels = 16;
  else if (magic == servo_magic_32)
    channels = 32;
  else
    return PacketError::magic;
  if (n != 8 + 2 * static_cast<std::size_t>(channels)) return PacketError::size_mismatch;
  out.magic = magic;
  out.channels = channels;
  out.frame_rate = u16(2);
  out.frame_count = static_cast<std::uint32_t>(d[4]) | (static_cast<std::uint32_t>(d[5]) << 8) |
                    (static_cast<std::uint32_t>(d[6]) << 16) |
                    (static_cast<std::uint32_t>(d[7]) << 24);
  out.pwm.fill(0);
  for (int i = 0; i < channels; ++i) out.pwm[static_cast<std::size_t>(i)] = u16(8 + 2 * i);
  return PacketError::none;
}

/// What the physics tells SITL about one vehicle.
struct VehicleReply {
  double timestamp = 0;                           ///< physics time [s]
  kelp::Vector3<double> gyro{0, 0, 0};            ///< body FRD [rad/s]
  kelp::Vector3<double> accel_body{0, 0, 0};      ///< specific force, body FRD [m/s²]
  kelp::Vector3<double> position{0, 0, 0};        ///< NED from home [m]
  kelp::Vector3<double> velocity{0, 0, 0};        ///< NED [m/s]
  kelp::Quaternion<double> attitude{1, 0, 0, 0};  ///< body → NED
  double rangefinder = NAN;                       ///< rng_1 [m]; NaN: not sent
  /// Battery terminal voltage [V] and current [A], sent as "battery": {"voltage", "current"}
  /// (ArduPilot's JSON backend, libraries/SITL/SIM_JSON.h since master ab03dc37 of 2025-07-28,
  /// feeds them to its simulated analog battery monitor, BATT_MONITOR 4; older builds ignore
  /// the key); NaN (before the first step, or no battery): not sent.
  double battery_voltage = NAN, battery_current = NAN;
};

/// The largest reply format_reply() writes.
inline constexpr std::size_t max_reply_size = 512;

/// Writes "\n{json}\n" for SITL into `buf` and returns its length, or 0 when a value is not
/// finite (SITL must not be sent NaN: the reply is withheld and the caller reports it).
inline std::size_t format_reply(const VehicleReply& r, char* buf, std::size_t cap) {
  const auto finite3 = [](const kelp::Vector3<double>& v) { return v.allFinite(); };
  if (!std::isfinite(r.timestamp) || !finite3(r.gyro) || !finite3(r.accel_body) ||
      !finite3(r.position) || !finite3(r.velocity) || !r.attitude.coeffs().allFinite())
    return 0;
  const auto& q = r.attitude;
  int n = std::snprintf(
      buf, cap,
      "\n{\"timestamp\":%.9f,\"imu\":{\"gyro\":[%.9g,%.9g,%.9g],\"accel_body\":[%.9g,%.9g,%.9g]},"
      "\"position\":[%.9g,%.9g,%.9g],\"quaternion\":[%.9g,%.9g,%.9g,%.9g],"
      "\"velocity\":[%.9g,%.9g,%.9g]",
      r.timestamp, r.gyro.x(), r.gyro.y(), r.gyro.z(), r.accel_body.x(), r.accel_body.y(),
      r.accel_body.z(), r.position.x(), r.position.y(), r.position.z(), q.w(), q.x(), q.y(), q.z(),
      r.velocity.x(), r.velocity.y(), r.velocity.z());
  if (n <= 0 || static_cast<std::size_t>(n) >= cap) return 0;
  if (std::isfinite(r.rangefinder)) {
    const int m =
        std::snprintf(buf + n, cap - static_cast<std::size_t>(n), ",\"rng_1\":%.6g", r.rangefinder);
    if (m <= 0 || static_cast<std::size_t>(n + m) >= cap) return 0;
    n += m;
  }
  if (std::isfinite(r.battery_voltage) && std::isfinite(r.battery_current)) {
    const int m = std::snprintf(buf + n, cap - static_cast<std::size_t>(n),
                                ",\"battery\":{\"voltage\":%.6g,\"current\":%.6g}",
                                r.battery_voltage, r.battery_current);
    if (m <= 0 || static_cast<std::size_t>(n + m) >= cap) return 0;
    n += m;
  }
  const int m = std::snprintf(buf + n, cap - static_cast<std::size_t>(n), "}\n");
  if (m <= 0 || static_cast<std::size_t>(n + m) >= cap) return 0;
  return static_cast<std::size_t>(n + m);
}

}  // namespace kelp_sitl
