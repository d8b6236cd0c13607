// The lockstep bridge between two ArduPilot SITL instances and one kelp system: ArduSub flies the
// BlueROV2 Heavy (the system's AUV), ArduRover the BlueBoat (its ASV). No sockets here: the
// program (main.cpp) hands each datagram to Bridge::receive() and sends what it returns, so the
// whole protocol logic is testable in-process.
//
// Lockstep, one clock (see the README's "Run with ArduPilot SITL" for the user's view):
// - Each servo packet with a new frame_count asks for one physics frame. The world advances by
//   one fixed step h = 1/rate only when every *active* autopilot has asked; then each of them
//   gets its reply, stamped with the one physics time. Both SITL clocks therefore advance by
//   the same h per frame (SITL derives its frame time from the timestamps, so its frame_rate
//   follows 1/h whatever it starts at; the packets' own frame_rate is recorded, not used).
// - Start: with `start_together` (the default) nothing moves until both autopilots have sent a
//   packet; the first one waits unanswered (SITL re-sends every ~1 s meanwhile). Without it the
//   world starts with the first autopilot; the other vehicle is in the world with its thrusters
//   off until its autopilot joins, at the current physics time (its SITL clock starts there).
//   Every such event is logged.
// - A re-sent frame (same frame_count) gets the same reply again, byte for byte, without a
//   step; while its frame is still waiting for the other autopilot it gets nothing yet.
// - A frame_count below the last one means that SITL restarted: that vehicle is put back at its
//   start pose at rest (or, if the tether cannot reach that far from where the other vehicle is
//   now, at its start depth and attitude but moved horizontally to keep the start's offset from
//   the other vehicle), the tether is laid again statically between the two, and the other
//   vehicle keeps its state. Logged.
// - An autopilot silent for `peer_timeout` wall seconds (while the bridge is not holding a frame
//   of its: then it is waiting on the bridge, and real SITL re-sends every ~1 s) leaves the
//   lockstep (logged): the world goes on with the other one and the silent vehicle's thrusters off.
//   When it sends again it rejoins (as a restart if its frame_count went back).
// - Malformed datagrams (size, magic) are counted per port and dropped.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

#include "kelp/system/presets.hpp"
#include "kelp/system/solver_stats.hpp"
#include "kelp/system/system.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"
#include "protocol.hpp"

