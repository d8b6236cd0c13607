// A scripted fake ArduPilot for kelp-mission's tests: a TCP server on 127.0.0.1 (ephemeral
// port) in its own thread, speaking MAVLink with kelp's codec. It sends HEARTBEAT, ATTITUDE,
// LOCAL_POSITION_NED and GLOBAL_POSITION_INT, answers COMMAND_LONG arm/disarm and set-mode
// with COMMAND_ACK (refusing arming as scripted, with a "PreArm: ..." STATUSTEXT), and "flies":
// in ALT_HOLD the depth follows MANUAL_CONTROL z; in GUIDED the position moves toward the last
// target received. It records what the client sent, for the test to check afterwards.
//
// Its clock (time_boot_ms, the kinematics, the failsafes) runs `clock_speed` times faster than
// the wall clock, as a SITL at --speedup does. Optionally it has ArduPilot's GCS failsafe (a
// mode change to `failsafe_mode` and system_status CRITICAL after `gcs_failsafe_timeout` s of
// its clock without a GCS HEARTBEAT, as ArduRover's FS_GCS_ENABLE / FS_GCS_TIMEOUT) or a
// scripted failsafe some time after it entered GUIDED.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "mavlink/mavlink.hpp"

namespace kelp_sitl::test {

namespace mv = kelp_sitl::mavlink;
inline constexpr double kPi = 3.14159265358979323846;

struct FakeConfig {
  std::uint8_t mav_type = mv::kTypeSubmarine;
  std::uint32_t initial_mode = 19;  // ArduSub MANUAL / Rover MANUAL is 0
  bool silent = false;              // accept the connection, never send anything
  double silent_after = -1.0;       // s after the connection: stop sending (a hung autopilot)
  double position_after = 0.0;      // s after the connection before positions are sent (no EKF)
  int arm_refusals = 0;             // refuse the first N arm commands; -1: always
  bool banner = false;              // plain text before the first frame (as ArduSub prints)
  double speed = 8.0;               // m/s horizontal in GUIDED
  double descent_rate = 3.0;        // m/s at full stick
  double heartbeat_hz = 5.0;        // per wall second (as the state messages, 20 Hz)
  double origin_lat = 33.810313, origin_lon = -118.393867;
  double clock_speed = 1.0;             // its seconds per wall second
  double gcs_failsafe_timeout = -1.0;   // s of its clock without GCS HEARTBEAT (< 0: none)
  double failsafe_after_guided = -1.0;  // s of its clock in GUIDED, then failsafe (< 0: never)
  std::uint32_t failsafe_mode = 4;      // Rover HOLD
  // s of its clock during which it reports system_status CRITICAL while disarmed, with no
  // STATUSTEXT, as ArduSub does at start-up (its pilot-input failsafe is set at boot).
  double boot_critical = 0.0;
  // Depth (m, down) where the vehicle starts, and where its EKF origin is: LOCAL_POSITION_NED z
  // counts from the origin, GLOBAL_POSITION_INT's altitude from the sea surface (as ArduSub's,
  // whose EKF origin is wherever the vehicle was when its EKF started).
  double start_depth = 0.0;
  double origin_depth = 0.0;
  // The battery in SYS_STATUS [V], and SITL's SIM_BATT_VOLTAGE answered to PARAM_REQUEST_READ
  // (< 0: no answer, not a SITL). Equal: an ArduPilot that shows its own SITL battery.
  double battery_voltage = 16.5;
  double sim_batt_voltage = 12.6;
};

// What the fake received.
struct FakeRecord {
  int gcs_heartbeats = 0;
  bool gcs_heartbeat_ok = true;  // every one: sysid 255, compid 190, type GCS, autopilot INVALID
  std::vector<double> manual_control_times;  // s since start, while armed
  std::vector<mv::ManualControl> manual_controls;
  std::vector<mv::CommandLong> commands;
  std::vector<std::uint32_t> modes;  // accepted mode changes, in order
  std::vector<int> arm_states;       // accepted arm (1) / disarm (0), in order
  std::vector<mv::SetPositionTargetLocalNed> local_targets;
  std::vector<mv::SetPositionTargetGlobalInt> global_targets;
  std::vector<std::uint8_t> senders;        // sysid of every frame received
  bool dive_before_position = false;        // MANUAL_CONTROL z < 500 before any position was sent
  std::vector<double> gcs_heartbeat_clock;  // its clock (s) at each GCS HEARTBEAT
  bool failsafe = false;                    // a failsafe fired
};

class FakeAutopilot {
 public:
  explicit FakeAutopilot(FakeConfig cfg) : cfg_(cfg), mode_(cfg.initial_mode), z_(cfg.start_depth) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(listen_fd_, 1);
    socklen_t len = sizeof a;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  FakeAutopilot(const FakeAutopilot&) = delete;
  FakeAutopilot& operator=(const FakeAutopilot&) = delete;
  ~FakeAutopilot() {
    stop_ = true;
    thread_.join();
    if (fd_ >= 0) ::close(fd_);
    ::close(listen_fd_);
  }

