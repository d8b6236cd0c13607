// kelp-fake-ardupilot: stands in for ArduSub / ArduRover SITL in the test that follows the
// README's launch lines (readme_launch.py). It takes the command line the README gives the real
// binaries (--model JSON -I N --home LAT,LON,ALT,HDG -w --defaults A,B,...) and behaves as
// far as kelp-sitl and kelp-mission can tell like a SITL:
//
// - it writes eeprom.bin into its working directory (SITL does), reads every --defaults file
//   (a missing one is an error, as for SITL) and takes FS_GCS_ENABLE / FS_GCS_TIMEOUT from them;
// - it listens for one MAVLink client on TCP 5760 + 10 N and sends nothing to the physics
//   before that client connects (SITL's SERIAL0 "wait");
// - then it steps in lockstep with the JSON physics on UDP 9002 + 10 N: one 16-channel servo
//   packet per frame (magic 18458), re-sent after 1 s without a reply; its clock is the
//   `timestamp` of the replies (so it runs as fast as the lockstep allows: a fast simulated
//   clock, as SITL at a high --speedup);
// - MAVLink, paced by that clock: HEARTBEAT 1 Hz (custom_mode, armed flag, system_status),
//   SYSTEM_TIME, ATTITUDE, LOCAL_POSITION_NED, GLOBAL_POSITION_INT 10 Hz (after 1 s: the EKF),
//   COMMAND_ACK to arm/disarm and set-mode; a kinematic vehicle (ALT_HOLD follows
//   MANUAL_CONTROL z, GUIDED goes to the last target); the GCS failsafe (HOLD for the boat,
//   MANUAL for the sub, system_status CRITICAL, STATUSTEXT) after FS_GCS_TIMEOUT s of its clock
//   without a GCS HEARTBEAT; the ROV's depth read as ArduSub reads SITL's pressure, with the
//   BARO_SPEC_GRAV of the --defaults files (its true depth in true_depth.txt, for the test).
//
// The test alone gives --json-port / --mavlink-port (ephemeral ports: tests never take the
// fixed SITL ports a running kelp-sitl may hold). It is not a flight model: the PWM it sends
// are neutral, so kelp's vehicles drift while the fake's own kinematics "fly".
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mavlink/mavlink.hpp"

namespace mv = kelp_sitl::mavlink;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerM = 1.0 / 111319.49;

struct Args {
  bool sub = true;
  int instance = 0;
  double lat = 0, lon = 0;
  std::vector<std::string> defaults;
  int json_port = -1, mavlink_port = -1;
};

[[noreturn]] void fail(const std::string& why) {
  std::fprintf(stderr, "kelp-fake-ardupilot: %s\n", why.c_str());
  std::exit(2);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string part; std::getline(ss, part, sep);) out.push_back(part);
  return out;
}

Args parse(int argc, char** argv) {
  Args a;
  bool json = false, wipe = false;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) fail(k + " needs a value");
      return argv[++i];
    };
    if (k == "--vehicle") {
      const std::string v = value();
      if (v != "sub" && v != "rover") fail("--vehicle sub|rover");
      a.sub = v == "sub";
    } else if (k == "--model") {
      json = value() == "JSON";
    } else if (k.rfind("-I", 0) == 0 && k.size() > 2) {
      a.instance = std::stoi(k.substr(2));
    } else if (k == "--home") {
      const auto f = split(value(), ',');
      if (f.size() != 4) fail("--home LAT,LON,ALT,HEADING");
      a.lat = std::stod(f[0]);
      a.lon = std::stod(f[1]);
      if (std::stod(f[2]) != 0.0) fail("--home altitude must be 0 (the README says why)");
    } else if (k == "-w") {
      wipe = true;
    } else if (k == "--defaults") {
      a.defaults = split(value(), ',');
    } else if (k == "--json-port") {
      a.json_port = std::stoi(value());
    } else if (k == "--mavlink-port") {
      a.mavlink_port = std::stoi(value());
    } else {
      fail("unknown argument " + k);
    }
  }
  if (!json) fail("expected --model JSON");
  if (!wipe) fail("expected -w");
  if (a.json_port < 0) a.json_port = 9002 + 10 * a.instance;
  if (a.mavlink_port < 0) a.mavlink_port = 5760 + 10 * a.instance;
  return a;
}

// NAME VALUE lines, # comments (ArduPilot's parameter file format).
void read_params(const std::string& file, double& fs_gcs_enable, double& fs_gcs_timeout,
                 double& spec_grav) {
  std::ifstream in(file);
  if (!in) fail("cannot read --defaults file " + file);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string name;
    double value = 0;
    if (!(ls >> name) || name[0] == '#' || !(ls >> value)) continue;
    if (name == "FS_GCS_ENABLE") fs_gcs_enable = value;
    if (name == "FS_GCS_TIMEOUT") fs_gcs_timeout = value;
    if (name == "BARO_SPEC_GRAV") spec_grav = value;
  }
}