namespace kelp_sitl {

namespace ks = kelp::system;
namespace kv = kelp::vehicle;

/// The two autopilots.
enum Slot : int { sub = 0, rover = 1 };
inline const char* slot_name(int s) { return s == sub ? "ArduSub" : "ArduRover"; }

/// Where a packet came from (IPv4 address and port as the socket layer gives them).
struct Endpoint {
  std::uint32_t address = 0;
  std::uint16_t port = 0;
  bool operator==(const Endpoint& o) const { return address == o.address && port == o.port; }
  bool operator!=(const Endpoint& o) const { return !(*this == o); }
};

struct BridgeSettings {
  double rate = 1200.0;        ///< physics frames per simulated second (h = 1/rate)
  bool start_together = true;  ///< wait for both autopilots before the first step
  double peer_timeout = 5.0;   ///< wall seconds of silence after which an autopilot leaves
};

/// What happened on one autopilot's port.
struct PeerCounters {
  std::uint64_t packets = 0;          ///< valid servo packets
  std::uint64_t frames = 0;           ///< new frames answered after a step
  std::uint64_t repeats = 0;          ///< re-sent frames answered again without a step
  std::uint64_t waiting_resends = 0;  ///< re-sent frames still waiting for the other autopilot
  std::uint64_t restarts = 0;         ///< frame_count went back
  std::uint64_t missed_frames = 0;    ///< frame_count jumped ahead by more than 1
  std::uint64_t malformed = 0;        ///< datagrams that are not servo packets (all reasons)
  std::uint64_t malformed_size = 0, malformed_magic = 0;  ///< ... by reason
  std::uint64_t pwm_out_of_range = 0;  ///< thruster channels outside 800–2200 µs (taken as off)
  std::uint64_t timeouts = 0;          ///< times it left the lockstep after silence
  std::uint64_t withheld = 0;          ///< replies not sent because a value was not finite
  std::uint16_t frame_rate_min = 0, frame_rate_max = 0;  ///< the packets' frame_rate field
};

/// A datagram to send.
struct Outgoing {
  int slot = 0;
  Endpoint to;
  const char* data = nullptr;
  std::size_t size = 0;
};

/// The replies produced by one call (at most one per autopilot).
struct Outbox {
  std::array<Outgoing, 2> items;
  int count = 0;
  void clear() { count = 0; }
  void push(const Outgoing& o) { items[static_cast<std::size_t>(count++)] = o; }
};

class Bridge {
 public:
  /// `model` and `ws` must outlive the bridge; `start` is where the vehicles begin (and where a
  /// restarted one is put back); `initial` is the system's state at the start.
  Bridge(const ks::SystemModeld& model, ks::SystemWorkspaced& ws, ks::SystemStated initial,
         const ks::presets::StartPoses<double>& start, const BridgeSettings& settings)
      : model_(model),
        ws_(ws),
        state_(std::move(initial)),
        start_(start),
        settings_(settings),
        rov_(kv::bluerov2_heavy<double>(model.environment().water_density(),
                                        model.environment().gravity())),
        boat_(kv::blueboat<double>(model.environment().water_density(),
                                   model.environment().gravity())),
        rov_chain_(kv::ThrusterAllocationd(rov_.thruster_positions, rov_.thruster_directions),
                   kv::t200_model, rov_.pwm, rov_.thruster_facing),
        boat_chain_(kv::ThrusterAllocationd(boat_.thruster_positions, boat_.thruster_directions),
                    kv::t200_model, boat_.pwm, boat_.thruster_facing) {
    kelp::check_positive(settings.rate, "rate");
    kelp::check_positive(settings.peer_timeout, "peer_timeout");
    auv_force_.setZero();
    asv_force_.setZero();
    auv_command_.setZero();
    asv_command_.setZero();
  }

  /// Called with one line for each event (joins, restarts, time-outs); default: stderr.
  std::function<void(const std::string&)> on_event = [](const std::string& s) {
    std::fprintf(stderr, "kelp-sitl: %s\n", s.c_str());
  };

  /// Handles one datagram from autopilot `slot` received at wall time `wall` [s] (any monotonic
  /// clock); appends the replies to send to `out`.
  void receive(int slot, const std::uint8_t* data, std::size_t n, const Endpoint& from, double wall,
               Outbox& out) {
    Peer& p = peers_[static_cast<std::size_t>(slot)];
    ServoPacket pkt;
    const PacketError e = parse_servo_packet(data, n, pkt);
    if (e != PacketError::none) {
      ++p.counters.malformed;
      if (e == PacketError::size)
        ++p.counters.malformed_size;
      else
        ++p.counters.malformed_magic;
      return;
    }
    ++p.counters.packets;
    p.last_heard = wall;
    if (p.counters.frame_rate_min == 0 || pkt.frame_rate < p.counters.frame_rate_min)
      p.counters.frame_rate_min = pkt.frame_rate;
    p.counters.frame_rate_max = std::max(p.counters.frame_rate_max, pkt.frame_rate);
    if (p.active && from != p.endpoint)
      event(std::string(slot_name(slot)) + ": packets now come from another port (" +
            std::to_string(from.port) + ")");
    p.endpoint = from;

    if (!p.joined) {
      p.joined = p.active = true;
      p.frame = pkt.frame_count;
      p.pending = true;
      set_pwm(slot, pkt);
      event(std::string(slot_name(slot)) + " joined at physics time " + time_string() + " (frame " +
            std::to_string(pkt.frame_count) + ", " + std::to_string(pkt.channels) + " channels)");
    } else if (!p.active) {
      p.active = true;
      event(std::string(slot_name(slot)) + " is back after a silence, at physics time " +
            time_string());
      if (pkt.frame_count < p.frame) {
        restart(slot, pkt);
      } else if (pkt.frame_count == p.frame && p.reply_size > 0) {
        ++p.counters.repeats;  // the frame it last got an answer for: the same answer
        out.push({slot, from, p.reply.data(), p.reply_size});
        return;
      } else {
        accept_frame(p, slot, pkt);
      }
    } else if (pkt.frame_count == p.frame) {
      if (p.pending) {
        ++p.counters.waiting_resends;
        set_pwm(slot, pkt);
      } else {
        ++p.counters.repeats;
        if (p.reply_size > 0) out.push({slot, from, p.reply.data(), p.reply_size});
        return;
      }
    } else if (pkt.frame_count < p.frame) {
      restart(slot, pkt);
    } else {
      accept_frame(p, slot, pkt);
    }
    advance(out);
  }

