/// \file
/// \brief A fleet's sample (kelp/sim/fleet_run.hpp: any vehicles, point masses and tethers) as
/// ROS 2 messages, one set of topics per vehicle and per tether, and its bag (run.mcap).
///
/// The topics, named after the scenario's parts (`<v>` a vehicle, `<t>` a tether):
///
/// - `/clock` (rosgraph_msgs/msg/Clock, QoS clock): simulation time;
/// - `/tf` (tf2_msgs/msg/TFMessage, QoS tf): world → `<v>/base_link` per vehicle, world → `<p>`
///   per point mass;
/// - `/<v>/odom` (nav_msgs/msg/Odometry, QoS state): pose in `world`, twist in `<v>/base_link`;
/// - `/<v>/imu` (sensor_msgs/msg/Imu, QoS sensor data): orientation, rates, specific force;
/// - `/<v>/thrusters` (sensor_msgs/msg/JointState, QoS sensor data): per thruster, command
///   (velocity) and thrust [N] (effort); vehicles with thrusters only;
/// - `/<t>/end_forces` (geometry_msgs/msg/WrenchStamped, QoS sensor data): two a sample, the
///   start end's, then the far end's;
/// - `/markers` (visualization_msgs/msg/MarkerArray, QoS state): a LINE_STRIP per tether (ns its
///   name, coloured by tension), a CUBE per vehicle, a SPHERE per point mass.
///
/// The messages are those of the pair's topics (kelp/sim/ros2/messages.hpp) with the same frames
/// (REP 103 / REP 105: `world` ENU, bodies FLU) and the same formulas; an end wrench is the
/// tether's force on what holds that end, in the holding vehicle's body frame about its origin,
/// or, at an anchor, a point mass or a free end, in `world` about the end node (zero torque).
/// Part of the optional `kelp::sim` component.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/ros2/mcap.hpp"
#include "kelp/sim/ros2/messages.hpp"
#include "kelp/sim/ros2/names.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp {
namespace ros2 {

/// \brief One vehicle of a fleet sample (pointed-to data must outlive fill_fleet_messages()).
struct FleetVehicleSample {
  std::string name;  ///< topic namespace, frame `<name>/base_link`
  const kelp::vehicle::VehicleStated* state = nullptr;  ///< its state (required)
  /// Its acceleration ν̇ (body FRD) for the IMU's specific force; NaN: unknown.
  Eigen::Matrix<double, 6, 1> nu_dot =
      Eigen::Matrix<double, 6, 1>::Constant(std::numeric_limits<double>::quiet_NaN());
  int thrusters = 0;                ///< number of thrusters (0: no /{v}/thrusters topic)
  const double* thrust = nullptr;   ///< each thruster's thrust [N] (`thrusters` values)
  const double* command = nullptr;  ///< each thruster's command in [−1, 1] (`thrusters` values)
  Eigen::Vector3d size = Eigen::Vector3d::Constant(0.5);  ///< display box, body x, y, z [m]
};

/// \brief One tether of a fleet sample.
struct FleetTetherSample {
  std::string name;  ///< topic namespace and the markers' ns
  /// Node positions, NED [m], start end first (required, at least 2).
  const Eigen::Matrix<double, 3, Eigen::Dynamic>* nodes = nullptr;
  /// Axial tension of each segment [N] (nodes − 1 values); null: drawn uncoloured.
  const Eigen::VectorXd* tensions = nullptr;
  /// The tether's force on what holds its start end, NED [N].
  Eigen::Vector3d force_at_start = Eigen::Vector3d::Zero(),
                  force_at_end = Eigen::Vector3d::Zero();  ///< the same at its far end, NED [N]
  /// The vehicle (index into FleetSample::vehicles) holding each end; −1: an anchor, a point
  /// mass or free (the wrench is then given in `world`). This one: the start end's.
  int start_vehicle = -1,
      end_vehicle = -1;  ///< the vehicle holding the far end (index, or −1 as start_vehicle)
};

/// \brief One point mass of a fleet sample.
struct FleetPointMassSample {
  std::string name;                                    ///< its TF frame and the markers' ns
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< NED [m]
  double diameter = 0.5;                               ///< display sphere [m]
};

/// \brief What a fleet's messages are made from: one sample of its run (kelp's frames).
struct FleetSample {
  double time = 0;                                 ///< simulation time [s]
  double gravity = kelp::standard_gravity;         ///< g [m/s²] (the environment's)
  std::vector<FleetVehicleSample> vehicles;        ///< every vehicle
  std::vector<FleetTetherSample> tethers;          ///< every tether
  std::vector<FleetPointMassSample> point_masses;  ///< every point mass
  double tension_scale = 200;                      ///< tension drawn fully red [N]
};

/// \brief The messages of one fleet sample: per vehicle an odometry, an IMU and (with thrusters)
/// a joint state; per tether two end wrenches (start, end); one /tf, /clock and /markers.
struct FleetMessages {
  rosgraph_msgs::Clock clock;                            ///< /clock
  tf2_msgs::TFMessage tf;                                ///< /tf
  std::vector<nav_msgs::Odometry> odom;                  ///< /{v}/odom, per vehicle
  std::vector<sensor_msgs::Imu> imu;                     ///< /{v}/imu, per vehicle
  std::vector<sensor_msgs::JointState> thrusters;        ///< /{v}/thrusters, per vehicle
  std::vector<geometry_msgs::WrenchStamped> end_forces;  ///< /{t}/end_forces: 2 per tether
  visualization_msgs::MarkerArray markers;               ///< /markers
  /// Each vehicle's body frame, `<v>/base_link` (kept here, so that a sample allocates nothing).
  std::vector<std::string> frames;
};

/// \brief Every message of fleet sample `s`, into `m` (reused: after the first call with the
/// same parts and node counts no allocation happens). Formulas and frames as fill_messages().
/// \throws kelp::invalid_argument when a vehicle state or a tether's nodes are missing, a tether
/// has fewer than 2 nodes or tensions of the wrong size, an end names a vehicle that is not
/// there, a name is not a ROS name (is_ros_name), or the time is one ros2::to_time refuses.
/// \param s the sample (kelp's frames: NED, FRD) \param m the messages, overwritten
KELP_SIM_API void fill_fleet_messages(const FleetSample& s, FleetMessages& m);

/// \brief A fleet's ROS 2 bag (MCAP, profile `ros2`): the topics of this file's table, one
/// channel each, created from a sample's parts; write() logs a sample's messages at its time.
class KELP_SIM_API FleetBagWriter {
 public:
  /// \brief Creates the bag at `path` with a channel for every topic of `layout`'s parts (its
  /// vehicles, their thrusters, its tethers; the values are not read).
  /// \throws kelp::error when the file cannot be written; kelp::invalid_argument for a name that
  /// is not a ROS name or used twice among the vehicles or among the tethers.
  /// \param path the bag's file \param layout a sample of the fleet (its names and counts)
  /// \param options the MCAP options
  FleetBagWriter(const std::filesystem::path& path, const FleetSample& layout,
                 const McapOptions& options = {});

  /// \brief Writes every message of a sample (made by fill_fleet_messages() from a sample of
  /// the same parts); `markers` false leaves /markers out (a bag may carry them at a lower rate).
  /// \throws kelp::error on a write failure; kelp::invalid_argument when `m` does not have the
  /// layout's parts.
  /// \param m the sample's messages \param markers whether to write /markers
  void write(const FleetMessages& m, bool markers = true);

  /// \brief Finishes the file (summary, index, footer).
  /// \throws kelp::error on a write failure.
  void close() { mcap_.close(); }

  /// \brief The underlying MCAP writer (counts, bytes). \return the writer
  const McapWriter& mcap() const { return mcap_; }

 private:
  template <class M>
  void put(std::uint16_t channel, const M& m, const builtin_interfaces::Time& stamp);

  McapWriter mcap_;
  std::uint16_t clock_ = 0, tf_ = 0, markers_ = 0;
  std::vector<std::uint16_t> odom_, imu_, thrusters_, end_forces_;  // thrusters_: 0 = none
  std::vector<std::uint32_t> sequence_;                             // per channel id
  std::vector<std::uint8_t> buf_;
};

}  // namespace ros2
}  // namespace kelp
