// kelp-mission against scripted fake autopilots on loopback TCP: the whole mission with short
// timings, a refused then accepted arm, an arm always refused, a silent peer, nobody listening.
#include <catch2/catch.hpp>

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "fake_autopilot.hpp"
#include "mission/mission.hpp"

using kelp_sitl::mission::Mission;
using kelp_sitl::mission::Options;
using kelp_sitl::test::FakeAutopilot;
using kelp_sitl::test::FakeConfig;
namespace mv = kelp_sitl::mavlink;
constexpr double kPi = 3.14159265358979323846;

namespace {

using Clock = std::chrono::steady_clock;

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("kelp-mission-test-" + std::to_string(::getpid()) + "-" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

Options short_options(const std::string& log_name) {
  Options o;
  o.depth = 2.0;
  o.depth_tolerance = 0.2;
  o.hold = 1.0;
  o.survey_side = 4.0;
  o.survey_radius = 0.5;
  o.log_dir = fresh_dir(log_name).string();
  o.connect_timeout = 3.0;
  o.heartbeat_timeout = 3.0;
  o.arm_timeout = 4.0;
  o.position_timeout = 4.0;
  o.mode_timeout = 3.0;
  o.dive_timeout = 10.0;
  o.leg_timeout = 5.0;
  o.retry_interval = 0.5;
  o.link_timeout = 3.0;
  return o;
}

// The sub alone, no survey: for the checks that need only the start of the mission.
Options sub_only_options(const std::string& log_name, const FakeAutopilot& sub) {
  Options o = short_options(log_name);
  o.sub = sub.endpoint();
  o.rover = "none";
  o.survey_side = 0.0;
  return o;
}

FakeConfig boat_config() {
  FakeConfig c;
  c.mav_type = mv::kTypeSurfaceBoat;
  c.initial_mode = 0;
  return c;
}

int count_lines(const std::filesystem::path& p) {
  std::ifstream f(p);
  int n = 0;
  for (std::string line; std::getline(f, line);) ++n;
  return n;
}

struct Run {
  int code;
  double seconds;
  std::string out, err;
};

Run run_mission(const Options& o) {
  std::ostringstream out, err;
  const auto t0 = Clock::now();
  Mission m(o, out, err);
  const int code = m.run();
  return {code, std::chrono::duration<double>(Clock::now() - t0).count(), out.str(), err.str()};
}

}  // namespace

TEST_CASE("kelp-mission flies the whole mission against fake autopilots", "[mission]") {
  FakeConfig sub_cfg;
  sub_cfg.banner = true;
  sub_cfg.arm_refusals = 1;      // refused once ("PreArm: ..."), accepted on the retry
  sub_cfg.position_after = 1.5;  // no position estimate at first: the dive must wait for it
  FakeAutopilot sub(sub_cfg);
  FakeAutopilot boat(boat_config());
  Options o = short_options("full");
  o.sub = sub.endpoint();
  o.rover = boat.endpoint();

  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.seconds < 20.0);
  CHECK(r.out.find("PreArm: Gyros inconsistent") != std::string::npos);
  CHECK(r.out.find("refused: FAILED") != std::string::npos);
  CHECK(r.out.find("mission complete") != std::string::npos);