  /// Takes autopilots that stayed silent for `peer_timeout` out of the lockstep (then the other
  /// one may proceed: its replies are appended to `out`). Call it regularly.
  void check_timeouts(double wall, Outbox& out) {
    for (int s = 0; s < 2; ++s) {
      Peer& p = peers_[static_cast<std::size_t>(s)];
      // An autopilot whose frame waits for the other one is waiting on us, not silent.
      if (p.active && !p.pending && wall - p.last_heard > settings_.peer_timeout) {
        p.active = false;
        p.pending = false;
        ++p.counters.timeouts;
        if (s == sub)
          auv_force_.setZero(), auv_command_.setZero();
        else
          asv_force_.setZero(), asv_command_.setZero();
        event(std::string(slot_name(s)) + " silent for " + std::to_string(settings_.peer_timeout) +
              " s: it leaves the lockstep at physics time " + time_string() +
              " (its thrusters off until it comes back)");
      }
    }
    advance(out);
  }

  const ks::SystemModeld& model() const { return model_; }
  const ks::SystemStated& state() const { return state_; }
  const ks::SystemReportd& last_report() const { return report_; }
  /// How hard the tether's solver has worked over every physics step so far.
  const ks::SolverStatsd& solver_stats() const { return solver_stats_; }
  const PeerCounters& counters(int slot) const {
    return peers_[static_cast<std::size_t>(slot)].counters;
  }
  bool joined(int slot) const { return peers_[static_cast<std::size_t>(slot)].joined; }
  bool active(int slot) const { return peers_[static_cast<std::size_t>(slot)].active; }
  std::uint64_t steps() const { return steps_; }
  /// Thrust per thruster [N] and normalised command from the last PWM, motor order.
  const Eigen::Matrix<double, 8, 1>& auv_thrust() const { return auv_force_; }
  const Eigen::Matrix<double, 8, 1>& auv_command() const { return auv_command_; }
  const Eigen::Vector2d& asv_thrust() const { return asv_force_; }
  const Eigen::Vector2d& asv_command() const { return asv_command_; }

