// kelp-tethered-pair --ros2 over Eclipse Cyclone DDS 0.10 (its C API, dds/dds.h), with the types
// idlc generates from idl/. See bridge.hpp.
//
// ROS 2 on the wire (what makes kelp's topics ROS 2 topics to a ROS 2 node):
// - topic names: "rt" + the ROS name ("/rov/odom" → "rt/rov/odom"): ROS 2's topic prefix for
//   topics (ros2/design, "Topic and Service name mapping to DDS"; rmw_cyclonedds_cpp's
//   make_fqtopic with ros_topic_prefix "rt");
// - type names: "<pkg>::msg::dds_::<Type>_" (rmw_cyclonedds_cpp/src/rmw_node.cpp
//   create_type_name), which idlc takes from the IDL's modules (idl/*.idl);
// - data representation XCDR1 (plain CDR with the 4-byte encapsulation header), which
//   rmw_cyclonedds_cpp writes and every ROS 2 middleware reads;
// - QoS by kind of data, as rclcpp/tf2_ros set them (rclcpp/include/rclcpp/qos.hpp,
//   rmw/include/rmw/qos_profiles.h, tf2_ros/include/tf2_ros/qos.hpp):
//     sensor data (SensorDataQoS, rmw_qos_profile_sensor_data): best effort, volatile, keep last 5;
//     state and commands (QoS(10), rmw_qos_profile_default): reliable, volatile, keep last 10;
//     /tf (tf2_ros::DynamicBroadcasterQoS, what TransformBroadcaster uses): reliable, volatile,
//       keep last 100;
//     /clock (rclcpp::ClockQoS): best effort, volatile, keep last 1.
#include "bridge.hpp"

#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "builtin_interfaces.h"
#include "commands.hpp"
#include "geometry_msgs.h"
#include "kelp/core/error.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/stop.hpp"
#include "nav_msgs.h"
#include "publisher.hpp"
#include "rosgraph_msgs.h"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"
#include "visualization_msgs.h"

namespace kelp_ros2 {
namespace {

void check(dds_return_t rc, const std::string& what) {
  if (rc < 0) throw kelp::error("ROS 2 (Cyclone DDS): " + what + ": " + dds_strretcode(rc));
}

}  // namespace

dds_qos_t* make_qos(const kelp::ros2::Qos& qos) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_durability(q, qos.durability == kelp::ros2::Durability::transient_local
                             ? DDS_DURABILITY_TRANSIENT_LOCAL
                             : DDS_DURABILITY_VOLATILE);
  if (qos.reliability == kelp::ros2::Reliability::reliable)
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  else
    dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, qos.depth);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
  return q;
}

Participant::Participant(int domain) {
  if (domain < 0) {
    domain = 0;
    if (const char* env = std::getenv("ROS_DOMAIN_ID"); env && *env) {
      char* end = nullptr;
      const long d = std::strtol(env, &end, 10);
      if (*end != '\0' || d < 0 || d > 232)
        throw kelp::error("ROS_DOMAIN_ID must be a domain id in [0, 232], not \"" +
                          std::string(env) + "\"");
      domain = static_cast<int>(d);
    }
  }
  domain_ = domain;
  participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
  check(participant_, "cannot create a participant in domain " + std::to_string(domain));
}

Participant::~Participant() { dds_delete(participant_); }

dds_entity_t Participant::topic(const dds_topic_descriptor_t* type, const std::string& ros_name) {
  const std::string dds_name = "rt" + ros_name;
  const dds_entity_t t = dds_create_topic(participant_, type, dds_name.c_str(), nullptr, nullptr);
  check(t, "cannot create topic " + dds_name);
  return t;
}

dds_entity_t Participant::writer(const dds_topic_descriptor_t* type, const std::string& ros_name,
                                 const kelp::ros2::Qos& qos) {
  dds_qos_t* q = make_qos(qos);
  const dds_entity_t w = dds_create_writer(participant_, topic(type, ros_name), q, nullptr);
  dds_delete_qos(q);
  check(w, "cannot create a writer of " + ros_name);
  return w;
}

dds_entity_t Participant::reader(const dds_topic_descriptor_t* type, const std::string& ros_name,
                                 const kelp::ros2::Qos& qos) {
  dds_qos_t* q = make_qos(qos);
  const dds_entity_t r = dds_create_reader(participant_, topic(type, ros_name), q, nullptr);
  dds_delete_qos(q);
  check(r, "cannot create a reader of " + ros_name);
  return r;
}

void Participant::write(dds_entity_t writer, const void* sample, const char* what) {
  check(dds_write(writer, sample), std::string("cannot publish ") + what);
}

