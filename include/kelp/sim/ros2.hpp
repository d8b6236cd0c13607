/// \file
/// \brief A sample of a kelp::sim run (LogRow) as ROS 2 messages: the one adapter the MCAP bag
/// (kelp/ros2/mcap.hpp) and the live DDS topics both use, so that both carry the same values.
/// Part of the optional `kelp::sim` component.
#pragma once

#include <Eigen/Core>

#include "kelp/core/error.hpp"
#include "kelp/ros2/messages.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/tether/failure.hpp"

namespace kelp {
namespace sim {

/// \brief Turns LogRows into ros2::Messages (ros2::fill_messages), keeping its buffers: after the
/// first sample (and after a change of the tether's node count) no heap allocation.
class Ros2Sampler {
 public:
  /// \brief The sample of row `r` (the segments' axial tensions evaluated from its tether by
  /// tether::segment_axial_force, as the line-failure check does).
  /// \throws kelp::invalid_argument when the row lacks what the messages need (vehicles, the
  /// tether, the end forces).
  const ros2::RunSample& sample(const LogRow& r) {
    KELP_CHECK(r.asv && r.auv && r.tether && r.tether_model,
               "Ros2Sampler: the row needs both vehicles and the tether (model and state)");
    KELP_CHECK(r.force_on_asv.allFinite() && r.force_on_auv.allFinite(),
               "Ros2Sampler: the row needs the tether's force on each vehicle");
    const auto& line = *r.tether_model;
    const auto& x = *r.tether;
    const int segments = static_cast<int>(x.position.cols()) - 1;
    tensions_.resize(segments);
    for (int i = 0; i < segments; ++i) tensions_(i) = kelp::tether::segment_axial_force(line, x, i);
    s_.time = r.t;
    s_.boat = r.asv;
    s_.rov = r.auv;
    s_.rov_nu_dot = r.auv_nu_dot;
    s_.gravity = std::isfinite(r.gravity) ? r.gravity : kelp::standard_gravity;
    s_.nodes = &x.position;
    s_.tensions = &tensions_;
    s_.force_on_boat = r.force_on_asv;
    s_.force_on_rov = r.force_on_auv;
    s_.boat_thrust = r.asv_thrust;
    s_.boat_command = r.asv_command;
    s_.rov_thrust = r.auv_thrust;
    s_.rov_command = r.auv_command;
    return s_;
  }

  /// \brief The messages of row `r` (valid until the next call).
  /// \throws kelp::invalid_argument as sample() and ros2::fill_messages.
  const ros2::Messages& messages(const LogRow& r) {
    ros2::fill_messages(sample(r), m_);
    return m_;
  }

  /// \brief The tension drawn fully red on /tether/markers [N] (default 200).
  void set_tension_scale(double newtons) { s_.tension_scale = newtons; }

 private:
  Eigen::VectorXd tensions_;
  ros2::RunSample s_;
  ros2::Messages m_;
};

}  // namespace sim
}  // namespace kelp