  std::uint16_t port() const { return port_; }
  std::string endpoint() const { return "tcp:127.0.0.1:" + std::to_string(port_); }

  FakeRecord record() {
    std::lock_guard<std::mutex> lock(mutex_);
    return record_;
  }
  // The simulated position (NED m: north and east from the origin, z the true depth).
  std::array<double, 3> position() {
    std::lock_guard<std::mutex> lock(mutex_);
    return {x_, y_, z_};
  }
  bool armed() {
    std::lock_guard<std::mutex> lock(mutex_);
    return armed_;
  }

 private:
  using Clock = std::chrono::steady_clock;

  void run() {
    const auto start = Clock::now();
    // Accept one client.
    while (!stop_ && fd_ < 0) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) == 1) fd_ = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    }
    if (fd_ < 0) return;
    if (cfg_.banner && !cfg_.silent) {
      const std::string banner = "Init ArduSub V4.7.0-dev (fake)\n\nFree RAM: 262144\n";
      write(std::vector<std::uint8_t>(banner.begin(), banner.end()));
    }
    auto last = Clock::now();
    auto next_hb = last, next_pos = last;
    mv::Parser parser;
    const auto clock = [&](Clock::time_point t) {
      return cfg_.clock_speed * std::chrono::duration<double>(t - start).count();
    };
    while (!stop_) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 10) == 1) {
        std::uint8_t buf[2048];
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n <= 0) break;  // client gone
        parser.feed(buf, static_cast<std::size_t>(n), [&](const mv::Frame& f) {
          handle(f, std::chrono::duration<double>(Clock::now() - start).count(),
                 clock(Clock::now()));
        });
      }
      const auto now = Clock::now();
      if (cfg_.silent || (cfg_.silent_after >= 0 &&
                          std::chrono::duration<double>(now - start).count() > cfg_.silent_after))
        continue;
      step(cfg_.clock_speed * std::chrono::duration<double>(now - last).count());
      last = now;
      check_failsafes(clock(now));
      clock_s_ = clock(now);
      if (now >= next_hb) {
        send_heartbeat();
        next_hb = now + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(1.0 / cfg_.heartbeat_hz));
      }
      if (now >= next_pos &&
          std::chrono::duration<double>(now - start).count() >= cfg_.position_after) {
        send_state(static_cast<std::uint32_t>(clock(now) * 1000.0));
        next_pos = now + std::chrono::milliseconds(50);
      }
    }
  }

  void write(const std::vector<std::uint8_t>& b) {
    if (fd_ >= 0) (void)::send(fd_, b.data(), b.size(), MSG_NOSIGNAL);
  }
  template <class M>
  void send(const M& m) {
    write(out_.pack(m));
  }

  void send_heartbeat() {
    mv::Heartbeat hb;
    std::lock_guard<std::mutex> lock(mutex_);
    hb.custom_mode = mode_;
    hb.type = cfg_.mav_type;
    hb.autopilot = mv::kAutopilotArdupilotmega;
    hb.base_mode = static_cast<std::uint8_t>(81 | (armed_ ? 128 : 0));
    // CRITICAL, ACTIVE, STANDBY
    hb.system_status = failsafe_ || (!armed_ && clock_s_ < cfg_.boot_critical) ? 5 : armed_ ? 4 : 3;
    send(hb);
  }

  // ArduPilot's GCS failsafe, counted in its own clock, and the scripted one.
  void check_failsafes(double t) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (failsafe_ || !armed_) return;
    std::string why;
    if (cfg_.gcs_failsafe_timeout >= 0 && last_gcs_heartbeat_ >= 0 &&
        t - last_gcs_heartbeat_ > cfg_.gcs_failsafe_timeout)
      why = "Failsafe. GCS";
    const std::uint32_t guided = cfg_.mav_type == mv::kTypeSubmarine ? 4u : 15u;
    if (mode_ == guided && cfg_.failsafe_after_guided >= 0 && guided_since_ >= 0 &&
        t - guided_since_ > cfg_.failsafe_after_guided)
      why = "Failsafe. Scripted";
    if (why.empty()) return;
    failsafe_ = true;
    record_.failsafe = true;
    mode_ = cfg_.failsafe_mode;
    have_target_ = false;
    lock.unlock();
    mv::Statustext s;
    s.severity = 2;
    s.text = mv::to_chars<50>(why);
    send(s);
  }

  void send_state(std::uint32_t t_ms) {
    mv::LocalPositionNed lp;
    mv::GlobalPositionInt gp;
    mv::Attitude att;
    mv::SystemTime st;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      position_sent_ = true;
      lp.time_boot_ms = gp.time_boot_ms = att.time_boot_ms = st.time_boot_ms = t_ms;
      lp.x = static_cast<float>(x_);
      lp.y = static_cast<float>(y_);
      lp.z = static_cast<float>(z_ - cfg_.origin_depth);
      const double deg_per_m = 1.0 / 111319.49;
      gp.lat = static_cast<std::int32_t>(std::lround((cfg_.origin_lat + x_ * deg_per_m) * 1e7));
      gp.lon = static_cast<std::int32_t>(std::lround(
          (cfg_.origin_lon + y_ * deg_per_m / std::cos(cfg_.origin_lat * kPi / 180.0)) * 1e7));
      gp.alt = gp.relative_alt = static_cast<std::int32_t>(-z_ * 1000.0);
      gp.hdg = 65535;
      att.yaw = static_cast<float>(yaw_);
    }
    mv::SysStatus ss;
    ss.voltage_battery = static_cast<std::uint16_t>(std::lround(cfg_.battery_voltage * 1000.0));
    ss.current_battery = static_cast<std::int16_t>(armed() ? 250 : 0);  // cA
    ss.battery_remaining = 90;
    send(st);
    send(lp);
    send(gp);
    send(att);
    send(ss);
  }

  // Simple kinematics.
  void step(double dt) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!armed_) return;
    const bool sub = cfg_.mav_type == mv::kTypeSubmarine;
    if (sub && mode_ == 2) z_ += cfg_.descent_rate * dt * (500.0 - manual_z_) / 500.0;
    if (mode_ == (sub ? 4u : 15u) && have_target_) {
      const double dx = tx_ - x_, dy = ty_ - y_, d = std::hypot(dx, dy);
      const double move = std::min(d, cfg_.speed * dt);
      if (d > 1e-9) {
        x_ += dx / d * move;
        y_ += dy / d * move;
      }
      if (sub) z_ += std::clamp(tz_ + cfg_.origin_depth - z_, -cfg_.speed * dt, cfg_.speed * dt);
    }
  }

  void ack(std::uint16_t cmd, mv::Result r) {
    mv::CommandAck a;
    a.command = cmd;
    a.result = static_cast<std::uint8_t>(r);
    a.target_system = 255;
    a.target_component = 190;
    send(a);
  }

  // t: wall s since the start; clock: its own clock, s.
  void handle(const mv::Frame& f, double t, double clock) {
    std::unique_lock<std::mutex> lock(mutex_);
    record_.senders.push_back(f.sysid);
    if (auto hb = mv::decode<mv::Heartbeat>(f)) {
      ++record_.gcs_heartbeats;
      record_.gcs_heartbeat_clock.push_back(clock);
      last_gcs_heartbeat_ = clock;
      record_.gcs_heartbeat_ok = record_.gcs_heartbeat_ok && f.sysid == 255 && f.compid == 190 &&
                                 hb->type == mv::kTypeGcs && hb->autopilot == mv::kAutopilotInvalid;
    } else if (auto mc = mv::decode<mv::ManualControl>(f)) {
      if (armed_) record_.manual_control_times.push_back(t);
      record_.manual_controls.push_back(*mc);
      if (mc->z < 500 && !position_sent_) record_.dive_before_position = true;
      manual_z_ = mc->z;
    } else if (auto c = mv::decode<mv::CommandLong>(f)) {
      record_.commands.push_back(*c);
      if (c->command == mv::kCmdComponentArmDisarm) {
        const bool arm = c->param1 == 1.0f;
        if (arm && (cfg_.arm_refusals < 0 || arm_refused_ < cfg_.arm_refusals)) {
          ++arm_refused_;
          lock.unlock();
          mv::Statustext s;
          s.severity = 2;
          s.text = mv::to_chars<50>("PreArm: Gyros inconsistent");
          send(s);
          ack(c->command, mv::Result::Failed);
          return;
        }
        armed_ = arm;
        record_.arm_states.push_back(arm ? 1 : 0);
        lock.unlock();
        ack(c->command, mv::Result::Accepted);
      } else if (c->command == mv::kCmdDoSetMode) {
        mode_ = static_cast<std::uint32_t>(c->param2);
        record_.modes.push_back(mode_);
        guided_since_ = clock;
        have_target_ = false;
        lock.unlock();
        ack(c->command, mv::Result::Accepted);
      } else {
        lock.unlock();
        ack(c->command, mv::Result::Unsupported);
      }
    } else if (auto pr = mv::decode<mv::ParamRequestRead>(f)) {
      if (mv::to_string(pr->param_id) != "SIM_BATT_VOLTAGE" || cfg_.sim_batt_voltage < 0) return;
      lock.unlock();
      mv::ParamValue pv;
      pv.param_id = pr->param_id;
      pv.param_value = static_cast<float>(cfg_.sim_batt_voltage);
      pv.param_type = 9;  // REAL32
      pv.param_count = 1;
      send(pv);
    } else if (auto lt = mv::decode<mv::SetPositionTargetLocalNed>(f)) {
      record_.local_targets.push_back(*lt);
      tx_ = lt->x;
      ty_ = lt->y;
      tz_ = lt->z;
      yaw_ = lt->yaw;
      have_target_ = true;
    } else if (auto gt = mv::decode<mv::SetPositionTargetGlobalInt>(f)) {
      record_.global_targets.push_back(*gt);
      const double deg_per_m = 1.0 / 111319.49;
      tx_ = (gt->lat_int * 1e-7 - cfg_.origin_lat) / deg_per_m;
      ty_ = (gt->lon_int * 1e-7 - cfg_.origin_lon) / deg_per_m *
            std::cos(cfg_.origin_lat * kPi / 180.0);
      have_target_ = true;
    }
  }

  FakeConfig cfg_;
  int listen_fd_ = -1;
  int fd_ = -1;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mv::Sender out_{1, mv::kCompAutopilot1};

  std::mutex mutex_;  // guards everything below (the test reads while the fake runs)
  FakeRecord record_;
  std::uint32_t mode_;
  bool armed_ = false;
  int arm_refused_ = 0;
  std::int16_t manual_z_ = 500;
  double x_ = 0, y_ = 0, yaw_ = 0;
  double z_;                         // true depth, m
  double tx_ = 0, ty_ = 0, tz_ = 0;  // tz_: in LOCAL_POSITION_NED's frame
  bool have_target_ = false;
  bool position_sent_ = false;
  bool failsafe_ = false;
  double last_gcs_heartbeat_ = -1.0;  // its clock, s
  double clock_s_ = 0.0;              // its clock, s, at the last round
  double guided_since_ = -1.0;        // its clock at the last mode change, s
};

}  // namespace kelp_sitl::test