  const auto s = sub.record();
  const auto b = boat.record();
  // GCS identity and heartbeats.
  CHECK(s.gcs_heartbeats >= 2);
  CHECK(s.gcs_heartbeat_ok);
  CHECK(b.gcs_heartbeat_ok);
  for (std::uint8_t id : s.senders) CHECK(id == 255);
  // Pilot input to the sub at >= 10 Hz while armed, gaps bounded; throttle below neutral to dive.
  REQUIRE(s.manual_control_times.size() > 20);
  double max_gap = 0;
  for (std::size_t i = 1; i < s.manual_control_times.size(); ++i)
    max_gap = std::max(max_gap, s.manual_control_times[i] - s.manual_control_times[i - 1]);
  const double span = s.manual_control_times.back() - s.manual_control_times.front();
  CHECK(static_cast<double>(s.manual_control_times.size() - 1) / span >= 10.0);
  CHECK(max_gap < 1.0);  // ArduSub's FS_PILOT_TIMEOUT is 3 s; slack for a loaded machine
  bool dived = false;
  for (const auto& mc : s.manual_controls) {
    CHECK(mc.target == 1);
    dived = dived || mc.z < 500;
  }
  CHECK(dived);
  CHECK_FALSE(s.dive_before_position);
  CHECK(b.manual_controls.empty());
  // Arming: sub refused once then armed; both disarmed at the end.
  CHECK(s.arm_states == std::vector<int>{1, 0});
  CHECK(b.arm_states == std::vector<int>{1, 0});
  CHECK_FALSE(sub.armed());
  CHECK_FALSE(boat.armed());
  // Modes: sub ALT_HOLD, GUIDED, MANUAL; boat GUIDED, HOLD.
  CHECK(s.modes == std::vector<std::uint32_t>{2, 4, 19});
  CHECK(b.modes == std::vector<std::uint32_t>{15, 4});
  for (const auto& c : s.commands) {
    CHECK(c.target_system == 1);
    CHECK(c.target_component == 1);
    if (c.command == mv::kCmdDoSetMode) CHECK(c.param1 == 1.0f);
  }
  // Survey targets: LOCAL_NED, type_mask 2552, at depth, yaw along each leg.
  REQUIRE(s.local_targets.size() >= 4);
  std::vector<float> yaws;
  for (const auto& t : s.local_targets) {
    CHECK(t.coordinate_frame == mv::kFrameLocalNed);
    CHECK(t.type_mask == 2552);
    CHECK(t.z == Approx(2.0).margin(0.005));  // the depth, in mm in GLOBAL_POSITION_INT
    CHECK(t.target_system == 1);
    if (yaws.empty() || yaws.back() != t.yaw) yaws.push_back(t.yaw);
  }
  REQUIRE(yaws.size() == 4);
  CHECK(yaws[0] == Approx(0.0).margin(0.05));             // north
  CHECK(yaws[1] == Approx(kPi / 2).margin(0.05));         // east
  CHECK(std::fabs(yaws[2]) == Approx(kPi).margin(0.05));  // south
  CHECK(yaws[3] == Approx(-kPi / 2).margin(0.05));        // west
  const auto end = sub.position();
  CHECK(end[2] >= 1.8);
  // The boat followed the sub: position-only global targets, frame 6, the sub's lat/lon.
  REQUIRE(b.global_targets.size() >= 3);
  for (const auto& t : b.global_targets) {
    CHECK(t.coordinate_frame == 6);
    CHECK(t.type_mask == 3576);
    CHECK(t.target_system == 1);
    CHECK(std::abs(t.lat_int - 338103130) < 1000);  // within ~10 m of the sub's start
  }
  const auto boat_end = boat.position();
  CHECK(std::hypot(boat_end[0] - end[0], boat_end[1] - end[1]) < 8.0);
  // Logs.
  const std::filesystem::path dir = o.log_dir;
  for (const char* f : {"attitude.csv", "local_position_ned.csv", "global_position_int.csv",
                        "statustext.csv", "command_ack.csv"})
    CHECK(std::filesystem::exists(dir / f));
  CHECK(count_lines(dir / "local_position_ned.csv") > 50);
  CHECK(count_lines(dir / "statustext.csv") == 2);
  CHECK(count_lines(dir / "command_ack.csv") >= 10);
  std::filesystem::remove_all(dir);
}

TEST_CASE("kelp-mission: an arm always refused fails clearly within the time-out", "[mission]") {
  FakeConfig sub_cfg;
  sub_cfg.arm_refusals = -1;
  FakeAutopilot sub(sub_cfg);
  Options o = short_options("refused");
  o.sub = sub.endpoint();
  o.rover = "none";
  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(r.seconds < o.arm_timeout + 3.0);
  CHECK(r.err.find("sub: arm: MAV_CMD_COMPONENT_ARM_DISARM not accepted within 4 s") !=
        std::string::npos);
  CHECK(r.err.find("last result: FAILED") != std::string::npos);
  CHECK(r.err.find("PreArm: Gyros inconsistent") != std::string::npos);
  const auto s = sub.record();
  CHECK(s.commands.size() >= 5);                                        // retried every 0.5 s
  CHECK(std::count(s.arm_states.begin(), s.arm_states.end(), 1) == 0);  // never armed
  std::filesystem::remove_all(o.log_dir);
}

