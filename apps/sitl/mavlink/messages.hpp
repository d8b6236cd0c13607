// The MAVLink messages kelp-mission uses, as plain structs. Ids, CRC_EXTRA seeds, field names,
// types and wire order follow ArduPilot's mavlink fork (message_definitions/v1.0/minimal.xml and
// common.xml) after mavgen's reordering (pymavlink generator/mavparse.py): base fields sorted by
// element size, largest first, stable; extension fields (after <extensions/>) unsorted, last.
// base_fields / extension_fields list the fields in that wire order; the static_asserts at the
// end recompute every length and CRC_EXTRA from those lists.
//
// Units are the XML's: lat/lon degE7, alt mm (GLOBAL_POSITION_INT, GPS_RAW_INT) or m (float
// fields), angles rad, local positions m in NED, time_boot_ms ms since the autopilot booted.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "wire.hpp"

namespace kelp_sitl::mavlink {

// HEARTBEAT (minimal.xml).
struct Heartbeat {
  static constexpr std::uint32_t msg_id = 0;
  static constexpr const char* name = "HEARTBEAT";
  static constexpr std::uint8_t crc_extra = 50;
  static constexpr std::size_t min_length = 9;
  static constexpr std::size_t length = 9;
  std::uint32_t custom_mode{};
  std::uint8_t type{};
  std::uint8_t autopilot{};
  std::uint8_t base_mode{};
  std::uint8_t system_status{};
  std::uint8_t mavlink_version{3};  // MAVLink 2: 3
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("custom_mode", m.custom_mode);
    f("type", m.type);
    f("autopilot", m.autopilot);
    f("base_mode", m.base_mode);
    f("system_status", m.system_status);
    f("mavlink_version", m.mavlink_version);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// SYS_STATUS (common.xml). ArduPilot's fork has no extension fields; upstream MAVLink later
// added three (onboard_control_sensors_*_extended), which this codec does not know.
struct SysStatus {
  static constexpr std::uint32_t msg_id = 1;
  static constexpr const char* name = "SYS_STATUS";
  static constexpr std::uint8_t crc_extra = 124;
  static constexpr std::size_t min_length = 31;
  static constexpr std::size_t length = 31;
  std::uint32_t onboard_control_sensors_present{};
  std::uint32_t onboard_control_sensors_enabled{};
  std::uint32_t onboard_control_sensors_health{};
  std::uint16_t load{};
  std::uint16_t voltage_battery{};
  std::int16_t current_battery{};
  std::uint16_t drop_rate_comm{};
  std::uint16_t errors_comm{};
  std::uint16_t errors_count1{};
  std::uint16_t errors_count2{};
  std::uint16_t errors_count3{};
  std::uint16_t errors_count4{};
  std::int8_t battery_remaining{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("onboard_control_sensors_present", m.onboard_control_sensors_present);
    f("onboard_control_sensors_enabled", m.onboard_control_sensors_enabled);
    f("onboard_control_sensors_health", m.onboard_control_sensors_health);
    f("load", m.load);
    f("voltage_battery", m.voltage_battery);
    f("current_battery", m.current_battery);
    f("drop_rate_comm", m.drop_rate_comm);
    f("errors_comm", m.errors_comm);
    f("errors_count1", m.errors_count1);
    f("errors_count2", m.errors_count2);
    f("errors_count3", m.errors_count3);
    f("errors_count4", m.errors_count4);
    f("battery_remaining", m.battery_remaining);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// SYSTEM_TIME (common.xml).
struct SystemTime {
  static constexpr std::uint32_t msg_id = 2;
  static constexpr const char* name = "SYSTEM_TIME";
  static constexpr std::uint8_t crc_extra = 137;
  static constexpr std::size_t min_length = 12;
  static constexpr std::size_t length = 12;
  std::uint64_t time_unix_usec{};
  std::uint32_t time_boot_ms{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_unix_usec", m.time_unix_usec);
    f("time_boot_ms", m.time_boot_ms);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// SET_MODE (common.xml).
struct SetMode {
  static constexpr std::uint32_t msg_id = 11;
  static constexpr const char* name = "SET_MODE";
  static constexpr std::uint8_t crc_extra = 89;
  static constexpr std::size_t min_length = 6;
  static constexpr std::size_t length = 6;
  std::uint32_t custom_mode{};
  std::uint8_t target_system{};
  std::uint8_t base_mode{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("custom_mode", m.custom_mode);
    f("target_system", m.target_system);
    f("base_mode", m.base_mode);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// PARAM_REQUEST_READ (common.xml). param_index -1: by param_id, NUL-padded.
struct ParamRequestRead {
  static constexpr std::uint32_t msg_id = 20;
  static constexpr const char* name = "PARAM_REQUEST_READ";
  static constexpr std::uint8_t crc_extra = 214;
  static constexpr std::size_t min_length = 20;
  static constexpr std::size_t length = 20;
  std::int16_t param_index{-1};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::array<char, 16> param_id{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("param_index", m.param_index);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
    f("param_id", m.param_id);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// PARAM_VALUE (common.xml).
struct ParamValue {
  static constexpr std::uint32_t msg_id = 22;
  static constexpr const char* name = "PARAM_VALUE";
  static constexpr std::uint8_t crc_extra = 220;
  static constexpr std::size_t min_length = 25;
  static constexpr std::size_t length = 25;
  float param_value{};
  std::uint16_t param_count{};
  std::uint16_t param_index{};
  std::array<char, 16> param_id{};
  std::uint8_t param_type{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("param_value", m.param_value);
    f("param_count", m.param_count);
    f("param_index", m.param_index);
    f("param_id", m.param_id);
    f("param_type", m.param_type);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// PARAM_SET (common.xml). param_id is NUL-padded, not necessarily NUL-terminated.
struct ParamSet {
  static constexpr std::uint32_t msg_id = 23;
  static constexpr const char* name = "PARAM_SET";
  static constexpr std::uint8_t crc_extra = 168;
  static constexpr std::size_t min_length = 23;
  static constexpr std::size_t length = 23;
  float param_value{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::array<char, 16> param_id{};
  std::uint8_t param_type{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("param_value", m.param_value);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
    f("param_id", m.param_id);
    f("param_type", m.param_type);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// GPS_RAW_INT (common.xml).
struct GpsRawInt {
  static constexpr std::uint32_t msg_id = 24;
  static constexpr const char* name = "GPS_RAW_INT";
  static constexpr std::uint8_t crc_extra = 24;
  static constexpr std::size_t min_length = 30;
  static constexpr std::size_t length = 52;
  std::uint64_t time_usec{};
  std::int32_t lat{};
  std::int32_t lon{};
  std::int32_t alt{};
  std::uint16_t eph{};
  std::uint16_t epv{};
  std::uint16_t vel{};
  std::uint16_t cog{};
  std::uint8_t fix_type{};
  std::uint8_t satellites_visible{};
  std::int32_t alt_ellipsoid{};
  std::uint32_t h_acc{};
  std::uint32_t v_acc{};
  std::uint32_t vel_acc{};
  std::uint32_t hdg_acc{};
  std::uint16_t yaw{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_usec", m.time_usec);
    f("lat", m.lat);
    f("lon", m.lon);
    f("alt", m.alt);
    f("eph", m.eph);
    f("epv", m.epv);
    f("vel", m.vel);
    f("cog", m.cog);
    f("fix_type", m.fix_type);
    f("satellites_visible", m.satellites_visible);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("alt_ellipsoid", m.alt_ellipsoid);
    f("h_acc", m.h_acc);
    f("v_acc", m.v_acc);
    f("vel_acc", m.vel_acc);
    f("hdg_acc", m.hdg_acc);
    f("yaw", m.yaw);
  }
};

// ATTITUDE (common.xml).
struct Attitude {
  static constexpr std::uint32_t msg_id = 30;
  static constexpr const char* name = "ATTITUDE";
  static constexpr std::uint8_t crc_extra = 39;
  static constexpr std::size_t min_length = 28;
  static constexpr std::size_t length = 28;
  std::uint32_t time_boot_ms{};
  float roll{};
  float pitch{};
  float yaw{};
  float rollspeed{};
  float pitchspeed{};
  float yawspeed{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_boot_ms", m.time_boot_ms);
    f("roll", m.roll);
    f("pitch", m.pitch);
    f("yaw", m.yaw);
    f("rollspeed", m.rollspeed);
    f("pitchspeed", m.pitchspeed);
    f("yawspeed", m.yawspeed);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// LOCAL_POSITION_NED (common.xml).
struct LocalPositionNed {
  static constexpr std::uint32_t msg_id = 32;
  static constexpr const char* name = "LOCAL_POSITION_NED";
  static constexpr std::uint8_t crc_extra = 185;
  static constexpr std::size_t min_length = 28;
  static constexpr std::size_t length = 28;
  std::uint32_t time_boot_ms{};
  float x{};
  float y{};
  float z{};
  float vx{};
  float vy{};
  float vz{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_boot_ms", m.time_boot_ms);
    f("x", m.x);
    f("y", m.y);
    f("z", m.z);
    f("vx", m.vx);
    f("vy", m.vy);
    f("vz", m.vz);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// GLOBAL_POSITION_INT (common.xml).
struct GlobalPositionInt {
  static constexpr std::uint32_t msg_id = 33;
  static constexpr const char* name = "GLOBAL_POSITION_INT";
  static constexpr std::uint8_t crc_extra = 104;
  static constexpr std::size_t min_length = 28;
  static constexpr std::size_t length = 28;
  std::uint32_t time_boot_ms{};
  std::int32_t lat{};
  std::int32_t lon{};
  std::int32_t alt{};
  std::int32_t relative_alt{};
  std::int16_t vx{};
  std::int16_t vy{};
  std::int16_t vz{};
  std::uint16_t hdg{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_boot_ms", m.time_boot_ms);
    f("lat", m.lat);
    f("lon", m.lon);
    f("alt", m.alt);
    f("relative_alt", m.relative_alt);
    f("vx", m.vx);
    f("vy", m.vy);
    f("vz", m.vz);
    f("hdg", m.hdg);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// SERVO_OUTPUT_RAW (common.xml).
struct ServoOutputRaw {
  static constexpr std::uint32_t msg_id = 36;
  static constexpr const char* name = "SERVO_OUTPUT_RAW";
  static constexpr std::uint8_t crc_extra = 222;
  static constexpr std::size_t min_length = 21;
  static constexpr std::size_t length = 37;
  std::uint32_t time_usec{};
  std::uint16_t servo1_raw{};
  std::uint16_t servo2_raw{};
  std::uint16_t servo3_raw{};
  std::uint16_t servo4_raw{};
  std::uint16_t servo5_raw{};
  std::uint16_t servo6_raw{};
  std::uint16_t servo7_raw{};
  std::uint16_t servo8_raw{};
  std::uint8_t port{};
  std::uint16_t servo9_raw{};
  std::uint16_t servo10_raw{};
  std::uint16_t servo11_raw{};
  std::uint16_t servo12_raw{};
  std::uint16_t servo13_raw{};
  std::uint16_t servo14_raw{};
  std::uint16_t servo15_raw{};
  std::uint16_t servo16_raw{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_usec", m.time_usec);
    f("servo1_raw", m.servo1_raw);
    f("servo2_raw", m.servo2_raw);
    f("servo3_raw", m.servo3_raw);
    f("servo4_raw", m.servo4_raw);
    f("servo5_raw", m.servo5_raw);
    f("servo6_raw", m.servo6_raw);
    f("servo7_raw", m.servo7_raw);
    f("servo8_raw", m.servo8_raw);
    f("port", m.port);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("servo9_raw", m.servo9_raw);
    f("servo10_raw", m.servo10_raw);
    f("servo11_raw", m.servo11_raw);
    f("servo12_raw", m.servo12_raw);
    f("servo13_raw", m.servo13_raw);
    f("servo14_raw", m.servo14_raw);
    f("servo15_raw", m.servo15_raw);
    f("servo16_raw", m.servo16_raw);
  }
};

// MANUAL_CONTROL (common.xml). Axes -1000..1000; for ArduSub z is 0..1000 with 500 neutral
// (ArduSub/joystick.cpp). target is the vehicle's sysid.
struct ManualControl {
  static constexpr std::uint32_t msg_id = 69;
  static constexpr const char* name = "MANUAL_CONTROL";
  static constexpr std::uint8_t crc_extra = 243;
  static constexpr std::size_t min_length = 11;
  static constexpr std::size_t length = 30;
  std::int16_t x{};
  std::int16_t y{};
  std::int16_t z{};
  std::int16_t r{};
  std::uint16_t buttons{};
  std::uint8_t target{};
  std::uint16_t buttons2{};
  std::uint8_t enabled_extensions{};
  std::int16_t s{};
  std::int16_t t{};
  std::int16_t aux1{};
  std::int16_t aux2{};
  std::int16_t aux3{};
  std::int16_t aux4{};
  std::int16_t aux5{};
  std::int16_t aux6{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("x", m.x);
    f("y", m.y);
    f("z", m.z);
    f("r", m.r);
    f("buttons", m.buttons);
    f("target", m.target);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("buttons2", m.buttons2);
    f("enabled_extensions", m.enabled_extensions);
    f("s", m.s);
    f("t", m.t);
    f("aux1", m.aux1);
    f("aux2", m.aux2);
    f("aux3", m.aux3);
    f("aux4", m.aux4);
    f("aux5", m.aux5);
    f("aux6", m.aux6);
  }
};

// RC_CHANNELS_OVERRIDE (common.xml).
struct RcChannelsOverride {
  static constexpr std::uint32_t msg_id = 70;
  static constexpr const char* name = "RC_CHANNELS_OVERRIDE";
  static constexpr std::uint8_t crc_extra = 124;
  static constexpr std::size_t min_length = 18;
  static constexpr std::size_t length = 38;
  std::uint16_t chan1_raw{};
  std::uint16_t chan2_raw{};
  std::uint16_t chan3_raw{};
  std::uint16_t chan4_raw{};
  std::uint16_t chan5_raw{};
  std::uint16_t chan6_raw{};
  std::uint16_t chan7_raw{};
  std::uint16_t chan8_raw{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::uint16_t chan9_raw{};
  std::uint16_t chan10_raw{};
  std::uint16_t chan11_raw{};
  std::uint16_t chan12_raw{};
  std::uint16_t chan13_raw{};
  std::uint16_t chan14_raw{};
  std::uint16_t chan15_raw{};
  std::uint16_t chan16_raw{};
  std::uint16_t chan17_raw{};
  std::uint16_t chan18_raw{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("chan1_raw", m.chan1_raw);
    f("chan2_raw", m.chan2_raw);
    f("chan3_raw", m.chan3_raw);
    f("chan4_raw", m.chan4_raw);
    f("chan5_raw", m.chan5_raw);
    f("chan6_raw", m.chan6_raw);
    f("chan7_raw", m.chan7_raw);
    f("chan8_raw", m.chan8_raw);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("chan9_raw", m.chan9_raw);
    f("chan10_raw", m.chan10_raw);
    f("chan11_raw", m.chan11_raw);
    f("chan12_raw", m.chan12_raw);
    f("chan13_raw", m.chan13_raw);
    f("chan14_raw", m.chan14_raw);
    f("chan15_raw", m.chan15_raw);
    f("chan16_raw", m.chan16_raw);
    f("chan17_raw", m.chan17_raw);
    f("chan18_raw", m.chan18_raw);
  }
};

// MISSION_ITEM_INT (common.xml).
struct MissionItemInt {
  static constexpr std::uint32_t msg_id = 73;
  static constexpr const char* name = "MISSION_ITEM_INT";
  static constexpr std::uint8_t crc_extra = 38;
  static constexpr std::size_t min_length = 37;
  static constexpr std::size_t length = 38;
  float param1{};
  float param2{};
  float param3{};
  float param4{};
  std::int32_t x{};
  std::int32_t y{};
  float z{};
  std::uint16_t seq{};
  std::uint16_t command{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::uint8_t frame{};
  std::uint8_t current{};
  std::uint8_t autocontinue{};
  std::uint8_t mission_type{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("param1", m.param1);
    f("param2", m.param2);
    f("param3", m.param3);
    f("param4", m.param4);
    f("x", m.x);
    f("y", m.y);
    f("z", m.z);
    f("seq", m.seq);
    f("command", m.command);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
    f("frame", m.frame);
    f("current", m.current);
    f("autocontinue", m.autocontinue);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("mission_type", m.mission_type);
  }
};

// VFR_HUD (common.xml).
struct VfrHud {
  static constexpr std::uint32_t msg_id = 74;
  static constexpr const char* name = "VFR_HUD";
  static constexpr std::uint8_t crc_extra = 20;
  static constexpr std::size_t min_length = 20;
  static constexpr std::size_t length = 20;
  float airspeed{};
  float groundspeed{};
  float alt{};
  float climb{};
  std::int16_t heading{};
  std::uint16_t throttle{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("airspeed", m.airspeed);
    f("groundspeed", m.groundspeed);
    f("alt", m.alt);
    f("climb", m.climb);
    f("heading", m.heading);
    f("throttle", m.throttle);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// COMMAND_LONG (common.xml).
struct CommandLong {
  static constexpr std::uint32_t msg_id = 76;
  static constexpr const char* name = "COMMAND_LONG";
  static constexpr std::uint8_t crc_extra = 152;
  static constexpr std::size_t min_length = 33;
  static constexpr std::size_t length = 33;
  float param1{};
  float param2{};
  float param3{};
  float param4{};
  float param5{};
  float param6{};
  float param7{};
  std::uint16_t command{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::uint8_t confirmation{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("param1", m.param1);
    f("param2", m.param2);
    f("param3", m.param3);
    f("param4", m.param4);
    f("param5", m.param5);
    f("param6", m.param6);
    f("param7", m.param7);
    f("command", m.command);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
    f("confirmation", m.confirmation);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// COMMAND_ACK (common.xml). result: MAV_RESULT (enums.hpp).
struct CommandAck {
  static constexpr std::uint32_t msg_id = 77;
  static constexpr const char* name = "COMMAND_ACK";
  static constexpr std::uint8_t crc_extra = 143;
  static constexpr std::size_t min_length = 3;
  static constexpr std::size_t length = 10;
  std::uint16_t command{};
  std::uint8_t result{};
  std::uint8_t progress{};
  std::int32_t result_param2{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("command", m.command);
    f("result", m.result);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("progress", m.progress);
    f("result_param2", m.result_param2);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
  }
};

// SET_POSITION_TARGET_LOCAL_NED (common.xml). type_mask: POSITION_TARGET_TYPEMASK (enums.hpp).
struct SetPositionTargetLocalNed {
  static constexpr std::uint32_t msg_id = 84;
  static constexpr const char* name = "SET_POSITION_TARGET_LOCAL_NED";
  static constexpr std::uint8_t crc_extra = 143;
  static constexpr std::size_t min_length = 53;
  static constexpr std::size_t length = 53;
  std::uint32_t time_boot_ms{};
  float x{};
  float y{};
  float z{};
  float vx{};
  float vy{};
  float vz{};
  float afx{};
  float afy{};
  float afz{};
  float yaw{};
  float yaw_rate{};
  std::uint16_t type_mask{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::uint8_t coordinate_frame{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_boot_ms", m.time_boot_ms);
    f("x", m.x);
    f("y", m.y);
    f("z", m.z);
    f("vx", m.vx);
    f("vy", m.vy);
    f("vz", m.vz);
    f("afx", m.afx);
    f("afy", m.afy);
    f("afz", m.afz);
    f("yaw", m.yaw);
    f("yaw_rate", m.yaw_rate);
    f("type_mask", m.type_mask);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
    f("coordinate_frame", m.coordinate_frame);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// POSITION_TARGET_LOCAL_NED (common.xml).
struct PositionTargetLocalNed {
  static constexpr std::uint32_t msg_id = 85;
  static constexpr const char* name = "POSITION_TARGET_LOCAL_NED";
  static constexpr std::uint8_t crc_extra = 140;
  static constexpr std::size_t min_length = 51;
  static constexpr std::size_t length = 51;
  std::uint32_t time_boot_ms{};
  float x{};
  float y{};
  float z{};
  float vx{};
  float vy{};
  float vz{};
  float afx{};
  float afy{};
  float afz{};
  float yaw{};
  float yaw_rate{};
  std::uint16_t type_mask{};
  std::uint8_t coordinate_frame{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_boot_ms", m.time_boot_ms);
    f("x", m.x);
    f("y", m.y);
    f("z", m.z);
    f("vx", m.vx);
    f("vy", m.vy);
    f("vz", m.vz);
    f("afx", m.afx);
    f("afy", m.afy);
    f("afz", m.afz);
    f("yaw", m.yaw);
    f("yaw_rate", m.yaw_rate);
    f("type_mask", m.type_mask);
    f("coordinate_frame", m.coordinate_frame);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// SET_POSITION_TARGET_GLOBAL_INT (common.xml). alt in m; lat_int/lon_int degE7.
struct SetPositionTargetGlobalInt {
  static constexpr std::uint32_t msg_id = 86;
  static constexpr const char* name = "SET_POSITION_TARGET_GLOBAL_INT";
  static constexpr std::uint8_t crc_extra = 5;
  static constexpr std::size_t min_length = 53;
  static constexpr std::size_t length = 53;
  std::uint32_t time_boot_ms{};
  std::int32_t lat_int{};
  std::int32_t lon_int{};
  float alt{};
  float vx{};
  float vy{};
  float vz{};
  float afx{};
  float afy{};
  float afz{};
  float yaw{};
  float yaw_rate{};
  std::uint16_t type_mask{};
  std::uint8_t target_system{};
  std::uint8_t target_component{};
  std::uint8_t coordinate_frame{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("time_boot_ms", m.time_boot_ms);
    f("lat_int", m.lat_int);
    f("lon_int", m.lon_int);
    f("alt", m.alt);
    f("vx", m.vx);
    f("vy", m.vy);
    f("vz", m.vz);
    f("afx", m.afx);
    f("afy", m.afy);
    f("afz", m.afz);
    f("yaw", m.yaw);
    f("yaw_rate", m.yaw_rate);
    f("type_mask", m.type_mask);
    f("target_system", m.target_system);
    f("target_component", m.target_component);
    f("coordinate_frame", m.coordinate_frame);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// TIMESYNC (common.xml). ArduPilot's fork has no extension fields; upstream MAVLink later
// added target_system and target_component, which this codec does not know.
struct Timesync {
  static constexpr std::uint32_t msg_id = 111;
  static constexpr const char* name = "TIMESYNC";
  static constexpr std::uint8_t crc_extra = 34;
  static constexpr std::size_t min_length = 16;
  static constexpr std::size_t length = 16;
  std::int64_t tc1{};
  std::int64_t ts1{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("tc1", m.tc1);
    f("ts1", m.ts1);
  }
  template <class M, class F>
  static constexpr void extension_fields(M&, F&&) {}
};

// STATUSTEXT (common.xml). text is NUL-padded, not necessarily NUL-terminated.
struct Statustext {
  static constexpr std::uint32_t msg_id = 253;
  static constexpr const char* name = "STATUSTEXT";
  static constexpr std::uint8_t crc_extra = 83;
  static constexpr std::size_t min_length = 51;
  static constexpr std::size_t length = 54;
  std::uint8_t severity{};
  std::array<char, 50> text{};
  std::uint16_t id{};
  std::uint8_t chunk_seq{};
  template <class M, class F>
  static constexpr void base_fields(M& m, F&& f) {
    f("severity", m.severity);
    f("text", m.text);
  }
  template <class M, class F>
  static constexpr void extension_fields(M& m, F&& f) {
    f("id", m.id);
    f("chunk_seq", m.chunk_seq);
  }
};

// Every message above, for tables and tests.
template <class... Ms>
struct MessageList {};
using AllMessages =
    MessageList<Heartbeat, SysStatus, SystemTime, SetMode, ParamRequestRead, ParamValue, ParamSet,
                GpsRawInt, Attitude, LocalPositionNed, GlobalPositionInt, ServoOutputRaw,
                ManualControl, RcChannelsOverride, MissionItemInt, VfrHud, CommandLong, CommandAck,
                SetPositionTargetLocalNed, PositionTargetLocalNed, SetPositionTargetGlobalInt,
                Timesync, Statustext>;

// Calls f(M{}) once per message type.
template <class F, class... Ms>
void for_each_message_type(MessageList<Ms...>, F&& f) {
  (f(Ms{}), ...);
}
template <class F>
void for_each_message_type(F&& f) {
  for_each_message_type(AllMessages{}, f);
}

// Compile-time check of each definition against its table values.
template <class M>
constexpr bool definition_consistent() {
  return field_bytes<M>(false) == M::min_length && field_bytes<M>(true) == M::length &&
         M::length <= 255 && compute_crc_extra<M>() == M::crc_extra &&
         base_fields_in_wire_order<M>();
}
template <class... Ms>
constexpr bool all_consistent(MessageList<Ms...>) {
  return (definition_consistent<Ms>() && ...);
}
static_assert(all_consistent(AllMessages{}),
              "a message's lengths, CRC_EXTRA or field order do not match its field list");

}  // namespace kelp_sitl::mavlink