class Fake {
 public:
  explicit Fake(const Args& a) : a_(a), mode_(a.sub ? 19u : 0u) {
    for (const std::string& f : a.defaults)
      read_params(f, fs_gcs_enable_, fs_gcs_timeout_, spec_grav_);
    std::ofstream("eeprom.bin", std::ios::binary) << std::string(16384, '\0');
  }

  int run() {
    const int listen_fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    ::setsockopt(listen_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(a_.mavlink_port));
    if (::bind(listen_fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listen_fd, 1) != 0)
      fail("cannot listen on TCP " + std::to_string(a_.mavlink_port));
    std::fprintf(stderr, "kelp-fake-ardupilot: %s -I%d waiting for a connection on TCP %d\n",
                 a_.sub ? "ardusub" : "ardurover", a_.instance, a_.mavlink_port);
    tcp_ = ::accept4(listen_fd, nullptr, nullptr, SOCK_CLOEXEC);
    ::close(listen_fd);
    if (tcp_ < 0) fail("accept failed");

    udp_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in physics{};
    physics.sin_family = AF_INET;
    physics.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    physics.sin_port = htons(static_cast<std::uint16_t>(a_.json_port));
    if (::connect(udp_, reinterpret_cast<sockaddr*>(&physics), sizeof physics) != 0)
      fail("cannot address UDP " + std::to_string(a_.json_port));

    for (std::uint32_t frame = 1;; ++frame) {
      const double t = exchange(frame);
      service_mavlink();
      step(t);
    }
  }

 private:
  // One physics frame: the servo packet, re-sent every second until a reply; returns the
  // reply's timestamp [s].
  double exchange(std::uint32_t frame) {
    std::array<std::uint8_t, 40> p{};
    const auto put16 = [&](std::size_t at, std::uint16_t v) {
      p[at] = static_cast<std::uint8_t>(v & 0xff);
      p[at + 1] = static_cast<std::uint8_t>(v >> 8);
    };
    put16(0, 18458);
    put16(2, 1200);
    for (int i = 0; i < 4; ++i) p[4 + i] = static_cast<std::uint8_t>(frame >> (8 * i));
    for (std::size_t c = 0; c < 16; ++c) put16(8 + 2 * c, 1500);
    for (;;) {
      (void)::send(udp_, p.data(), p.size(), 0);
      service_mavlink();  // keep the link alive while kelp-sitl waits for the other autopilot
      pollfd pf{udp_, POLLIN, 0};
      if (::poll(&pf, 1, 1000) != 1) continue;
      char buf[4096];
      const ssize_t n = ::recv(udp_, buf, sizeof buf, 0);
      if (n <= 0) continue;
      const auto j =
          nlohmann::json::parse(std::string(buf, static_cast<std::size_t>(n)), nullptr, false);
      if (j.is_discarded() || !j.contains("timestamp")) fail("reply without a timestamp");
      return j.at("timestamp").get<double>();
    }
  }

  void write(const std::vector<std::uint8_t>& b) {
    (void)::send(tcp_, b.data(), b.size(), MSG_NOSIGNAL);
  }
  template <class M>
  void send(const M& m) {
    write(out_.pack(m));
  }
  void text(const std::string& s) {
    mv::Statustext st;
    st.severity = 2;
    st.text = mv::to_chars<50>(s);
    send(st);
  }

  void service_mavlink() {
    for (;;) {
      pollfd pf{tcp_, POLLIN, 0};
      if (::poll(&pf, 1, 0) != 1) return;
      std::uint8_t buf[4096];
      const ssize_t n = ::recv(tcp_, buf, sizeof buf, 0);
      if (n <= 0) {  // the ground station left: go on (SITL does), the physics still needs us
        ::close(tcp_);
        tcp_ = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        return;
      }
      parser_.feed(buf, static_cast<std::size_t>(n), [&](const mv::Frame& f) { handle(f); });
    }
  }

  void handle(const mv::Frame& f) {
    if (auto hb = mv::decode<mv::Heartbeat>(f)) {
      if (hb->type == mv::kTypeGcs) last_gcs_ = t_;
    } else if (auto mc = mv::decode<mv::ManualControl>(f)) {
      manual_z_ = mc->z;
    } else if (auto c = mv::decode<mv::CommandLong>(f)) {
      mv::CommandAck ack;
      ack.command = c->command;
      ack.target_system = f.sysid;
      ack.target_component = f.compid;
      ack.result = static_cast<std::uint8_t>(mv::Result::Accepted);
      if (c->command == mv::kCmdComponentArmDisarm) {
        armed_ = c->param1 == 1.0f;
        if (armed_) failsafe_ = false;
      } else if (c->command == mv::kCmdDoSetMode) {
        mode_ = static_cast<std::uint32_t>(c->param2);
        have_target_ = false;
      } else {
        ack.result = static_cast<std::uint8_t>(mv::Result::Unsupported);
      }
      send(ack);
    } else if (auto lt = mv::decode<mv::SetPositionTargetLocalNed>(f)) {
      target_ = {lt->x, lt->y, lt->z};
      have_target_ = true;
    } else if (auto gt = mv::decode<mv::SetPositionTargetGlobalInt>(f)) {
      target_ = {(gt->lat_int * 1e-7 - a_.lat) / kDegPerM,
                 (gt->lon_int * 1e-7 - a_.lon) / kDegPerM * std::cos(a_.lat * kPi / 180.0), 0.0};
      have_target_ = true;
    }
  }