TEST_CASE("kelp-mission: a peer that never sends times out", "[mission]") {
  FakeConfig silent;
  silent.silent = true;
  FakeAutopilot sub(silent);
  Options o = short_options("silent");
  o.sub = sub.endpoint();
  o.rover = "none";
  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(r.seconds < o.heartbeat_timeout + 2.0);
  CHECK(r.err.find("sub: no HEARTBEAT within 3 s") != std::string::npos);
  // It still heard from us: GCS heartbeats (and pilot input) go out from the connection on.
  CHECK(sub.record().gcs_heartbeats >= 2);
  std::filesystem::remove_all(o.log_dir);
}

TEST_CASE("kelp-mission: nobody listening times out on connect", "[mission]") {
  // A port that was free a moment ago.
  std::uint16_t port = 0;
  {
    FakeConfig c;
    c.silent = true;
    FakeAutopilot probe(c);
    port = probe.port();
  }
  Options o = short_options("noconnect");
  o.sub = "none";
  o.rover = "tcp:127.0.0.1:" + std::to_string(port);
  o.connect_timeout = 1.5;
  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(r.seconds < 4.0);
  CHECK(r.err.find("boat: cannot connect to 127.0.0.1:" + std::to_string(port)) !=
        std::string::npos);
  std::filesystem::remove_all(o.log_dir);
}

TEST_CASE("kelp-mission: a vehicle that stops talking mid-mission fails it; the other is made safe",
          "[mission]") {
  FakeConfig sub_cfg;
  sub_cfg.silent_after = 2.0;  // during the dive / hold
  FakeAutopilot sub(sub_cfg);
  FakeAutopilot boat(boat_config());
  Options o = short_options("lost");
  o.sub = sub.endpoint();
  o.rover = boat.endpoint();
  o.hold = 10.0;
  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(r.seconds < 12.0);
  CHECK(r.err.find("sub: no HEARTBEAT for 3 s: link lost") != std::string::npos);
  CHECK(r.err.find("sub: no link, cannot make it safe") != std::string::npos);
  const auto b = boat.record();
  CHECK(b.arm_states == std::vector<int>{1, 0});
  REQUIRE_FALSE(b.modes.empty());
  CHECK(b.modes.back() == 4);  // HOLD
  CHECK_FALSE(boat.armed());
  std::filesystem::remove_all(o.log_dir);
}

// At SITL --speedup 10 the vehicles' clocks run ten times faster than the wall clock, and
// their failsafes count in their clocks: ArduRover's GCS failsafe (FS_GCS_TIMEOUT 5 s in
// params/blueboat.parm) fired when kelp-mission sent one HEARTBEAT per wall second (one per
// ~7.6 simulated seconds in a real run). Paced by the vehicles' clocks, HEARTBEATs reach both
// at least once per second of their time and the mission completes.
TEST_CASE("kelp-mission paces HEARTBEATs by the vehicles' clocks: no GCS failsafe at 10x",
          "[mission]") {
  FakeConfig sub_cfg;
  sub_cfg.clock_speed = 10.0;
  sub_cfg.gcs_failsafe_timeout = 5.0;
  sub_cfg.failsafe_mode = 19;  // MANUAL, as ArduSub's FS_GCS_ENABLE 2 would
  FakeAutopilot sub(sub_cfg);
  FakeConfig boat_cfg = boat_config();
  boat_cfg.clock_speed = 10.0;
  boat_cfg.gcs_failsafe_timeout = 5.0;
  FakeAutopilot boat(boat_cfg);
  Options o = short_options("fastclock");
  o.sub = sub.endpoint();
  o.rover = boat.endpoint();
  o.hold = 40.0;  // s of the sub's clock: 4 s of wall time
  o.survey_side = 20.0;

  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(r.out.find("held depth between") != std::string::npos);
  CHECK(r.out.find("0 mode changes not commanded by kelp-mission, 0 failsafes") !=
        std::string::npos);
  for (const FakeAutopilot* f : {&sub, &boat}) {
    const auto rec = const_cast<FakeAutopilot*>(f)->record();
    CHECK_FALSE(rec.failsafe);
    REQUIRE(rec.gcs_heartbeat_clock.size() > 20);
    double max_gap = 0;
    for (std::size_t i = 1; i < rec.gcs_heartbeat_clock.size(); ++i)
      max_gap = std::max(max_gap, rec.gcs_heartbeat_clock[i] - rec.gcs_heartbeat_clock[i - 1]);
    // s of the vehicle's clock; the failsafe needs 5. At 10x a wall-clock stall of the client
    // (a loaded machine: 0.35 s seen once beside a build) is ten times longer on this clock.
    CHECK(max_gap < 4.0);
  }
  std::filesystem::remove_all(o.log_dir);
}

