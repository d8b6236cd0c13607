// kelp-sitl: kelp as the physics of two ArduPilot SITL instances over their JSON interface,
// ArduSub (-I0, BlueROV2 Heavy) on UDP 9002 and ArduRover (-I1, BlueBoat) on UDP 9012, stepping
// the tethered system of a kelp-tethered-pair scenario in lockstep with both (bridge.hpp says
// how). Logs timeseries.csv and nodes.csv in kelp-tethered-pair's format (plot_run.py plots
// them), events.log, summary.json with the per-port counters and the 3-D replay (replay.html)
// when it stops.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bridge.hpp"
#include "common/replay_template.hpp"
#include "default_world.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/stop.hpp"
#include "kelp/sim/summary.hpp"
#include "kelp/sim/turn_counter.hpp"
#include "kelp/sim/world.hpp"
#include "kelp/version.hpp"

namespace fs = std::filesystem;
namespace ks = kelp::system;

namespace {

struct Options {
  kelp::sim::Scenario scenario = kelp_sitl::default_scenario();
  std::string scenario_file = "(embedded default)";
  std::string bind = "127.0.0.1";
  int sub_port = 9002, rover_port = 9012;
  std::string log = "kelp-sitl-run";
  double log_rate = -1, node_rate = -1;  // < 0: the scenario's
  kelp_sitl::BridgeSettings bridge;
  std::string start = "both";
  double duration = 0;  // physics seconds; 0: until interrupted
  double status_interval = 10;
  bool quiet = false;
  int mcap = -1;  // run.mcap: 1 on, 0 off, -1 the scenario's output.mcap
};

// A UDP socket bound to address:port; throws with the reason.
class UdpSocket {
 public:
  UdpSocket(const std::string& address, int port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    if (inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1)
      throw std::runtime_error("--bind: '" + address + "' is not an IPv4 address");
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    if (fd_ < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      const std::string why = std::strerror(errno);
      ::close(fd_);
      throw std::runtime_error("cannot bind UDP " + address + ":" + std::to_string(port) + ": " +
                               why);
    }
  }
  ~UdpSocket() { ::close(fd_); }
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  int fd() const { return fd_; }

  // Receives one datagram; returns its real size (which may exceed `cap`: then it was cut and
  // is malformed anyway), or -1 when nothing is waiting.
  long receive(std::uint8_t* buf, std::size_t cap, kelp_sitl::Endpoint& from) {
    sockaddr_in a{};
    socklen_t len = sizeof a;
    const ssize_t n =
        ::recvfrom(fd_, buf, cap, MSG_TRUNC | MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&a), &len);
    if (n < 0) return -1;
    from.address = a.sin_addr.s_addr;
    from.port = ntohs(a.sin_port);
    return static_cast<long>(n);
  }
  void send(const kelp_sitl::Endpoint& to, const char* data, std::size_t n) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = to.address;
    a.sin_port = htons(to.port);
    ::sendto(fd_, data, n, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }

 private:
  int fd_ = -1;
};

double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

nlohmann::json counters_json(const kelp_sitl::PeerCounters& c, int port, bool joined) {
  return {{"port", port},
          {"joined", joined},
          {"packets", c.packets},
          {"frames", c.frames},
          {"repeats", c.repeats},
          {"waiting_resends", c.waiting_resends},
          {"restarts", c.restarts},
          {"missed_frames", c.missed_frames},
          {"malformed", c.malformed},
          {"malformed_size", c.malformed_size},
          {"malformed_magic", c.malformed_magic},
          {"pwm_out_of_range", c.pwm_out_of_range},
          {"timeouts", c.timeouts},
          {"withheld", c.withheld},
          {"frame_rate_min", c.frame_rate_min},
          {"frame_rate_max", c.frame_rate_max}};
}

