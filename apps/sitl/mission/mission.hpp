// kelp-mission's logic: a MAVLink ground station for two ArduPilot vehicles on TCP links, the
// AUV (ArduSub, BlueROV2 Heavy) and the ASV (ArduRover boat, BlueBoat) joined by the tether.
//
// Mission: connect, wait for both HEARTBEATs and for the AUV's position estimate
// (LOCAL_POSITION_NED), arm both, AUV to ALT_HOLD and boat to GUIDED; the AUV dives to --depth
// with the throttle stick below neutral and holds it for --hold s;
// then it flies a square of --survey-side m at that depth in GUIDED; all along the boat is
// sent the AUV's latitude/longitude at 1 Hz, so it stays above it. Finally both are put in a
// safe state (AUV MANUAL and disarmed, boat HOLD and disarmed).
//
// One thread, poll() on both sockets. Every wait is bounded; a time-out, a refusal, a lost link,
// an unexpected disarm or a mode change kelp-mission did not command (a failsafe, a pilot) ends
// the mission with a message naming the vehicle, the command and the MAV_RESULT, an attempt to
// leave both vehicles safe, and exit code 1. Failsafes (HEARTBEAT system_status CRITICAL or
// EMERGENCY once the vehicle was armed, or with a STATUSTEXT naming a failsafe) are reported as
// they happen and counted in the summary printed at the end; the same states while disarmed
// before the first arming are the autopilot's start-up (ArduSub's first seconds) and are
// reported apart.
//
// Two clocks. A SITL runs at --speedup times real time (or slower, when the lockstep with the
// physics cannot keep up), and its failsafes count in its own time: ArduRover's GCS failsafe
// fires after FS_GCS_TIMEOUT s of *its* clock without a GCS HEARTBEAT. So every periodic
// message (HEARTBEAT, MANUAL_CONTROL, the targets) goes out when either the vehicle's clock
// (time_boot_ms of SYSTEM_TIME, ATTITUDE, LOCAL_POSITION_NED, GLOBAL_POSITION_INT) or the wall
// clock has advanced by its period, and the dive and survey time-outs count in the sub's clock.
#pragma once

#include <poll.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "csv_log.hpp"
#include "mavlink/mavlink.hpp"
#include "tcp_link.hpp"

namespace kelp_sitl::mission {

struct Options {
  std::string sub = "tcp:127.0.0.1:5760";    // ArduSub SERIAL0; "none": no AUV
  std::string rover = "tcp:127.0.0.1:5770";  // ArduRover SERIAL0 (-I1); "none": no boat
  // m below the sea surface, as ArduSub reports it (Vehicle::depth(): its altitude relative to
  // its home at the surface, negated; not LOCAL_POSITION_NED z, which counts from wherever its
  // EKF started)
  double depth = 5.0;
  double depth_tolerance = 0.05;  // m: the dive ends this far short of --depth
  double hold = 60.0;             // s in ALT_HOLD at depth
  double survey_side = 10.0;      // m, side of the square (0: no survey)
  double survey_radius = 1.0;     // m: a corner counts as reached within this horizontal distance
  std::string log_dir = "kelp-mission-log";
  double connect_timeout = 60.0;    // s, per vehicle, retrying the TCP connect
  double heartbeat_timeout = 30.0;  // s for the first HEARTBEAT after connecting
  double arm_timeout = 60.0;        // s of arming retries (the EKF needs 10-30 s after boot)
  double position_timeout = 120.0;  // s for the sub's first LOCAL_POSITION_NED (before arming)
  double mode_timeout = 30.0;       // s of mode-change retries (GUIDED needs a position)
  double dive_timeout = 120.0;      // s of the sub's clock to reach the depth
  double leg_timeout = 120.0;       // s of the sub's clock per side of the square
  double retry_interval = 3.0;      // s between repeats of a refused or unanswered command
  double link_timeout = 5.0;        // wall s without HEARTBEAT during the mission: link lost
  int dive_throttle = 300;  // MANUAL_CONTROL z while diving (0..1000, 500 neutral); 1000 minus
                            // it while rising to --depth from below
};

struct MissionError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One vehicle: its link and the latest state it reported.
struct Vehicle {
  std::string name;  // "sub" or "boat": log and message prefix
  Endpoint endpoint;
  TcpLink link;
  mavlink::Sender gcs{255, mavlink::kCompMissionPlanner};  // the GCS identity on this link
  std::uint8_t sysid = 1;                                  // learnt from the first HEARTBEAT
  bool have_heartbeat = false;
  Clock::time_point last_heartbeat{};
  mavlink::Heartbeat heartbeat;
  std::optional<mavlink::LocalPositionNed> local;
  std::optional<mavlink::GlobalPositionInt> global;
  std::optional<mavlink::Attitude> attitude;
  std::optional<mavlink::SysStatus> sys_status;
  std::optional<float> sim_batt_voltage;  // SITL's SIM_BATT_VOLTAGE, once read
  // The battery as the autopilot reports it while armed: voltage range [V], peak current [A].
  double battery_min_v = NAN, battery_max_v = NAN, battery_max_a = NAN;
  std::string battery_note;                // the start-up check's verdict, for the summary
  std::optional<mavlink::CommandAck> ack;  // last COMMAND_ACK not yet consumed
  std::string last_text;                   // last STATUSTEXT
  bool expect_armed = false;
  Clock::time_point armed_since{};
  // The vehicle's clock: the latest time_boot_ms it reported (ms since its boot).
  std::optional<std::uint32_t> clock_ms;
  // Mode watch: the mode kelp-mission last set (none before its first command); while a
  // command is under way (`changing_mode`) the HEARTBEAT may still show the old one.
  std::optional<std::uint32_t> commanded_mode;
  bool changing_mode = false;
  std::optional<std::uint32_t> uncommanded_mode;  // set when seen, cleared when reported
  std::vector<std::string> events;                // mode changes not commanded, failsafes
  int uncommanded_mode_changes = 0;
  int failsafes = 0;
  // CRITICAL / EMERGENCY states reported while disarmed before kelp-mission first armed the
  // vehicle and with no failsafe STATUSTEXT: start-up states, reported apart from failsafes.
  int boot_states = 0;
  std::vector<std::string> boot_events;
  bool was_armed = false;  // armed by kelp-mission at least once