// A mode change kelp-mission did not command (here the boat's failsafe puts it in HOLD while
// it follows the sub) is reported with the vehicle's clock and the STATUSTEXT, ends the mission
// (the boat would hold there for good) and is counted in the summary.
TEST_CASE("kelp-mission reports a mode change it did not command and stops the mission",
          "[mission]") {
  FakeConfig sub_cfg;
  FakeAutopilot sub(sub_cfg);
  FakeConfig boat_cfg = boat_config();
  boat_cfg.failsafe_after_guided = 1.0;
  FakeAutopilot boat(boat_cfg);
  Options o = short_options("uncommanded");
  o.sub = sub.endpoint();
  o.rover = boat.endpoint();
  o.hold = 10.0;
  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 1);
  CHECK(boat.record().failsafe);
  CHECK(r.err.find("FAILED: boat: mode changed from GUIDED (15) to HOLD (4) at ") !=
        std::string::npos);
  CHECK(r.err.find("without a command from kelp-mission") != std::string::npos);
  CHECK(r.err.find("Failsafe. Scripted") != std::string::npos);
  CHECK(r.out.find("boat: failsafe (HEARTBEAT system_status CRITICAL)") != std::string::npos);
  CHECK(r.out.find("boat: 1 mode changes not commanded by kelp-mission, 1 failsafes") !=
        std::string::npos);
  CHECK(r.out.find("sub: 0 mode changes not commanded by kelp-mission, 0 failsafes") !=
        std::string::npos);
  // Both left safe: the sub MANUAL and disarmed, the boat HOLD and disarmed.
  CHECK_FALSE(sub.armed());
  CHECK_FALSE(boat.armed());
  std::filesystem::remove_all(o.log_dir);
}

TEST_CASE("kelp-mission's summary tells ignored message types from malformed frames", "[mission]") {
  FakeAutopilot sub{FakeConfig{}};
  Options o = sub_only_options("summary", sub);
  const Run r = run_mission(o);
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find(" frames of other message types ignored; malformed: 0 bad CRC, 0 bad "
                   "length, 0 bad flags, ") != std::string::npos);
  CHECK(r.out.find("unknown messages") == std::string::npos);
  std::filesystem::remove_all(o.log_dir);
}

// ArduSub reports system_status CRITICAL for its first seconds after boot, disarmed and with no
// STATUSTEXT (its pilot-input failsafe is set at start-up until a pilot is heard). That is not
// a failsafe: the summary reports it apart, and the mission goes on. A CRITICAL state once the
// vehicle is armed still is one (the test above).
TEST_CASE("kelp-mission: CRITICAL at start-up, disarmed, is not a failsafe", "[mission]") {
  FakeConfig sub_cfg;
  sub_cfg.boot_critical = 1.0;   // s of its clock
  sub_cfg.position_after = 1.5;  // arming waits for the position, after the start-up state
  FakeAutopilot sub(sub_cfg);
  Options o = sub_only_options("boot", sub);
  const Run r = run_mission(o);
  INFO(r.out);
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(r.out.find("sub: 0 mode changes not commanded by kelp-mission, 0 failsafes") !=
        std::string::npos);
  CHECK(r.out.find("sub: 1 CRITICAL/EMERGENCY states at start-up, disarmed (not failsafes)") !=
        std::string::npos);
  CHECK(r.out.find("CRITICAL before arming at ") != std::string::npos);
  CHECK(r.out.find("failsafe (HEARTBEAT") == std::string::npos);
  std::filesystem::remove_all(o.log_dir);
}

