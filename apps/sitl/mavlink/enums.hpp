// The MAVLink enum values kelp-mission uses (common.xml, minimal.xml) and ArduPilot's
// custom_mode numbers (ArduSub/mode.h and Rover/mode.h, enum class Mode::Number).
#pragma once

#include <cstdint>
#include <string>

namespace kelp_sitl::mavlink {

// MAV_TYPE
inline constexpr std::uint8_t kTypeGroundRover = 10;
inline constexpr std::uint8_t kTypeSurfaceBoat = 11;
inline constexpr std::uint8_t kTypeSubmarine = 12;
inline constexpr std::uint8_t kTypeGcs = 6;
// MAV_AUTOPILOT
inline constexpr std::uint8_t kAutopilotArdupilotmega = 3;
inline constexpr std::uint8_t kAutopilotInvalid = 8;
// MAV_MODE_FLAG
inline constexpr std::uint8_t kModeFlagCustomModeEnabled = 1;
inline constexpr std::uint8_t kModeFlagSafetyArmed = 128;
// MAV_COMP_ID
inline constexpr std::uint8_t kCompAutopilot1 = 1;
inline constexpr std::uint8_t kCompMissionPlanner = 190;
// MAV_CMD
inline constexpr std::uint16_t kCmdDoSetMode = 176;
inline constexpr std::uint16_t kCmdComponentArmDisarm = 400;
// MAV_FRAME
inline constexpr std::uint8_t kFrameLocalNed = 1;
inline constexpr std::uint8_t kFrameGlobalRelativeAltInt = 6;

// POSITION_TARGET_TYPEMASK bits.
inline constexpr std::uint16_t kIgnoreX = 1, kIgnoreY = 2, kIgnoreZ = 4;
inline constexpr std::uint16_t kIgnoreVx = 8, kIgnoreVy = 16, kIgnoreVz = 32;
inline constexpr std::uint16_t kIgnoreAx = 64, kIgnoreAy = 128, kIgnoreAz = 256;
inline constexpr std::uint16_t kForceSet = 512, kIgnoreYaw = 1024, kIgnoreYawRate = 2048;
// Position and yaw; velocity, acceleration and yaw rate ignored: 0x09F8 = 2552.
inline constexpr std::uint16_t kTypeMaskPositionYaw =
    kIgnoreVx | kIgnoreVy | kIgnoreVz | kIgnoreAx | kIgnoreAy | kIgnoreAz | kIgnoreYawRate;
static_assert(kTypeMaskPositionYaw == 2552);
// Position only: 0x0DF8 = 3576.
inline constexpr std::uint16_t kTypeMaskPosition = kTypeMaskPositionYaw | kIgnoreYaw;
static_assert(kTypeMaskPosition == 3576);

// MAV_RESULT
enum class Result : std::uint8_t {
  Accepted = 0,
  TemporarilyRejected = 1,
  Denied = 2,
  Unsupported = 3,
  Failed = 4,
  InProgress = 5,
  Cancelled = 6,
};

inline std::string result_name(std::uint8_t r) {
  switch (r) {
    case 0:
      return "ACCEPTED";
    case 1:
      return "TEMPORARILY_REJECTED";
    case 2:
      return "DENIED";
    case 3:
      return "UNSUPPORTED";
    case 4:
      return "FAILED";
    case 5:
      return "IN_PROGRESS";
    case 6:
      return "CANCELLED";
    default:
      return "MAV_RESULT " + std::to_string(r);
  }
}

inline std::string command_name(std::uint16_t c) {
  switch (c) {
    case kCmdDoSetMode:
      return "MAV_CMD_DO_SET_MODE";
    case kCmdComponentArmDisarm:
      return "MAV_CMD_COMPONENT_ARM_DISARM";
    default:
      return "MAV_CMD " + std::to_string(c);
  }
}

// MAV_SEVERITY
inline std::string severity_name(std::uint8_t s) {
  static const char* const names[] = {"EMERGENCY", "ALERT",  "CRITICAL", "ERROR",
                                      "WARNING",   "NOTICE", "INFO",     "DEBUG"};
  return s < 8 ? names[s] : "SEVERITY " + std::to_string(s);
}

// ArduSub custom_mode (ArduSub/mode.h).
namespace sub_mode {
inline constexpr std::uint32_t kStabilize = 0;
inline constexpr std::uint32_t kAltHold = 2;  // "Depth Hold"
inline constexpr std::uint32_t kGuided = 4;
inline constexpr std::uint32_t kManual = 19;
}  // namespace sub_mode

// ArduRover custom_mode (Rover/mode.h).
namespace rover_mode {
inline constexpr std::uint32_t kManual = 0;
inline constexpr std::uint32_t kHold = 4;
inline constexpr std::uint32_t kGuided = 15;
}  // namespace rover_mode

}  // namespace kelp_sitl::mavlink