  bool armed() const { return (heartbeat.base_mode & mavlink::kModeFlagSafetyArmed) != 0; }
  // Depth below the sea surface as the autopilot reports it, m (down positive): minus
  // GLOBAL_POSITION_INT's relative_alt. ArduSub puts its home at the water's surface, the
  // vehicle's position raised by its depth sensor's depth (ArduSub/commands.cpp,
  // set_home_to_current_location), and reports the altitude relative to home (Sub::get_alt_rel;
  // before home is set, the depth sensor's), so this is the depth from the surface wherever the
  // vehicle was when its EKF started. LOCAL_POSITION_NED z counts from that start (the EKF
  // origin), which is under water after a submerged start.
  std::optional<double> depth() const {
    if (!global) return std::nullopt;
    return -global->relative_alt / 1000.0;
  }
  bool is_sub() const { return heartbeat.type == mavlink::kTypeSubmarine; }
  // The vehicle's clock in s, or "?" while unknown (for messages).
  std::string clock_text() const {
    if (!clock_ms) return "?";
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << *clock_ms / 1000.0;
    return s.str();
  }
};

// A periodic message: due when the vehicle's clock or the wall clock has advanced by the period
// since it was last sent. The vehicle's clock keeps the rate right in simulated time at any
// --speedup; the wall clock keeps it going before the vehicle has reported its time and when
// its clock runs slower than real time. A clock that went back (a reboot) counts as due.
struct Pace {
  Clock::time_point wall{};
  std::optional<std::uint32_t> clock_ms;

  bool due(const Vehicle& v, double period_s, Clock::time_point now) {
    const auto period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s));
    const auto period_ms = static_cast<std::uint32_t>(period_s * 1000.0);
    const bool wall_due = now - wall >= period;
    const bool clock_due = v.clock_ms && (!clock_ms || *v.clock_ms < *clock_ms ||
                                          *v.clock_ms - *clock_ms >= period_ms);
    if (!wall_due && !clock_due) return false;
    wall = now;
    clock_ms = v.clock_ms;
    return true;
  }
};

// ArduPilot's mode names for the messages (ArduSub/mode.h and Rover/mode.h, Mode::Number).
inline std::string mode_name(bool sub, std::uint32_t mode) {
  const char* n = nullptr;
  if (sub) {
    switch (mode) {
      case 0:
        n = "STABILIZE";
        break;
      case 1:
        n = "ACRO";
        break;
      case 2:
        n = "ALT_HOLD";
        break;
      case 3:
        n = "AUTO";
        break;
      case 4:
        n = "GUIDED";
        break;
      case 7:
        n = "CIRCLE";
        break;
      case 9:
        n = "SURFACE";
        break;
      case 16:
        n = "POSHOLD";
        break;
      case 19:
        n = "MANUAL";
        break;
      case 20:
        n = "MOTOR_DETECT";
        break;
      case 21:
        n = "SURFTRAK";
        break;
      default:
        break;
    }
  } else {
    switch (mode) {
      case 0:
        n = "MANUAL";
        break;
      case 1:
        n = "ACRO";
        break;
      case 3:
        n = "STEERING";
        break;
      case 4:
        n = "HOLD";
        break;
      case 5:
        n = "LOITER";
        break;
      case 6:
        n = "FOLLOW";
        break;
      case 7:
        n = "SIMPLE";
        break;
      case 8:
        n = "DOCK";
        break;
      case 9:
        n = "CIRCLE";
        break;
      case 10:
        n = "AUTO";
        break;
      case 11:
        n = "RTL";
        break;
      case 12:
        n = "SMART_RTL";
        break;
      case 15:
        n = "GUIDED";
        break;
      case 16:
        n = "INITIALISING";
        break;
      default:
        break;
    }
  }
  return (n != nullptr ? std::string(n) : std::string("mode")) + " (" + std::to_string(mode) + ")";
}

class Mission {
 public:
  Mission(Options options, std::ostream& out, std::ostream& err)
      : opt_(std::move(options)), out_(out), err_(err), start_(Clock::now()) {
    if (opt_.sub != "none") {
      sub_ = std::make_unique<Vehicle>();
      sub_->name = "sub";
      sub_->endpoint = parse_endpoint(opt_.sub);
    }
    if (opt_.rover != "none") {
      boat_ = std::make_unique<Vehicle>();
      boat_->name = "boat";
      boat_->endpoint = parse_endpoint(opt_.rover);
    }
    if (!sub_ && !boat_) throw std::invalid_argument("--sub and --rover are both 'none'");
  }