// ArduSub's LOCAL_POSITION_NED counts from its EKF origin, set wherever the ROV was when its EKF
// started: 5.75 m down after a submerged start, the ROV having risen to 2.4 m by arming (as in a
// live run). The dive, the hold and the survey's depth go by the depth below the surface, so the
// ROV ends at the target depth, not 5.75 m deeper. From below the target it rises to it.
TEST_CASE("kelp-mission dives to the depth below the surface, not below the EKF origin",
          "[mission]") {
  struct Case {
    double start, origin;
  };
  for (const Case c : {Case{2.4, 5.75}, Case{8.0, 8.0}}) {
    INFO("start " << c.start << " m, EKF origin " << c.origin << " m");
    FakeConfig sub_cfg;
    sub_cfg.start_depth = c.start;
    sub_cfg.origin_depth = c.origin;
    FakeAutopilot sub(sub_cfg);
    Options o = short_options("origin");
    o.sub = sub.endpoint();
    o.rover = "none";
    o.depth = 5.0;
    o.depth_tolerance = 0.05;
    const Run r = run_mission(o);
    INFO(r.out);
    INFO(r.err);
    REQUIRE(r.code == 0);
    CHECK(r.out.find(c.start < 5.0 ? "sub: diving to 5 m from 2.40 m"
                                   : "sub: rising to 5 m from 8 m") != std::string::npos);
    // The depth held after the dive, and the survey flown at it (GUIDED targets in the EKF's
    // frame: 5 m less the origin's depth).
    const auto held = r.out.find("sub: held depth between ");
    REQUIRE(held != std::string::npos);
    double lo = 0, hi = 0;
    REQUIRE(std::sscanf(r.out.c_str() + held, "sub: held depth between %lf and %lf", &lo, &hi) ==
            2);
    CHECK(lo >= 4.9);
    CHECK(hi <= 5.1);
    const auto rec = sub.record();
    REQUIRE(rec.local_targets.size() >= 4);
    for (const auto& t : rec.local_targets) CHECK(t.z == Approx(5.0 - c.origin).margin(0.1));
    CHECK(sub.position()[2] == Approx(5.0).margin(0.1));
    std::filesystem::remove_all(o.log_dir);
  }
}

// Whose battery the autopilot shows: an ArduPilot that ignores kelp-sitl's JSON "battery" shows
// its own SITL battery, exactly SIM_BATT_VOLTAGE while disarmed; kelp-mission says so before
// arming, and otherwise that the battery is kelp's. The summary gives the range reported while
// armed (SYS_STATUS, also in sys_status.csv).
TEST_CASE("kelp-mission tells whether the autopilot shows kelp's battery or its own", "[mission]") {
  for (const bool ignored : {false, true}) {
    INFO((ignored ? "JSON battery ignored" : "JSON battery read"));
    FakeConfig sub_cfg;
    sub_cfg.sim_batt_voltage = 12.6;
    sub_cfg.battery_voltage = ignored ? 12.6 : 16.42;
    FakeAutopilot sub(sub_cfg);
    Options o = sub_only_options(ignored ? "battery-own" : "battery-kelp", sub);
    const Run r = run_mission(o);
    INFO(r.out);
    INFO(r.err);
    CHECK(r.code == 0);
    if (ignored) {
      CHECK(r.out.find("sub: the battery it reports (12.60 V) is ArduPilot's own SITL battery "
                       "(SIM_BATT_VOLTAGE 12.60 V), not kelp's") != std::string::npos);
    } else {
      CHECK(r.out.find("sub: the battery it reports (16.42 V) is kelp's") != std::string::npos);
    }
    CHECK(r.out.find(std::string("sub: battery as it reports it while armed (SYS_STATUS): ") +
                     (ignored ? "12.60-12.60 V" : "16.42-16.42 V") + ", up to 2.50 A") !=
          std::string::npos);
    CHECK(count_lines(std::filesystem::path(o.log_dir) / "sys_status.csv") > 5);
    std::filesystem::remove_all(o.log_dir);
  }
}