namespace {

using Clock = std::chrono::steady_clock;

// Takes every pending sample of a command reader (fixed-size types: no loans needed) and hands
// each valid one to `f`.
template <typename T, typename F>
void take_all(dds_entity_t reader, F&& f) {
  constexpr int batch = 16;
  T samples[batch];
  void* ptrs[batch];
  dds_sample_info_t infos[batch];
  for (int i = 0; i < batch; ++i) ptrs[i] = &samples[i];
  for (;;) {
    const dds_return_t n = dds_take(reader, ptrs, infos, batch, batch);
    check(n, "cannot take commands");
    for (int i = 0; i < n; ++i)
      if (infos[i].valid_data) f(samples[i]);
    if (n < batch) return;
  }
}

// The subscriptions: the commands a ROS 2 node flies the pair with, and /clock in lockstep.
class Subscriptions {
 public:
  Subscriptions(Participant& p, bool lockstep) {
    rov_wrench_ =
        p.reader(&geometry_msgs_msg_dds__Wrench__desc, "/rov/cmd_wrench", kelp::ros2::state_qos);
    rov_vel_ = p.reader(&geometry_msgs_msg_dds__Twist__desc, "/rov/cmd_vel", kelp::ros2::state_qos);
    boat_vel_ =
        p.reader(&geometry_msgs_msg_dds__Twist__desc, "/boat/cmd_vel", kelp::ros2::state_qos);
    payout_ =
        p.reader(&std_msgs_msg_dds__Float64__desc, "/tether/cmd_payout", kelp::ros2::state_qos);
    if (lockstep) {
      clock_ = p.reader(&rosgraph_msgs_msg_dds__Clock__desc, "/clock", kelp::ros2::clock_qos);
      waitset_ = dds_create_waitset(p.handle());
      check(waitset_, "cannot create a waitset");
      const dds_entity_t cond = dds_create_readcondition(clock_, DDS_ANY_STATE);
      check(cond, "cannot create a read condition");
      check(dds_waitset_attach(waitset_, cond, 0), "cannot wait for /clock");
    }
  }

  // Takes the commands that arrived and passes them to the commander.
  void take(PairCommander& c) {
    take_all<geometry_msgs_msg_dds__Wrench_>(rov_wrench_, [&](const auto& m) {
      const double f[3] = {m.force.x, m.force.y, m.force.z};
      const double t[3] = {m.torque.x, m.torque.y, m.torque.z};
      rov_wrench.count(c.rov_wrench(f, t));
    });
    take_all<geometry_msgs_msg_dds__Twist_>(rov_vel_, [&](const auto& m) {
      const double l[3] = {m.linear.x, m.linear.y, m.linear.z};
      const double a[3] = {m.angular.x, m.angular.y, m.angular.z};
      rov_velocity.count(c.rov_velocity(l, a));
    });
    take_all<geometry_msgs_msg_dds__Twist_>(boat_vel_, [&](const auto& m) {
      const double l[3] = {m.linear.x, m.linear.y, m.linear.z};
      const double a[3] = {m.angular.x, m.angular.y, m.angular.z};
      boat_velocity.count(c.boat_velocity(l, a));
    });
    take_all<std_msgs_msg_dds__Float64_>(payout_,
                                         [&](const auto& m) { payout.count(c.payout(m.data)); });
  }

  // Lockstep: waits up to `timeout` [s] for a /clock later than `target` and raises `target` to
  // the latest received. \returns false when none came.
  bool wait_clock(double& target, double timeout) {
    const auto until = Clock::now() + std::chrono::duration<double>(timeout);
    for (;;) {
      bool raised = false;
      take_all<rosgraph_msgs_msg_dds__Clock_>(clock_, [&](const auto& m) {
        ++clock_received;
        const double t = m.clock.sec + 1e-9 * m.clock.nanosec;
        if (!std::isfinite(t) || m.clock.nanosec >= 1000000000u) {
          ++clock_refused;
          return;
        }
        if (t > target) {
          target = t;
          raised = true;
        }
      });
      if (raised) return true;
      if (kelp::sim::stop_requested()) return false;  // a signal: the run stops (kelp/sim/stop.hpp)
      const double left = std::chrono::duration<double>(until - Clock::now()).count();
      if (left <= 0) return false;
      const dds_return_t rc =
          dds_waitset_wait(waitset_, nullptr, 0, DDS_SECS(std::min(left, 0.1)) + 1);
      check(rc, "cannot wait for /clock");
    }
  }

  SubscriptionCounters rov_wrench, rov_velocity, boat_velocity, payout;
  std::uint64_t clock_received = 0, clock_refused = 0;

 private:
  dds_entity_t rov_wrench_ = 0, rov_vel_ = 0, boat_vel_ = 0, payout_ = 0, clock_ = 0;
  dds_entity_t waitset_ = 0;
};

}  // namespace