  // Flies the mission; returns the exit code (0 done, 1 failed).
  int run() {
    try {
      log_ = std::make_unique<CsvLog>(opt_.log_dir);
      fly();
      finish(true);
      phase("mission complete");
      print_link_stats();
      return 0;
    } catch (const std::exception& e) {
      err_ << "kelp-mission: FAILED: " << e.what() << std::endl;
      try {
        finish(false);
      } catch (const std::exception& e2) {
        err_ << "kelp-mission: could not leave the vehicles safe: " << e2.what() << std::endl;
      }
      print_link_stats();
      return 1;
    }
  }

 private:
  std::vector<Vehicle*> vehicles() {
    std::vector<Vehicle*> v;
    if (sub_) v.push_back(sub_.get());
    if (boat_) v.push_back(boat_.get());
    return v;
  }

  double now_s() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  void phase(const std::string& what) {
    out_ << "[" << std::fixed << std::setprecision(1) << std::setw(7) << now_s() << " s] " << what
         << std::endl;
    out_.unsetf(std::ios::floatfield);
  }

  static Clock::duration seconds(double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }

  // ---- the mission ---------------------------------------------------------------------------
  void fly() {
    for (Vehicle* v : vehicles()) {
      phase(v->name + ": connecting to " + v->endpoint.host + ":" +
            std::to_string(v->endpoint.port));
      std::string error;
      if (!v->link.connect(v->endpoint, Clock::now() + seconds(opt_.connect_timeout), error))
        throw MissionError(v->name + ": cannot connect to " + v->endpoint.host + ":" +
                           std::to_string(v->endpoint.port) + " within " +
                           fmt(opt_.connect_timeout) + " s (" + error + ")");
    }
    for (Vehicle* v : vehicles()) {
      phase(v->name + ": waiting for HEARTBEAT");
      wait_for([&] { return v->have_heartbeat; }, opt_.heartbeat_timeout,
               v->name + ": no HEARTBEAT within " + fmt(opt_.heartbeat_timeout) +
                   " s of connecting (is it an ArduPilot SITL, and running?)");
      phase(v->name + ": HEARTBEAT from sysid " + std::to_string(v->sysid) + ", MAV_TYPE " +
            std::to_string(v->heartbeat.type) + ", mode " +
            std::to_string(v->heartbeat.custom_mode) + (v->armed() ? ", armed" : ", disarmed"));
      request_param(*v, "SIM_BATT_VOLTAGE");  // answered by a SITL only: check_battery()
    }
    if (sub_) {
      // ArduSub sends LOCAL_POSITION_NED and GLOBAL_POSITION_INT only once its EKF has a
      // position (after GPS lock, tens of seconds after boot; seen with ArduSub SITL). Without
      // them the dive could not be stopped at the depth nor the survey flown.
      phase("sub: waiting for a position estimate (LOCAL_POSITION_NED, GLOBAL_POSITION_INT)");
      wait_for([&] { return sub_->local && sub_->global; }, opt_.position_timeout,
               "sub: no LOCAL_POSITION_NED and GLOBAL_POSITION_INT within " +
                   fmt(opt_.position_timeout) + " s (no position estimate: GPS? EKF?)");
      phase("sub: position (" + fmt(sub_->local->x) + ", " + fmt(sub_->local->y) + ", " +
            fmt(sub_->local->z) + ") m NED from its EKF origin; depth " + fmt(*sub_->depth()) +
            " m");
    }
    for (Vehicle* v : vehicles()) check_battery(*v);
    for (Vehicle* v : vehicles()) {
      phase(v->name + ": arming");
      arm(*v, true);
    }
    if (sub_) set_mode(*sub_, mavlink::sub_mode::kAltHold, "ALT_HOLD");
    if (boat_) {
      set_mode(*boat_, mavlink::rover_mode::kGuided, "GUIDED");
      following_ = sub_ != nullptr;
      if (following_) phase("boat: following the sub (SET_POSITION_TARGET_GLOBAL_INT at 1 Hz)");
    }
    if (!sub_) return;

    // Down with the stick below neutral, or up with it as far above when the sub is deeper than
    // the target (a submerged start), until it is within the tolerance of the target.
    const bool rise = *sub_->depth() > opt_.depth + opt_.depth_tolerance;
    const int throttle = rise ? 1000 - opt_.dive_throttle : opt_.dive_throttle;
    phase("sub: " + std::string(rise ? "rising" : "diving") + " to " + fmt(opt_.depth) +
          " m from " + fmt(*sub_->depth()) + " m (ALT_HOLD, throttle " + std::to_string(throttle) +
          ")");
    manual_z_ = static_cast<std::int16_t>(throttle);
    const auto arrived = [&] {
      const double d = *sub_->depth();
      return rise ? d <= opt_.depth + opt_.depth_tolerance : d >= opt_.depth - opt_.depth_tolerance;
    };
    wait_for_clock(
        *sub_, arrived, opt_.dive_timeout,
        [&] {
          return "sub: did not reach " + fmt(opt_.depth) + " m within " + fmt(opt_.dive_timeout) +
                 " s (depth " + fmt(*sub_->depth()) + " m)";
        },
        [&] { return "depth " + fmt(*sub_->depth()) + " m"; });
    manual_z_ = kNeutralZ;
    phase("sub: at " + fmt(*sub_->depth()) + " m; holding depth for " + fmt(opt_.hold) + " s");
    hold_depth(*sub_, opt_.hold);

    if (opt_.survey_side > 0.0) survey();
  }