  /// The reply SITL gets for a vehicle in the current state.
  VehicleReply reply_of(int slot) const {
    const bool is_sub = slot == sub;
    const kv::VehicleStated& x = is_sub ? state_.auv : state_.asv;
    const kelp::Vector6<double>& nu_dot = is_sub ? state_.auv_nu_dot : state_.asv_nu_dot;
    VehicleReply r;
    r.timestamp = state_.time;
    const kelp::Vector3<double> v = x.nu.head<3>(), w = x.nu.tail<3>();
    r.gyro = w;
    // Specific force: the acceleration of the body origin relative to NED, in body axes
    // (v̇ + ω × v), minus gravity; at rest and level (0, 0, −g).
    const kelp::Vector3<double> g(0, 0, model_.environment().gravity());
    r.accel_body = nu_dot.head<3>() + w.cross(v) - x.attitude.conjugate() * g;
    r.position = x.position;
    r.velocity = x.attitude * v;
    r.attitude = x.attitude;
    if (is_sub && std::isfinite(model_.environment().seabed_depth()))
      r.rangefinder = std::max(0.0, model_.environment().seabed_depth() - x.position.z());
    // The battery's terminal voltage and current over the last step (ArduPilot's JSON backend
    // takes them as "battery": {"voltage", "current"}: libraries/SITL/SIM_JSON.h keytable, since
    // master ab03dc37, 2025-07-28; older builds ignore the key: README, "The battery").
    if (model_.auv_propulsion() != nullptr && is_sub) {
      r.battery_voltage = state_.auv_propulsion.battery.voltage;
      r.battery_current = state_.auv_propulsion.battery.current;
    }
    if (model_.asv_propulsion() != nullptr && !is_sub) {
      r.battery_voltage = state_.asv_propulsion.battery.voltage;
      r.battery_current = state_.asv_propulsion.battery.current;
    }
    return r;
  }

 private:
  struct Peer {
    bool joined = false, active = false, pending = false;
    std::uint32_t frame = 0;
    Endpoint endpoint;
    double last_heard = 0;
    std::array<char, max_reply_size> reply{};
    std::size_t reply_size = 0;
    PeerCounters counters;
  };

  void event(const std::string& s) {
    if (on_event) on_event(s);
  }
  std::string time_string() const {
    char b[32];
    std::snprintf(b, sizeof b, "%.4f s", state_.time);
    return b;
  }

  void accept_frame(Peer& p, int slot, const ServoPacket& pkt) {
    if (pkt.frame_count > p.frame + 1 && !p.pending)
      p.counters.missed_frames += pkt.frame_count - p.frame - 1;
    p.frame = pkt.frame_count;
    p.pending = true;
    set_pwm(slot, pkt);
  }

  // Thruster forces from the PWM: ArduSub's motors 1–8 on SERVO1–8 (vectored_6dof order, as the
  // BlueROV2 Heavy preset), ArduRover's skid steering ThrottleLeft on SERVO1 and ThrottleRight
  // on SERVO3 (ArduPilot Tools/autotest/default_params/rover-skid.parm). A channel without a
  // plausible pulse (0 = none, or outside 800–2200 µs) is taken as off.
  double thrust_of(std::uint16_t pwm, const kv::ThrusterChaind& chain, Eigen::Index i,
                   double& command, Peer& p) {
    command = 0;
    if (pwm == 0) return 0;
    if (pwm < 800 || pwm > 2200) {
      ++p.counters.pwm_out_of_range;
      return 0;
    }
    return chain.thrust_of_pwm(i, static_cast<double>(pwm), &command);
  }
  void set_pwm(int slot, const ServoPacket& pkt) {
    Peer& p = peers_[static_cast<std::size_t>(slot)];
    if (slot == sub) {
      for (int i = 0; i < 8; ++i)
        auv_force_(i) =
            thrust_of(pkt.pwm[static_cast<std::size_t>(i)], rov_chain_, i, auv_command_(i), p);
    } else {
      asv_force_(0) = thrust_of(pkt.pwm[0], boat_chain_, 0, asv_command_(0), p);
      asv_force_(1) = thrust_of(pkt.pwm[2], boat_chain_, 1, asv_command_(1), p);
    }
  }