kelp::sim::RunSummary run_with_ros2(const kelp::sim::Scenario& sc, const kelp::sim::RunOptions& run,
                                    const Ros2Options& o) {
  KELP_CHECK(std::isfinite(o.speed) && o.speed > 0, "--ros2 speed must be positive");
  KELP_CHECK(std::isfinite(o.clock_timeout) && o.clock_timeout > 0,
             "--ros2 clock timeout must be positive");
  const kelp::sim::WorldSetup setup = kelp::sim::world_setup(sc, run.scenario_file);
  std::unique_ptr<kelp::sim::RunLog> log;
  if (!run.out.empty()) log = std::make_unique<kelp::sim::RunLog>(run.out);
  kelp::sim::ClosedLoopOptions lo;
  lo.scenario_file = run.scenario_file;
  lo.log = log.get();
  lo.on_sample = run.on_sample;
  // The same files as every run: run.mcap (the scenario's output.mcap), and at the end
  // summary.json and replay.html (finish_run).
  std::unique_ptr<kelp::sim::RunBag> bag = kelp::sim::open_run_bag(sc, run, lo.on_sample);
  kelp::sim::ClosedLoop loop(sc, setup, lo);
  PairCommander commander(loop);

  Participant participant(o.domain);
  Publisher publisher(participant, !o.lockstep);
  Subscriptions subs(participant, o.lockstep);

  const double dt = kelp::sim::ClosedLoop::dt;
  const long log_every = std::max(1L, std::lround(1.0 / (sc.log_rate * dt)));
  const long node_every = std::max(1L, std::lround(1.0 / (sc.node_rate * dt)));
  publisher.publish(loop, true);  // t = 0
  const auto wall0 = Clock::now();
  double publish_s = 0, target = 0;
  long published_steps = 0;
  bool stopped = false;
  const auto stop = [&] {
    return kelp::sim::stop_requested() || (run.should_stop && run.should_stop());
  };
  while (!loop.done()) {
    // A stop (kelp/sim/stop.hpp): the run ends between two steps, its files whole.
    if (stop()) break;
    if (o.lockstep) {
      while (target < loop.time() + 0.5 * dt) {
        if (!subs.wait_clock(target, o.clock_timeout)) {
          stopped = true;
          break;
        }
      }
      if (stopped) break;
    }
    subs.take(commander);
    commander.apply();
    loop.step();
    const long k = loop.steps_taken();
    const auto p0 = Clock::now();
    if (!o.lockstep) publisher.clock(loop.time());
    if (k % log_every == 0) publisher.publish(loop, k % node_every == 0);
    publish_s += std::chrono::duration<double>(Clock::now() - p0).count();
    ++published_steps;
    if (!o.lockstep) {
      // Paced: in slices of at most 0.1 s, so that a slow --ros2-speed still stops at once.
      const auto until = wall0 + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(loop.time() / o.speed));
      while (Clock::now() < until && !stop())
        std::this_thread::sleep_until(
            std::min(until, Clock::now() + std::chrono::milliseconds(100)));
    }
  }
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();
  if (log) log->close();
  if (bag) bag->close();

  kelp::sim::RunSummary summary = loop.summary();
  summary.wall_s = wall;
  summary.realtime_factor = loop.time() / wall;
  if (!run.version.empty()) summary.kelp_version = run.version;
  nlohmann::json r;
  r["mode"] = o.lockstep ? "lockstep" : "paced";
  if (!o.lockstep) r["speed"] = o.speed;
  r["domain_id"] = participant.domain();
  r["simulated_s"] = loop.time();
  // lockstep: no /clock for clock_timeout before the end (a signal's stop is `completed`: false)
  r["stopped_early"] = stopped && !kelp::sim::stop_requested();
  r["published"] = publisher.counts();
  r["publish_us_per_step_mean"] =
      published_steps > 0 ? 1e6 * publish_s / double(published_steps) : 0.0;
  r["subscriptions"] = {{"/rov/cmd_wrench", subs.rov_wrench.to_json()},
                        {"/rov/cmd_vel", subs.rov_velocity.to_json()},
                        {"/boat/cmd_vel", subs.boat_velocity.to_json()},
                        {"/tether/cmd_payout", subs.payout.to_json()}};
  if (o.lockstep)
    r["subscriptions"]["/clock"] = {{"received", subs.clock_received},
                                    {"refused", subs.clock_refused}};
  // summary.json: the run's summary with the live run's `ros2` object.
  nlohmann::json text = nlohmann::json::parse(kelp::sim::summary_json(summary));
  text["ros2"] = r;
  kelp::sim::finish_run_with(text.dump(2), run);
  return summary;
}

}  // namespace kelp_ros2