  // A square at the dive depth: north, east, south, west, from where the sub is.
  void survey() {
    set_mode(*sub_, mavlink::sub_mode::kGuided, "GUIDED");
    const double x0 = sub_->local->x, y0 = sub_->local->y, s = opt_.survey_side;
    // LOCAL_POSITION_NED counts from the EKF origin, which may lie under water: the target
    // depth in that frame is --depth less the origin's depth (depth - local z, now).
    const double local_z = opt_.depth - (*sub_->depth() - sub_->local->z);
    const std::array<std::array<double, 2>, 4> corners{
        {{x0 + s, y0}, {x0 + s, y0 + s}, {x0, y0 + s}, {x0, y0}}};
    double from_x = x0, from_y = y0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
      const double tx = corners[i][0], ty = corners[i][1];
      // Yaw along the leg (NED: 0 north, pi/2 east). type_mask 2552 (0x09F8) ignores velocity,
      // acceleration and yaw rate but not yaw, so the target yaw must be meaningful.
      const float yaw = static_cast<float>(std::atan2(ty - from_y, tx - from_x));
      phase("sub: survey leg " + std::to_string(i + 1) + "/4 to (" + fmt(tx) + ", " + fmt(ty) +
            ") m NED, yaw " + fmt(yaw * 180.0 / kPi) + " deg");
      mavlink::SetPositionTargetLocalNed t;
      t.x = static_cast<float>(tx);
      t.y = static_cast<float>(ty);
      t.z = static_cast<float>(local_z);
      t.yaw = yaw;
      t.type_mask = mavlink::kTypeMaskPositionYaw;
      t.coordinate_frame = mavlink::kFrameLocalNed;
      t.target_system = sub_->sysid;
      t.target_component = mavlink::kCompAutopilot1;
      local_target_ = t;
      local_target_pace_ = Pace{};  // the new corner goes out at once
      auto distance = [&] { return std::hypot(sub_->local->x - tx, sub_->local->y - ty); };
      wait_for_clock(
          *sub_, [&] { return distance() <= opt_.survey_radius; }, opt_.leg_timeout,
          [&] {
            return "sub: corner " + std::to_string(i + 1) + " not reached within " +
                   fmt(opt_.leg_timeout) + " s (" + fmt(distance()) + " m away)";
          },
          [&] { return "distance " + fmt(distance()) + " m"; });
      from_x = tx;
      from_y = ty;
    }
    local_target_.reset();
    phase("sub: survey done");
  }

  // Safe state. After a failure: best effort, short waits, no exception for a refusal.
  void finish(bool strict) {
    following_ = false;
    local_target_.reset();
    manual_z_ = kNeutralZ;
    // From here on a lost link or a disarm is no longer an error: it must not stop the other
    // vehicle from being made safe. Each command still has its time-out.
    checks_ = false;
    for (Vehicle* v : vehicles()) v->expect_armed = false;
    const double timeout = strict ? opt_.mode_timeout : std::min(opt_.mode_timeout, 5.0);
    auto attempt = [&](Vehicle& v, auto&& action) {
      if (!v.link.is_open() || !v.have_heartbeat) return;
      if (Clock::now() - v.last_heartbeat > seconds(opt_.link_timeout)) {
        err_ << "kelp-mission: " << v.name << ": no link, cannot make it safe" << std::endl;
        return;
      }
      try {
        action();
      } catch (const MissionError& e) {
        if (strict) throw;
        err_ << "kelp-mission: " << e.what() << std::endl;
      }
    };
    bool any = false;
    for (Vehicle* v : vehicles()) any = any || (v->link.is_open() && v->have_heartbeat);
    if (!any) return;
    std::string what = sub_ ? "sub MANUAL + disarm" : "";
    if (boat_) what += std::string(sub_ ? ", " : "") + "boat HOLD + disarm";
    phase((strict ? "finishing: " : "leaving the vehicles safe: ") + what);
    if (sub_) {
      attempt(*sub_, [&] { set_mode(*sub_, mavlink::sub_mode::kManual, "MANUAL", timeout); });
      attempt(*sub_, [&] { arm(*sub_, false, timeout); });
    }
    if (boat_) {
      attempt(*boat_, [&] { set_mode(*boat_, mavlink::rover_mode::kHold, "HOLD", timeout); });
      attempt(*boat_, [&] { arm(*boat_, false, timeout); });
    }
  }

  // Whose battery the autopilot shows. kelp-sitl sends kelp's battery in its JSON replies
  // ("battery": voltage, current), which ArduPilot's SIM_JSON reads since master ab03dc37
  // (2025-07-28); older builds drop the key without a word and show their own SITL battery:
  // SIM_BATT_VOLTAGE, less a drop with the thrusters' PWM (libraries/AP_HAL_SITL/
  // SITL_State_common.cpp, update_voltage_current), i.e. exactly SIM_BATT_VOLTAGE while
  // disarmed, when every PWM is neutral. kelp's battery at rest reads its open-circuit voltage,
  // which equals that only by chance. So, disarmed: SYS_STATUS's voltage within 0.05 V of
  // SIM_BATT_VOLTAGE is ArduPilot's own battery, and the user is told. Not a SITL (no
  // SIM_BATT_VOLTAGE) or no SYS_STATUS within 3 s: nothing to check.
  void check_battery(Vehicle& v) {
    const auto wall_end = Clock::now() + std::chrono::seconds(3);
    auto next_request = Clock::now() + std::chrono::seconds(1);
    while ((!v.sys_status || !v.sim_batt_voltage) && Clock::now() < wall_end) {
      if (!v.sim_batt_voltage && Clock::now() >= next_request) {
        request_param(v, "SIM_BATT_VOLTAGE");
        next_request += std::chrono::seconds(1);
      }
      spin(std::min(wall_end, next_request));
    }
    if (!v.sys_status || !v.sim_batt_voltage || v.sys_status->voltage_battery == 0xFFFF ||
        v.armed())
      return;
    const double volts = v.sys_status->voltage_battery / 1000.0;
    const double sim = *v.sim_batt_voltage;
    const std::string reports = "the battery it reports (" + fmt(volts) + " V) is ";
    if (std::fabs(volts - sim) <= 0.05)
      v.battery_note = reports + "ArduPilot's own SITL battery (SIM_BATT_VOLTAGE " + fmt(sim) +
                       " V), not kelp's: this ArduPilot ignores kelp-sitl's JSON \"battery\" "
                       "(read since ArduPilot master ab03dc37, 2025-07-28), so its battery "
                       "voltage, current and failsafes are not kelp's";
    else
      v.battery_note = reports +
                       "kelp's, through the JSON \"battery\" (SITL's own SIM_BATT_VOLTAGE " +
                       fmt(sim) + " V is unused)";
    phase(v.name + ": " + v.battery_note);
  }

  void request_param(Vehicle& v, const std::string& id) {
    mavlink::ParamRequestRead r;
    r.target_system = v.sysid;
    r.target_component = mavlink::kCompAutopilot1;
    r.param_id = mavlink::to_chars<16>(id);
    send(v, r);
  }

  // ---- commands ------------------------------------------------------------------------------
  void arm(Vehicle& v, bool on, double timeout = -1) {
    if (timeout < 0) timeout = opt_.arm_timeout;
    v.expect_armed = false;  // no "disarmed unexpectedly" while this changes
    command(v, mavlink::kCmdComponentArmDisarm, {on ? 1.0f : 0.0f}, on ? "arm" : "disarm", timeout);
    wait_for([&] { return v.armed() == on; }, std::max(timeout, 3.0),
             v.name + ": " + (on ? "arm" : "disarm") +
                 " was accepted but the HEARTBEAT does not show it");
    v.expect_armed = on;
    v.was_armed = v.was_armed || on;
    v.armed_since = Clock::now();
  }

  void set_mode(Vehicle& v, std::uint32_t mode, const std::string& name, double timeout = -1) {
    if (timeout < 0) timeout = opt_.mode_timeout;
    // From here until the HEARTBEAT shows the new mode, neither the old nor the new one is a
    // change kelp-mission did not command.
    v.commanded_mode = mode;
    v.changing_mode = true;
    // param1: base_mode with MAV_MODE_FLAG_CUSTOM_MODE_ENABLED; param2: ArduPilot's mode number.
    command(v, mavlink::kCmdDoSetMode,
            {static_cast<float>(mavlink::kModeFlagCustomModeEnabled), static_cast<float>(mode)},
            "mode " + name + " (" + std::to_string(mode) + ")", timeout);
    wait_for([&] { return v.heartbeat.custom_mode == mode; }, std::max(timeout, 3.0),
             v.name + ": mode " + name + " was accepted but the HEARTBEAT does not show it");
    v.changing_mode = false;
    v.uncommanded_mode.reset();
  }

  // COMMAND_LONG repeated every retry_interval until COMMAND_ACK ACCEPTED or `timeout`.
  void command(Vehicle& v, std::uint16_t cmd, std::array<float, 7> params, const std::string& what,
               double timeout) {
    const auto deadline = Clock::now() + seconds(timeout);
    auto next_send = Clock::now();
    std::optional<std::uint8_t> last_result;
    int attempts = 0;
    v.last_text.clear();
    for (;;) {
      const auto now = Clock::now();
      if (now >= next_send) {
        mavlink::CommandLong c;
        c.param1 = params[0];
        c.param2 = params[1];
        c.param3 = params[2];
        c.param4 = params[3];
        c.param5 = params[4];
        c.param6 = params[5];
        c.param7 = params[6];
        c.command = cmd;
        c.target_system = v.sysid;
        c.target_component = mavlink::kCompAutopilot1;
        c.confirmation = static_cast<std::uint8_t>(std::min(attempts, 255));
        v.ack.reset();
        send(v, c);
        ++attempts;
        next_send = now + seconds(opt_.retry_interval);
      }
      if (v.ack && v.ack->command == cmd) {
        const std::uint8_t r = v.ack->result;
        v.ack.reset();
        if (r == static_cast<std::uint8_t>(mavlink::Result::Accepted)) {
          phase(v.name + ": " + what + ": ACCEPTED");
          return;
        }
        if (r != static_cast<std::uint8_t>(mavlink::Result::InProgress)) {
          last_result = r;
          phase(v.name + ": " + what + ": " + mavlink::command_name(cmd) +
                " refused: " + mavlink::result_name(r) +
                (v.last_text.empty() ? "" : " (" + v.last_text + ")") + "; retrying");
        }
      }
      if (now >= deadline)
        throw MissionError(
            v.name + ": " + what + ": " + mavlink::command_name(cmd) + " not accepted within " +
            fmt(timeout) + " s after " + std::to_string(attempts) + " attempts; last result: " +
            (last_result ? mavlink::result_name(*last_result) : std::string("no COMMAND_ACK")) +
            (v.last_text.empty() ? "" : "; last STATUSTEXT: \"" + v.last_text + "\""));
      spin(std::min(next_send, deadline));
    }
  }

  template <class M>
  void send(Vehicle& v, const M& msg) {
    if (!v.link.send(v.gcs.pack(msg)))
      throw MissionError(v.name + ": cannot send (" + std::string(M::name) + "): link broken");
  }

  // ---- the loop ------------------------------------------------------------------------------
  // Runs the loop until pred() or `timeout` s, then throws MissionError(message) (a string, or a
  // callable that makes it then). status() is printed every 5 s while waiting.
  template <class Pred, class Message>
  void wait_for(Pred pred, double timeout, const Message& message) {
    wait_for(pred, timeout, message, [] { return std::string(); });
  }
  template <class Pred, class Message, class Status>
  void wait_for(Pred pred, double timeout, const Message& message, Status status) {
    const auto deadline = Clock::now() + seconds(timeout);
    auto next_status = Clock::now() + std::chrono::seconds(5);
    while (!pred()) {
      const auto now = Clock::now();
      if (now >= deadline) {
        if constexpr (std::is_invocable_v<Message>)
          throw MissionError(message());
        else
          throw MissionError(message);
      }
      if (now >= next_status) {
        const std::string s = status();
        if (!s.empty()) phase("  " + s);
        next_status = now + std::chrono::seconds(5);
      }
      spin(std::min(deadline, next_status));
    }
  }

  // As wait_for, but the time-out counts in the vehicle's own clock (time_boot_ms), so that it
  // means the same simulated time at any SITL --speedup. While the vehicle has not reported its
  // time yet the wall clock counts instead; a wall-clock backstop of 10 x timeout + 60 s ends
  // the wait if the vehicle's clock stops (a lost link is caught sooner by the HEARTBEAT check).
  template <class Pred, class Message, class Status>
  void wait_for_clock(const Vehicle& v, Pred pred, double timeout, const Message& message,
                      Status status) {
    const auto wall_start = Clock::now();
    const auto wall_end = wall_start + seconds(10.0 * timeout + 60.0);
    const std::optional<std::uint32_t> clock0 = v.clock_ms;
    auto next_status = wall_start + std::chrono::seconds(5);
    const auto expired = [&] {
      const auto now = Clock::now();
      if (now >= wall_end) return true;
      if (clock0 && v.clock_ms && *v.clock_ms >= *clock0)
        return (*v.clock_ms - *clock0) / 1000.0 >= timeout;
      return now - wall_start >= seconds(timeout);
    };
    while (!pred()) {
      if (expired()) {
        if constexpr (std::is_invocable_v<Message>)
          throw MissionError(message());
        else
          throw MissionError(message);
      }
      const auto now = Clock::now();
      if (now >= next_status) {
        const std::string s = status();
        if (!s.empty()) phase("  " + s);
        next_status = now + std::chrono::seconds(5);
      }
      spin(std::min(wall_end, next_status));
    }
  }

  // Holds depth for `duration` s of the vehicle's own clock (time_boot_ms of its
  // GLOBAL_POSITION_INT), so that the hold lasts the same simulated time at any SITL --speedup;
  // reports the depth range seen. Gives up after 10 × duration + 60 s of wall time (a SITL in
  // lockstep with a loaded machine may run well below real time; a lost link is caught sooner).
  void hold_depth(Vehicle& v, double duration) {
    const auto wall_end = Clock::now() + seconds(10.0 * duration + 60.0);
    auto next_status = Clock::now() + std::chrono::seconds(5);
    const std::uint32_t t0 = v.global->time_boot_ms;
    double lo = *v.depth(), hi = lo;
    while (Clock::now() < wall_end) {
      lo = std::min(lo, *v.depth());
      hi = std::max(hi, *v.depth());
      if (v.global->time_boot_ms - t0 >= static_cast<std::uint32_t>(duration * 1000.0)) {
        phase(v.name + ": held depth between " + fmt(lo) + " and " + fmt(hi) + " m for " +
              fmt(duration) + " s of its clock");
        return;
      }
      if (Clock::now() >= next_status) {
        phase("  depth " + fmt(*v.depth()) + " m");
        next_status += std::chrono::seconds(5);
      }
      spin(std::min(wall_end, next_status));
    }
    throw std::runtime_error(v.name + ": its clock did not advance " + fmt(duration) + " s in " +
                             fmt(10.0 * duration + 60.0) + " s of wall time");
  }

  // One round: periodic sends, poll() until input or `until` (at most 20 ms), read, dispatch,
  // then the link and arming checks.
  void spin(Clock::time_point until) {
    periodic();
    std::vector<pollfd> fds;
    std::vector<Vehicle*> owners;
    for (Vehicle* v : vehicles())
      if (v->link.is_open()) {
        fds.push_back(pollfd{v->link.fd(), POLLIN, 0});
        owners.push_back(v);
      }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count();
    const int timeout_ms = static_cast<int>(std::max<long long>(0, std::min<long long>(left, 20)));
    const int n = ::poll(fds.data(), fds.size(), timeout_ms);
    if (n < 0 && errno != EINTR) throw MissionError(std::string("poll: ") + std::strerror(errno));
    for (std::size_t i = 0; n > 0 && i < fds.size(); ++i) {
      if (fds[i].revents == 0) continue;
      Vehicle& v = *owners[i];
      if (!v.link.receive([&](const mavlink::Frame& f) { handle(v, f); })) {
        v.link.close();
        if (checks_) throw MissionError(v.name + ": the autopilot closed the connection");
        err_ << "kelp-mission: " << v.name << ": the autopilot closed the connection" << std::endl;
      }
    }
    if (!checks_) return;
    const auto now = Clock::now();
    for (Vehicle* v : vehicles()) {
      if (v->have_heartbeat && now - v->last_heartbeat > seconds(opt_.link_timeout))
        throw MissionError(v->name + ": no HEARTBEAT for " + fmt(opt_.link_timeout) +
                           " s: link lost");
      if (v->uncommanded_mode) {
        const std::string what = v->events.back();
        v->uncommanded_mode.reset();
        throw MissionError(what);
      }
      if (v->expect_armed && !v->armed() && now - v->armed_since > std::chrono::seconds(2))
        throw MissionError(
            v->name + " disarmed unexpectedly" +
            (v->last_text.empty() ? "" : " (last STATUSTEXT: \"" + v->last_text + "\")"));
    }
  }

  // HEARTBEAT 1 Hz to each vehicle (its GCS failsafe); MANUAL_CONTROL 20 Hz to the sub
  // (ArduSub's pilot-input failsafe); the boat's follow target 1 Hz; the sub's survey target
  // 2 Hz. Each in the receiving vehicle's clock and at least as often in wall time (Pace).
  void periodic() {
    const auto now = Clock::now();
    for (Vehicle* v : vehicles()) {
      if (!v->link.is_open()) continue;
      if (heartbeat_pace_[v == sub_.get() ? 0 : 1].due(*v, 1.0, now)) {
        mavlink::Heartbeat hb;
        hb.type = mavlink::kTypeGcs;
        hb.autopilot = mavlink::kAutopilotInvalid;
        send(*v, hb);
      }
    }
    if (sub_ && sub_->link.is_open() && manual_pace_.due(*sub_, 0.05, now)) {
      mavlink::ManualControl mc;
      mc.z = manual_z_;
      mc.target = sub_->sysid;
      send(*sub_, mc);
    }
    if (following_ && boat_ && sub_ && sub_->global && follow_pace_.due(*boat_, 1.0, now)) {
      mavlink::SetPositionTargetGlobalInt t;
      t.lat_int = sub_->global->lat;
      t.lon_int = sub_->global->lon;
      t.type_mask = mavlink::kTypeMaskPosition;
      t.coordinate_frame = mavlink::kFrameGlobalRelativeAltInt;
      t.target_system = boat_->sysid;
      t.target_component = mavlink::kCompAutopilot1;
      send(*boat_, t);
    }
    if (local_target_ && sub_ && local_target_pace_.due(*sub_, 0.5, now))
      send(*sub_, *local_target_);
  }

  void handle(Vehicle& v, const mavlink::Frame& f) {
    const double t = now_s();
    if (auto hb = mavlink::decode<mavlink::Heartbeat>(f)) {
      // Only the autopilot's own HEARTBEAT (a GCS or a camera may share the link).
      if (hb->autopilot == mavlink::kAutopilotInvalid) return;
      if (v.have_heartbeat && f.sysid != v.sysid) return;
      const bool first = !v.have_heartbeat;
      const mavlink::Heartbeat before = v.heartbeat;
      v.sysid = f.sysid;
      v.have_heartbeat = true;
      v.last_heartbeat = Clock::now();
      v.heartbeat = *hb;
      watch(v, first, before);
      return;
    }
    if (!v.have_heartbeat || f.sysid != v.sysid) return;
    if (auto m = mavlink::decode<mavlink::LocalPositionNed>(f)) {
      v.local = *m;
      v.clock_ms = m->time_boot_ms;
      log_->write(t, v.name, *m);
    } else if (auto g = mavlink::decode<mavlink::GlobalPositionInt>(f)) {
      v.global = *g;
      v.clock_ms = g->time_boot_ms;
      log_->write(t, v.name, *g);
    } else if (auto a = mavlink::decode<mavlink::Attitude>(f)) {
      v.attitude = *a;
      v.clock_ms = a->time_boot_ms;
      log_->write(t, v.name, *a);
    } else if (auto st = mavlink::decode<mavlink::SystemTime>(f)) {
      v.clock_ms = st->time_boot_ms;
    } else if (auto ss = mavlink::decode<mavlink::SysStatus>(f)) {
      v.sys_status = *ss;
      log_->write(t, v.name, *ss);
      if (v.armed() && ss->voltage_battery != 0xFFFF) {
        const double volts = ss->voltage_battery / 1000.0, amps = ss->current_battery / 100.0;
        // fmin/fmax take the other operand when one is NaN (nothing seen yet).
        v.battery_min_v = std::fmin(v.battery_min_v, volts);
        v.battery_max_v = std::fmax(v.battery_max_v, volts);
        if (ss->current_battery != -1) v.battery_max_a = std::fmax(v.battery_max_a, amps);
      }
    } else if (auto pv = mavlink::decode<mavlink::ParamValue>(f)) {
      if (mavlink::to_string(pv->param_id) == "SIM_BATT_VOLTAGE")
        v.sim_batt_voltage = pv->param_value;
    } else if (auto s = mavlink::decode<mavlink::Statustext>(f)) {
      v.last_text = mavlink::to_string(s->text);
      phase(v.name + " says (" + mavlink::severity_name(s->severity) + "): " + v.last_text);
      log_->write(t, v.name, *s);
    } else if (auto ack = mavlink::decode<mavlink::CommandAck>(f)) {
      v.ack = *ack;
      log_->write(t, v.name, *ack);
    }
  }

  // The mode and failsafe watch, on each HEARTBEAT of the vehicle. A mode other than the one
  // kelp-mission set (outside its own mode changes) is a change it did not command: reported
  // now, and spin() ends the mission with it. A system_status entering MAV_STATE_CRITICAL or
  // EMERGENCY (ArduPilot's report of an active failsafe, GCS_Common.cpp / each vehicle's
  // vehicle_system_status()) is reported with the last STATUSTEXT and counted.
  void watch(Vehicle& v, bool first, const mavlink::Heartbeat& before) {
    const auto failsafe = [](std::uint8_t status) { return status == 5 || status == 6; };
    const std::string at = v.clock_ms ? " at " + v.clock_text() + " s of its clock"
                                      : " at boot (before it reported its clock)";
    const std::string text =
        v.last_text.empty() ? "" : "; last STATUSTEXT: \"" + v.last_text + "\"";
    if (failsafe(v.heartbeat.system_status) && (first || !failsafe(before.system_status))) {
      const std::string state = v.heartbeat.system_status == 5 ? "CRITICAL" : "EMERGENCY";
      if (v.armed() || v.was_armed || failsafe_text(v.last_text)) {
        ++v.failsafes;
        v.events.push_back(v.name + ": failsafe (HEARTBEAT system_status " + state + ")" + at +
                           text);
        phase(v.events.back());
      } else {
        // Disarmed, never armed by kelp-mission, and no failsafe message: an autopilot's
        // start-up state (ArduSub reports CRITICAL for its first seconds while its pilot-input
        // failsafe, set at boot, and its EKF checks clear), not a failsafe.
        ++v.boot_states;
        v.boot_events.push_back(state + at + " (disarmed, before arming)" + text);
        phase(v.name + ": " + state + " before arming" + at + " (a start-up state)" + text);
      }
    }
    if (first || !v.commanded_mode || v.changing_mode) return;
    const std::uint32_t mode = v.heartbeat.custom_mode;
    if (mode == before.custom_mode || mode == *v.commanded_mode) return;
    ++v.uncommanded_mode_changes;
    v.events.push_back(v.name + ": mode changed from " + mode_name(v.is_sub(), before.custom_mode) +
                       " to " + mode_name(v.is_sub(), mode) + at +
                       " without a command from kelp-mission (a failsafe or another ground "
                       "station)" +
                       text);
    phase(v.events.back());
    if (checks_) v.uncommanded_mode = mode;
  }

  // The summary: per vehicle, what the link carried and what happened that kelp-mission did not
  // ask for. Frames of message types kelp-mission does not decode (ArduPilot streams dozens)
  // are well-formed and simply not used: "ignored", not errors. Malformed input is counted
  // apart: CRC mismatches, impossible lengths, unknown incompatibility flags, stray bytes.
  void print_link_stats() {
    if (log_) log_->flush();
    for (Vehicle* v : vehicles()) {
      const auto& s = v->link.stats();
      out_ << v->name << " link: " << s.frames << " frames used, " << s.unknown_msgid
           << " frames of other message types ignored; malformed: " << s.bad_crc << " bad CRC, "
           << s.bad_length << " bad length, " << s.bad_flags << " bad flags, " << s.junk_bytes
           << " bytes outside frames; " << v->link.dropped_frames()
           << " frames not sent (send buffer full)" << std::endl;
      out_ << v->name << ": " << v->uncommanded_mode_changes
           << " mode changes not commanded by kelp-mission, " << v->failsafes << " failsafes"
           << (v->clock_ms ? "; its clock at " + v->clock_text() + " s" : std::string())
           << std::endl;
      for (const std::string& e : v->events) out_ << "  " << e << std::endl;
      if (!std::isnan(v->battery_min_v))
        out_ << v->name
             << ": battery as it reports it while armed (SYS_STATUS): " << fmt(v->battery_min_v)
             << "-" << fmt(v->battery_max_v) << " V"
             << (std::isnan(v->battery_max_a) ? std::string()
                                              : ", up to " + fmt(v->battery_max_a) + " A")
             << (v->battery_note.empty() ? std::string() : "; " + v->battery_note) << std::endl;
      if (v->boot_states > 0) {
        out_ << v->name << ": " << v->boot_states
             << " CRITICAL/EMERGENCY states at start-up, disarmed (not failsafes):" << std::endl;
        for (const std::string& e : v->boot_events) out_ << "  " << e << std::endl;
      }
    }
  }

  // A STATUSTEXT that names a failsafe (ArduPilot's are "Failsafe...", "... failsafe ...":
  // ArduSub/failsafe.cpp, Rover/failsafe.cpp, GCS_Common.cpp).
  static bool failsafe_text(const std::string& text) {
    std::string lower(text);
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return lower.find("failsafe") != std::string::npos;
  }

  static std::string fmt(double x) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(x == std::floor(x) && std::fabs(x) < 1e6 ? 0 : 2) << x;
    return s.str();
  }

  static constexpr std::int16_t kNeutralZ = 500;
  static constexpr double kPi = 3.14159265358979323846;

  Options opt_;
  std::ostream& out_;
  std::ostream& err_;
  Clock::time_point start_;
  std::unique_ptr<Vehicle> sub_, boat_;
  std::unique_ptr<CsvLog> log_;
  bool following_ = false;
  bool checks_ = true;  // link and arming checks in spin()
  std::int16_t manual_z_ = kNeutralZ;
  std::optional<mavlink::SetPositionTargetLocalNed> local_target_;
  std::array<Pace, 2> heartbeat_pace_{};  // sub, boat
  Pace manual_pace_, follow_pace_, local_target_pace_;
};

}  // namespace kelp_sitl::mission