  void step(double t) {
    const double dt = std::max(0.0, t - t_);
    t_ = t;
    const std::uint32_t guided = a_.sub ? 4u : 15u;
    if (armed_ && a_.sub && mode_ == 2) z_ += 1.0 * dt * (500.0 - manual_z_) / 500.0;
    if (armed_ && mode_ == guided && have_target_) {
      const double dx = target_[0] - x_, dy = target_[1] - y_, d = std::hypot(dx, dy);
      const double move = std::min(d, 2.0 * dt);
      if (d > 1e-9) {
        x_ += dx / d * move;
        y_ += dy / d * move;
        yaw_ = std::atan2(dy, dx);
      }
      if (a_.sub) z_ += std::clamp(target_[2] / reading_per_metre() - z_, -dt, dt);
    }
    if (fs_gcs_enable_ != 0 && armed_ && !failsafe_ && last_gcs_ >= 0 &&
        t_ - last_gcs_ > fs_gcs_timeout_) {
      failsafe_ = true;
      mode_ = a_.sub ? 19u : 4u;
      text("GCS Failsafe");
    }
    if (t_ >= next_heartbeat_) {
      next_heartbeat_ = t_ + 1.0;
      mv::Heartbeat hb;
      hb.custom_mode = mode_;
      hb.type = a_.sub ? mv::kTypeSubmarine : mv::kTypeSurfaceBoat;
      hb.autopilot = mv::kAutopilotArdupilotmega;
      hb.base_mode = static_cast<std::uint8_t>(81 | (armed_ ? 128 : 0));
      hb.system_status = failsafe_ ? 5 : armed_ ? 4 : 3;
      send(hb);
    }
    if (t_ >= 1.0 && t_ >= next_state_) {
      next_state_ = t_ + 0.1;
      if (a_.sub) std::ofstream("true_depth.txt") << z_ << "\n";  // for the test
      const auto ms = static_cast<std::uint32_t>(std::lround(t_ * 1000.0));
      mv::SystemTime st;
      st.time_boot_ms = ms;
      send(st);
      mv::Attitude att;
      att.time_boot_ms = ms;
      att.yaw = static_cast<float>(yaw_);
      send(att);
      mv::LocalPositionNed lp;
      lp.time_boot_ms = ms;
      lp.x = static_cast<float>(x_);
      lp.y = static_cast<float>(y_);
      lp.z = static_cast<float>(depth_reading());
      send(lp);
      mv::GlobalPositionInt gp;
      gp.time_boot_ms = ms;
      gp.lat = static_cast<std::int32_t>(std::lround((a_.lat + x_ * kDegPerM) * 1e7));
      gp.lon = static_cast<std::int32_t>(
          std::lround((a_.lon + y_ * kDegPerM / std::cos(a_.lat * kPi / 180.0)) * 1e7));
      gp.alt = gp.relative_alt = static_cast<std::int32_t>(-depth_reading() * 1000.0);
      gp.hdg = 65535;
      send(gp);
    }
  }

  Args a_;
  int tcp_ = -1, udp_ = -1;
  mv::Parser parser_;
  mv::Sender out_{1, mv::kCompAutopilot1};
  double fs_gcs_enable_ = 0, fs_gcs_timeout_ = 5;
  double spec_grav_ = 1.0;  // BARO_SPEC_GRAV, ArduSub's default 1

  // The depth as ArduSub reads it from SITL's pressure: SITL's water is 1024 kg/m^3 under
  // 9.80665 m/s^2 (AP_Baro::SimpleUnderWaterAtmosphere, AP_Baro_HIL.cpp), ArduSub divides the
  // pressure by 9800 Pa/m x BARO_SPEC_GRAV (AP_Baro.cpp): 2.5 % deep unless the parameter
  // file sets the specific gravity. z_ is the true depth (the kinematics).
  double reading_per_metre() const { return 1024.0 * 9.80665 / (9800.0 * spec_grav_); }
  double depth_reading() const { return z_ * reading_per_metre(); }
  double t_ = 0, next_heartbeat_ = 0, next_state_ = 0, last_gcs_ = -1;
  std::uint32_t mode_;
  bool armed_ = false, failsafe_ = false, have_target_ = false;
  std::int16_t manual_z_ = 500;
  double x_ = 0, y_ = 0, z_ = 0, yaw_ = 0;
  std::array<double, 3> target_{};
};

}  // namespace

int main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  Fake fake(a);
  return fake.run();
}