int run(const Options& o) {
  const kelp::sim::WorldSetup setup = kelp::sim::world_setup(o.scenario, o.scenario_file);
  const ks::SystemModeld model(setup.parameters, setup.environment);
  ks::SystemWorkspaced ws(model);
  kelp_sitl::BridgeSettings settings = o.bridge;
  settings.start_together = o.start == "both";
  kelp_sitl::Bridge bridge(model, ws, kelp::sim::start_state(model, ws, setup, o.scenario),
                           setup.start, settings);

  UdpSocket sub(o.bind, o.sub_port), rover(o.bind, o.rover_port);
  fs::create_directories(o.log);
  kelp::sim::RunLog log(o.log);
  std::ofstream events(fs::path(o.log) / "events.log");
  // The run as a ROS 2 bag (run.mcap), the markers at the node rate.
  const bool mcap = o.mcap >= 0 ? o.mcap != 0 : o.scenario.mcap;
  std::unique_ptr<kelp::sim::BagRecorder> bag;
  const double wall0 = wall_now();
  bridge.on_event = [&](const std::string& s) {
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "[wall %8.3f s] ", wall_now() - wall0);
    events << stamp << s << '\n' << std::flush;
    if (!o.quiet) std::fprintf(stderr, "kelp-sitl: %s\n", s.c_str());
  };
  std::fprintf(stderr,
               "kelp-sitl: serving ArduSub on udp %s:%d and ArduRover on udp %s:%d, %.0f Hz "
               "physics, start: %s; logs in %s\n",
               o.bind.c_str(), o.sub_port, o.bind.c_str(), o.rover_port, settings.rate,
               settings.start_together ? "when both have sent a packet" : "with the first",
               o.log.c_str());

  const double log_rate = o.log_rate > 0 ? o.log_rate : o.scenario.log_rate;
  const double node_rate = o.node_rate > 0 ? o.node_rate : o.scenario.node_rate;
  if (mcap) bag = std::make_unique<kelp::sim::BagRecorder>(fs::path(o.log) / "run.mcap", node_rate);
  double next_log = 0, next_nodes = 0, next_status = wall0 + o.status_interval;
  // The ROV's turns about the tether and the line's partings, at every step (as kelp::sim's
  // ClosedLoop keeps them).
  kelp::sim::TurnCounter turns;
  std::vector<kelp::tether::LineFailured> failures;
  const auto log_state = [&]() {
    const ks::SystemStated& s = bridge.state();
    const double t = s.time;
    turns.update(s.auv, s.tether, int(s.tether.position.cols()) - 1);
    if (bridge.last_report().tether.partings > 0) {
      failures.push_back(bridge.last_report().tether.failure);
      log.line_parted(failures.back());
    }
    if (t + 1e-9 >= next_log) {
      kelp::sim::LogRow row;
      row.t = t;
      row.asv = &s.asv;
      row.auv = &s.auv;
      row.asv_error = (s.asv.position - s.auv.position).head<2>().norm();
      row.asv_thrust = bridge.asv_thrust();
      row.asv_command = bridge.asv_command();
      row.auv_thrust = bridge.auv_thrust();
      row.auv_command = bridge.auv_command();
      row.tension_asv = bridge.last_report().force_on_asv.norm();
      row.tension_auv = bridge.last_report().force_on_auv.norm();
      row.tether_turns = turns.turns();
      row.parted_segments = s.tether.parted_segments();
      row.force_on_asv = bridge.last_report().force_on_asv;
      row.force_on_auv = bridge.last_report().force_on_auv;
      row.auv_nu_dot = s.auv_nu_dot;
      row.gravity = bridge.model().environment().gravity();
      row.tether_model = &bridge.model().tether_of(s);
      row.tether = &s.tether;
      // Propulsion: thrust as delivered (lagged), currents, batteries.
      if (const auto* pm = bridge.model().asv_propulsion()) {
        row.asv_thrust = s.asv_propulsion.thrust.head<2>();
        row.asv_current = s.asv_propulsion.current.head<2>();
        row.asv_voltage = s.asv_propulsion.battery.voltage;
        row.asv_soc =
            kelp::vehicle::state_of_charge(pm->parameters().battery, s.asv_propulsion.battery);
      }
      if (const auto* pm = bridge.model().auv_propulsion()) {
        row.auv_thrust = s.auv_propulsion.thrust.head<8>();
        row.auv_current = s.auv_propulsion.current.head<8>();
        row.auv_voltage = s.auv_propulsion.battery.voltage;
        row.auv_soc =
            kelp::vehicle::state_of_charge(pm->parameters().battery, s.auv_propulsion.battery);
      }
      log.row(row);
      if (bag) bag->record(row);
      next_log = t + 1.0 / log_rate;
    }
    if (t + 1e-9 >= next_nodes) {
      log.nodes(t, bridge.model().tether_of(s), s.tether);
      next_nodes = t + 1.0 / node_rate;
    }
  };
  log_state();

  std::array<UdpSocket*, 2> sockets{&sub, &rover};
  std::array<std::uint8_t, 2048> buf{};
  kelp_sitl::Outbox out;
  // Each reply leaves from the port of the autopilot it answers.
  const auto send_all = [&] {
    for (int i = 0; i < out.count; ++i) {
      const kelp_sitl::Outgoing& g = out.items[static_cast<std::size_t>(i)];
      sockets[static_cast<std::size_t>(g.slot)]->send(g.to, g.data, g.size);
    }
  };
  pollfd fds[2] = {{sub.fd(), POLLIN, 0}, {rover.fd(), POLLIN, 0}};
  std::uint64_t logged_steps = 0;
  bool done = false;
  // SIGINT or SIGTERM (kelp/sim/stop.hpp, installed in main) ends the loop between two frames.
  while (!kelp::sim::stop_requested() && !done) {
    const int ready = ::poll(fds, 2, 100);
    if (ready < 0 && errno != EINTR)
      throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
    const double now = wall_now();
    for (int s = 0; s < 2; ++s) {
      // Drain the socket: every datagram gets its answer in arrival order.
      for (;;) {
        kelp_sitl::Endpoint from;
        const long n = sockets[static_cast<std::size_t>(s)]->receive(buf.data(), buf.size(), from);
        if (n < 0) break;
        out.clear();
        bridge.receive(s, buf.data(), static_cast<std::size_t>(n), from, now, out);
        send_all();
        if (bridge.steps() != logged_steps) {
          logged_steps = bridge.steps();
          log_state();
          if (o.duration > 0 && bridge.state().time >= o.duration - 1e-9) done = true;
        }
      }
    }
    out.clear();
    bridge.check_timeouts(now, out);
    send_all();
    if (now >= next_status) {
      next_status = now + o.status_interval;
      log.flush();
      if (!o.quiet)
        std::fprintf(stderr,
                     "kelp-sitl: physics %.1f s (%.1fx real time), frames sub %llu rover %llu, "
                     "malformed sub %llu rover %llu\n",
                     bridge.state().time, bridge.state().time / (now - wall0),
                     static_cast<unsigned long long>(bridge.counters(0).frames),
                     static_cast<unsigned long long>(bridge.counters(1).frames),
                     static_cast<unsigned long long>(bridge.counters(0).malformed),
                     static_cast<unsigned long long>(bridge.counters(1).malformed));
    }
  }
  log.close();
  if (bag) bag->close();
  const double wall = wall_now() - wall0;
  // Completed: stopped at --duration, or by a signal when no duration was asked (kelp-sitl's
  // usual end); a signal before --duration leaves an interrupted run (kelp/sim/stop.hpp).
  const bool completed = done || o.duration <= 0;
  nlohmann::json summary;
  summary["kelp_version"] = KELP_VERSION_STRING;
  summary["completed"] = completed;
  summary["simulated_s"] = bridge.state().time;
  summary["physics_s"] = bridge.state().time;
  summary["wall_s"] = wall;
  summary["steps"] = bridge.steps();
  summary["rate_hz"] = settings.rate;
  summary["bind"] = o.bind;
  summary["ardusub"] = counters_json(bridge.counters(0), o.sub_port, bridge.joined(0));
  summary["ardurover"] = counters_json(bridge.counters(1), o.rover_port, bridge.joined(1));
  // The wave kernel's instruction path and the C library's math (kelp/core/kernel_path.hpp).
  summary["kernel"] = kelp::simd::kernel_name(model.environment().waves().active_kernel());
  summary["math_library"] = kelp::simd::math_library_fingerprint();
  summary["tether_solver"] = nlohmann::json::parse(kelp::sim::solver_summary_json(
      kelp::sim::solver_summary(bridge.solver_stats(), bridge.model().parameters())));
  // Propulsion: the energy each battery delivered [Wh] and its final state of charge.
  const auto battery = [&](const kelp::vehicle::PropulsionModeld* pm,
                           const kelp::vehicle::PropulsionStated& x) {
    nlohmann::json b;
    if (pm == nullptr) return b;
    b["energy_wh"] = x.battery.energy_drawn / 3600.0;
    b["final_soc"] = kelp::vehicle::state_of_charge(pm->parameters().battery, x.battery);
    return b;
  };
  if (bridge.model().auv_propulsion() != nullptr)
    summary["auv_battery"] =
        battery(bridge.model().auv_propulsion(), bridge.state().auv_propulsion);
  if (bridge.model().asv_propulsion() != nullptr)
    summary["asv_battery"] =
        battery(bridge.model().asv_propulsion(), bridge.state().asv_propulsion);
  summary["tether"] = {{"net_turns", turns.turns()}, {"max_abs_turns", turns.max_abs_turns()}};
  summary["tether"]["line_failures"] = nlohmann::json::array();
  for (const auto& f : failures)
    summary["tether"]["line_failures"].push_back(
        {{"time_s", f.time},
         {"segment", f.segment},
         {"position_m", {f.position.x(), f.position.y(), f.position.z()}},
         {"tension_n", f.tension}});
  summary["scenario_file"] = o.scenario_file;
  summary["scenario"] = nlohmann::json::parse(kelp::sim::scenario_json(o.scenario));
  kelp::sim::write_file_atomically(fs::path(o.log) / "summary.json", summary.dump(2) + '\n');
  // The 3-D replay (docs/replay.md): without the page's template (kelp built without three.js)
  // the run is still complete; a replay that cannot be made is reported, not fatal.
  const std::string replay_template = kelp_apps::find_replay_template(KELP_REPLAY_TEMPLATE_BUILD);
  if (replay_template.empty()) {
    std::fprintf(stderr, "kelp-sitl: no replay.html: %s\n",
                 kelp_apps::replay_template_missing_note().c_str());
  } else {
    try {
      kelp::sim::ReplayOptions ro;
      ro.source = "kelp-sitl";
      kelp::sim::write_replay(o.log, replay_template, ro);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "kelp-sitl: no replay.html: %s\n", e.what());
    }
  }
  std::fprintf(stderr,
               "kelp-sitl: stopped after %.2f s of physics (%llu steps) in %.1f s; malformed "
               "packets: ArduSub %llu, ArduRover %llu; summary in %s/summary.json\n",
               bridge.state().time, static_cast<unsigned long long>(bridge.steps()), wall,
               static_cast<unsigned long long>(bridge.counters(0).malformed),
               static_cast<unsigned long long>(bridge.counters(1).malformed), o.log.c_str());
  if (!completed) {
    std::fprintf(stderr, "kelp-sitl: stopped by %s before --duration %g s (\"completed\": false)\n",
                 kelp::sim::stop_signal() == SIGTERM ? "SIGTERM" : "SIGINT", o.duration);
    return kelp::sim::interrupted_exit_status();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "kelp-sitl: kelp's tethered BlueBoat + BlueROV2 Heavy as the physics of ArduPilot SITL "
      "(ArduSub -I0 and ArduRover -I1, --model JSON), in lockstep"};
  std::string file;
  app.add_option("--scenario", file,
                 "scenario file (kelp-tethered-pair's schema: sea, tether, start; the mission "
                 "and controller fields are not used)");
  app.add_option("--bind", o.bind, "IPv4 address to listen on")->capture_default_str();
  app.add_option("--sub-port", o.sub_port, "ArduSub's JSON port (9002 + 10 x instance)")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  app.add_option("--rover-port", o.rover_port, "ArduRover's JSON port")
      ->check(CLI::Range(1, 65535))
      ->capture_default_str();
  app.add_option("--log", o.log, "output directory")->capture_default_str();
  app.add_option("--log-rate", o.log_rate,
                 "timeseries.csv rows per physics second (default: the scenario's)")
      ->check(CLI::Range(1e-3, 1e4));
  app.add_option("--node-rate", o.node_rate,
                 "nodes.csv snapshots per physics second (default: the scenario's)")
      ->check(CLI::Range(1e-3, 1e4));
  app.add_option("--rate", o.bridge.rate, "physics frames per second (SITL's SIM_RATE_HZ is 1200)")
      ->check(CLI::Range(10.0, 10000.0))
      ->capture_default_str();
  app.add_option("--start", o.start,
                 "both: no physics until both autopilots have sent a packet; any: start with the "
                 "first (the other vehicle drifts, thrusters off, until its autopilot joins)")
      ->check(CLI::IsMember({"both", "any"}))
      ->capture_default_str();
  app.add_option("--peer-timeout", o.bridge.peer_timeout,
                 "wall seconds of silence after which an autopilot leaves the lockstep")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  app.add_option("--duration", o.duration,
                 "stop after this much physics time [s] (0: run until interrupted)")
      ->check(CLI::Range(0.0, 1e7));
  app.add_option("--status-interval", o.status_interval, "wall seconds between status lines")
      ->check(CLI::Range(0.1, 1e6));
  bool with_mcap = false, no_mcap = false;
  app.add_flag("--mcap", with_mcap,
               "write run.mcap, the run as a ROS 2 bag (the default; the scenario's output.mcap)");
  app.add_flag("--no-mcap", no_mcap, "do not write run.mcap");
  app.add_flag("--quiet", o.quiet,
               "no status lines or events on stderr (events.log still has them)");
  CLI11_PARSE(app, argc, argv);
  if (with_mcap || no_mcap) o.mcap = with_mcap && !no_mcap ? 1 : 0;
  try {
    kelp::simd::kernel_policy();  // a bad KELP_KERNEL stops here, named
  } catch (const kelp::invalid_argument& e) {
    std::fprintf(stderr, "kelp-sitl: %s\n", e.what());
    return 3;
  }
  try {
    if (!file.empty()) {
      o.scenario = kelp::sim::load_scenario(file);
      o.scenario_file = file;
    }
    // SIGINT and SIGTERM stop the lockstep after the frame they land in, the files whole; a
    // second one at once.
    kelp::sim::install_stop_handlers();
    return run(o);
  } catch (const kelp::sim::scenario_error& e) {
    std::fprintf(stderr, "kelp-sitl: invalid scenario: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kelp-sitl: %s\n", e.what());
    return 1;
  }
}
