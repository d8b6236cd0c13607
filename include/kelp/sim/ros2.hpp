/// \file
/// \brief A sample of a kelp::sim run (LogRow) as ROS 2 messages: the one adapter the MCAP bag
/// (kelp/sim/ros2/mcap.hpp) and the live DDS topics both use, so that both carry the same values.
/// Part of the optional `kelp::sim` component.
#pragma once

#include <Eigen/Core>
#include <filesystem>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/ros2/mcap.hpp"
#include "kelp/sim/ros2/messages.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/tether/failure.hpp"

namespace kelp {
namespace sim {

/// \brief Turns LogRows into ros2::Messages (ros2::fill_messages), keeping its buffers: after the
/// first sample (and after a change of the tether's node count) no heap allocation.
class KELP_SIM_API Ros2Sampler {
 public:
  /// \brief The sample of row `r` (the segments' axial tensions evaluated from its tether by
  /// tether::segment_axial_force, as the line-failure check does).
  /// \throws kelp::invalid_argument when the row lacks what the messages need (vehicles, the
  /// tether, the end forces).
  /// \param r the row (its `asv`, `auv`, `tether`, `tether_model` and end forces set)
  /// \return the sample (kelp's frames: NED, FRD), pointing into `r` and this sampler: valid
  /// while they are and until the next call
  const ros2::RunSample& sample(const LogRow& r);

  /// \brief The messages of row `r` (valid until the next call).
  /// \param r the row (as sample()) \return the messages (ROS frames: ENU, FLU)
  /// \throws kelp::invalid_argument as sample() and ros2::fill_messages.
  const ros2::Messages& messages(const LogRow& r);

  /// \brief The tension drawn fully red on /tether/markers [N] (default 200).
  /// \param newtons the tension [N], > 0
  void set_tension_scale(double newtons) { s_.tension_scale = newtons; }

 private:
  Eigen::VectorXd tensions_;
  ros2::RunSample s_;
  ros2::Messages m_;
};

/// \brief A run's ROS 2 bag (run.mcap): every sample's messages (Ros2Sampler) written by a
/// ros2::BagWriter, /tether/markers at most at `marker_rate` (the line's drawing is the bulk of
/// a bag: at the node rate it costs a tenth of what it would at the log rate).
class KELP_SIM_API BagRecorder {
 public:
  /// \brief Creates the bag at `path`; markers at most `marker_rate` times a second (> 0);
  /// `options` of the MCAP file (chunk size).
  /// \throws kelp::error when the file cannot be written; kelp::invalid_argument for a rate
  /// that is not finite and > 0 (checked before the file is created: none is left behind).
  /// \param path the bag's file \param marker_rate markers per second [Hz], > 0
  /// \param options the MCAP options
  BagRecorder(const std::filesystem::path& path, double marker_rate,
              const ros2::McapOptions& options = {});
  /// \brief Writes the messages of row `r` (markers when due).
  /// \throws kelp::error on a write failure, kelp::invalid_argument as Ros2Sampler.
  /// \param r the row (as Ros2Sampler::sample())
  void record(const LogRow& r);
  /// \brief Finishes the bag (summary, index, footer).
  /// \throws kelp::error on a write failure.
  void close() { bag_.close(); }
  /// \brief The bag being written. \return the writer (counts, bytes)
  const ros2::BagWriter& bag() const { return bag_; }

 private:
  friend struct CheckpointAccess;  // a run's checkpoint
  explicit BagRecorder(double marker_rate) : marker_period_(1.0 / marker_rate) {}  // to continue
  Ros2Sampler sampler_;
  ros2::BagWriter bag_;
  double marker_period_, next_marker_ = 0;
};

}  // namespace sim
}  // namespace kelp