  void restart(int slot, const ServoPacket& pkt) {
    Peer& p = peers_[static_cast<std::size_t>(slot)];
    ++p.counters.restarts;
    const bool is_sub = slot == sub;
    kv::VehicleStated fresh = is_sub ? start_.auv : start_.asv;
    const kv::VehicleStated& other = is_sub ? state_.asv : state_.auv;
    const auto& par = model_.parameters();
    const double reach = (fresh.point_position(is_sub ? par.auv_attachment : par.asv_attachment) -
                          other.point_position(is_sub ? par.asv_attachment : par.auv_attachment))
                             .norm();
    const char* where = "at its start pose";
    if (reach > 0.95 * model_.tether().parameters().length) {
      // Out of the tether's reach: the start pose moved horizontally so that it keeps the
      // start's offset from the other vehicle (a geometry the tether spans by construction).
      const kv::VehicleStated& other_start = is_sub ? start_.asv : start_.auv;
      fresh.position.head<2>() += other.position.head<2>() - other_start.position.head<2>();
      where = "at its start depth and attitude, at its start offset from the other vehicle";
    }
    try {
      ks::SystemStated s = ks::initial_state(model_, ws_, is_sub ? other : fresh,
                                             is_sub ? fresh : other, state_.time);
      state_ = std::move(s);
      state_.reset_coupling();
    } catch (const std::exception& e) {
      event(std::string(slot_name(slot)) + " restart: the tether could not be laid again (" +
            e.what() + "); the vehicle keeps its state");
      where = "nowhere (kept)";
    }
    p.frame = pkt.frame_count;
    p.pending = true;
    set_pwm(slot, pkt);
    event(std::string(slot_name(slot)) + " restarted (frame_count went back to " +
          std::to_string(pkt.frame_count) + ") at physics time " + time_string() +
          ": vehicle reset " + where + ", tether laid again, the other vehicle kept");
  }

  // One physics step when every active autopilot has asked for a frame; then their replies.
  void advance(Outbox& out) {
    int active = 0, joined = 0;
    for (const Peer& p : peers_) {
      joined += p.joined;
      if (!p.active) continue;
      ++active;
      if (!p.pending) return;
    }
    if (active == 0) return;
    if (settings_.start_together && steps_ == 0 && joined < 2) return;
    ks::SystemInputsd in;
    // A vehicle with propulsion in the system (the presets'): its autopilot's PWM commands drive
    // the thrusters (their lag, their current from the battery); else the static thrust's wrench.
    // An autopilot out of the lockstep: thrusters off (no commands, zero wrench).
    if (model_.auv_propulsion() != nullptr) {
      if (peers_[sub].active) in.auv_commands = auv_command_;
    } else if (peers_[sub].active) {
      in.auv.tau = rov_chain_.wrench(auv_force_);
    }
    if (model_.asv_propulsion() != nullptr) {
      if (peers_[rover].active) in.asv_commands = asv_command_;
    } else if (peers_[rover].active) {
      in.asv.tau = boat_chain_.wrench(asv_force_);
    }
    report_ = ks::step(model_, ws_, state_, in, 1.0 / settings_.rate);
    solver_stats_ += report_;
    ++steps_;
    for (int s = 0; s < 2; ++s) {
      Peer& p = peers_[static_cast<std::size_t>(s)];
      if (!p.active || !p.pending) continue;
      p.pending = false;
      ++p.counters.frames;
      p.reply_size = format_reply(reply_of(s), p.reply.data(), p.reply.size());
      if (p.reply_size == 0) {
        ++p.counters.withheld;
        event(std::string(slot_name(s)) + ": reply withheld, the state is not finite");
        continue;
      }
      out.push({s, p.endpoint, p.reply.data(), p.reply_size});
    }
  }

  const ks::SystemModeld& model_;
  ks::SystemWorkspaced& ws_;
  ks::SystemStated state_;
  ks::presets::StartPoses<double> start_;
  BridgeSettings settings_;
  kv::VehiclePresetd rov_, boat_;
  kv::ThrusterChaind rov_chain_, boat_chain_;  ///< PWM → command → thrust → wrench
  std::array<Peer, 2> peers_;
  ks::SystemReportd report_;
  ks::SolverStatsd solver_stats_;
  std::uint64_t steps_ = 0;
  Eigen::Matrix<double, 8, 1> auv_force_, auv_command_;
  Eigen::Vector2d asv_force_, asv_command_;
};

}  // namespace kelp_sitl
