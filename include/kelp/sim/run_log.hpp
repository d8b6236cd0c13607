/// \file
/// \brief The log of a run of the tethered pair: timeseries.csv (one row per sample: both
/// vehicles, the AUV's target and errors, thrusts, commands, end tensions, the tether's turns),
/// nodes.csv (the tether's node positions and segment tensions) and events.csv (the line
/// parting, the tether's entanglement with obstacles).
///
/// The format is shared by kelp-tethered-pair and kelp-sitl and plotted by
/// apps/tethered_pair/plot_run.py; its columns are documented in
/// apps/tethered_pair/README.md. It knows vehicle and tether states only, not the scenario or
/// the controllers: a program fills a LogRow from whatever flies the vehicles. Numbers are written
/// with printf's `%.6g`. Part of the optional `kelp::sim` component (it needs no JSON itself).
///
/// What a crash leaves: lines gather in memory and reach the files in blocks of whole lines, each
/// block one write() (repeated only for the rest of a block the system wrote in part), at least
/// once a simulated second (when a row or snapshot is at least 1 s after the last block; an
/// event at once). So a process killed at any point (SIGKILL) leaves every file ending on a
/// whole line, with everything logged up to about a simulated second before it died. Only a kill
/// that lands while the kernel copies a block (Linux checks for one between pages) or a power
/// loss (nothing is synced to disk) can leave a last line cut short or missing: a reader should
/// drop a last line without its newline.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/types.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/tether/failure.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp {
namespace sim {

/// \brief One row of timeseries.csv. Quantities a run does not have (the AUV's target and path
/// error when an autopilot flies it) are NaN, written as `nan`.
///
/// The vehicle states are pointed to, not copied: they must outlive the call to RunLog::row.
struct LogRow {
  /// The value of a quantity the run does not have.
  static constexpr double none = std::numeric_limits<double>::quiet_NaN();
  double t = 0;                                       ///< simulation time [s]
  const kelp::vehicle::VehicleStated* asv = nullptr;  ///< the ASV's state (required)
  const kelp::vehicle::VehicleStated* auv = nullptr;  ///< the AUV's state (required)
  /// The AUV's current target (NED [m]).
  kelp::Vector3<double> auv_target = kelp::Vector3<double>::Constant(none);
  double auv_error = none;  ///< the AUV's distance from the survey leg it flies [m]
  double asv_error = none;  ///< the ASV's horizontal distance from the AUV [m]
  Eigen::Vector2d asv_thrust = Eigen::Vector2d::Constant(none);   ///< port, starboard [N]
  Eigen::Vector2d asv_command = Eigen::Vector2d::Constant(none);  ///< normalised
  Eigen::Matrix<double, 8, 1> auv_thrust =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< [N], motor order
  Eigen::Matrix<double, 8, 1> auv_command =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< normalised
  double tension_asv = 0,  ///< magnitude of the tether's force on the ASV [N]
      tension_auv = 0;     ///< magnitude of the tether's force on the AUV [N]
  /// \name Winch: the unstretched line out [m], and with a winch its payout rate [m/s] and the
  /// pull at the winch [N] (NaN without a winch).
  ///@{
  double tether_length = none,  ///< unstretched line out [m]
      payout_rate = none,       ///< winch payout rate [m/s] (positive: paying out)
      winch_pull = none;        ///< pull at the winch [N]
  ///@}
  /// \name Propulsion: each battery's terminal voltage [V] and state of charge, each thruster's
  /// current [A] (NaN without a propulsion model).
  ///@{
  double asv_voltage = none, asv_soc = none, auv_voltage = none, auv_soc = none;
  Eigen::Vector2d asv_current = Eigen::Vector2d::Constant(none);  ///< port, starboard [A]
  Eigen::Matrix<double, 8, 1> auv_current =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< [A], motor order
  ///@}
  /// Net turns of the AUV about the tether at its attachment (TurnCounter) [-].
  double tether_turns = none;
  /// Segments of the tether that have parted (TetherState::parted) [-].
  double parted_segments = none;
  /// The tether's winding angle [rad] about the obstacle it is most wound round now (the
  /// largest |winding|; kelp/sim/entanglement.hpp), and that obstacle's index among the
  /// scenario's cylinders (NaN without cylinders).
  double tether_winding = none,  ///< the winding angle [rad] (signed)
      winding_obstacle = none;   ///< the obstacle's index among the cylinders (NaN: none)
  /// \name For the ROS 2 messages (kelp/sim/ros2.hpp; not in timeseries.csv): the tether's force
  /// on each vehicle (NED [N], system::SystemReport), the AUV's last acceleration ν̇ (body, its
  /// IMU's specific force), gravity [m/s²], and the tether's line model and state (pointed to:
  /// they must outlive the call). NaN / null when the program does not give them.
  ///@{
  /// The tether's force on the ASV, NED [N].
  kelp::Vector3<double> force_on_asv = kelp::Vector3<double>::Constant(none);
  /// The tether's force on the AUV, NED [N].
  kelp::Vector3<double> force_on_auv = kelp::Vector3<double>::Constant(none);
  /// The AUV's last acceleration ν̇, body axes ([m/s²], [rad/s²]).
  kelp::Vector6<double> auv_nu_dot = kelp::Vector6<double>::Constant(none);
  double gravity = none;  ///< gravitational acceleration g [m/s²]
  const kelp::tether::TetherModeld* tether_model = nullptr;  ///< the line model (or null)
  const kelp::tether::TetherStated* tether = nullptr;  ///< the line's state, NED [m] (or null)
  ///@}
};

/// \brief The columns of timeseries.csv, in order (documented in
/// apps/tethered_pair/README.md); for_each_value gives a row's values in the same order.
/// \return the names (a static list, built once)
KELP_SIM_API const std::vector<std::string>& timeseries_columns();

/// \brief Calls `f(value)` for each value of row `r`, in timeseries_columns()' order (what
/// RunLog::row writes and kelp's Python package returns as columns). No allocation.
/// \tparam F a callable taking a double
/// \param r the row (its `asv` and `auv` must not be null) \param f called once per column
template <typename F>
void for_each_value(const LogRow& r, F&& f) {
  const Eigen::Vector3d ea = kelp::euler_from_quaternion(r.asv->attitude);
  const Eigen::Vector3d eb = kelp::euler_from_quaternion(r.auv->attitude);
  const auto& a = *r.asv;
  const auto& b = *r.auv;
  for (double v : {r.t,
                   a.position.x(),
                   a.position.y(),
                   a.position.z(),
                   ea.x(),
                   ea.y(),
                   ea.z(),
                   a.nu(0),
                   a.nu(1),
                   a.nu(5),
                   b.position.x(),
                   b.position.y(),
                   b.position.z(),
                   eb.x(),
                   eb.y(),
                   eb.z(),
                   b.nu(0),
                   b.nu(1),
                   b.nu(2),
                   r.auv_target.x(),
                   r.auv_target.y(),
                   r.auv_target.z(),
                   r.auv_error,
                   r.asv_error,
                   r.asv_thrust(0),
                   r.asv_thrust(1)})
    f(v);
  for (int i = 0; i < 8; ++i) f(r.auv_thrust(i));
  f(r.asv_command(0));
  f(r.asv_command(1));
  for (int i = 0; i < 8; ++i) f(r.auv_command(i));
  f(r.tension_asv);
  f(r.tension_auv);
  // Propulsion.
  for (double v :
       {r.asv_voltage, r.asv_soc, r.asv_current(0), r.asv_current(1), r.auv_voltage, r.auv_soc})
    f(v);
  for (int i = 0; i < 8; ++i) f(r.auv_current(i));
  // The tether.
  for (double v : {r.tether_turns, r.parted_segments, r.tether_length, r.payout_rate, r.winch_pull})
    f(v);
  f(r.tether_winding);
  f(r.winding_obstacle);
}

/// \brief A text file written in whole lines (RunLog's CSV files, a fleet run's): lines gather in
/// memory and reach the file in blocks of whole lines, each block one write() (repeated only for
/// the part of a block the system did not take), when a block is full (64 KiB), on write_out()
/// and on close(). A process killed at any other point leaves the file ending on a whole line.
///
/// A line is appended to text() and ended by end_line(); up to the capacity reserved when opened
/// (128 KiB) appending allocates nothing.
class KELP_SIM_API LineFile {
 public:
  LineFile() = default;
  /// \brief Opens `path` (see open()).
  /// \param path the file to create or truncate
  /// \throws kelp::error naming the file when it cannot be created.
  explicit LineFile(const std::filesystem::path& path) { open(path); }
  /// \brief Writes out and closes (close()), errors swallowed: call close() to see them.
  ~LineFile();
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;

  /// \brief Creates (or truncates) `path` for writing.
  /// \param path the file
  /// \throws kelp::error naming the file when it cannot be created.
  void open(const std::filesystem::path& path);
  /// \brief Is a file open? \return true between open() and close()
  bool is_open() const { return fd_ >= 0; }
  /// \brief The text gathered: append the current line's text to it.
  /// \return the buffer (ended lines not yet written, then the current line)
  std::string& text() { return text_; }
  /// \brief Ends the current line (a newline); writes the gathered lines out once they fill a
  /// block. \throws kelp::error when the file cannot be written.
  void end_line();
  /// \brief Writes every ended line gathered to the file (a line not ended yet stays).
  /// \throws kelp::error when the file cannot be written.
  void write_out();
  /// \brief Writes the ended lines out and closes the file. Does nothing when not open.
  /// \throws kelp::error when the file cannot be written (it is closed anyway).
  void close();

 private:
  friend struct CheckpointAccess;  // a run's checkpoint: the file's length, reopened there
  int fd_ = -1;
  std::string path_, text_;
  std::size_t ended_ = 0;      // text_'s ended lines: its first ended_ bytes
  std::uint64_t written_ = 0;  // bytes in the file
};

/// \brief Writes `text` as the file `path` atomically: into a temporary file beside it (same
/// directory, so the same file system), then renamed over it. A reader, or a process killed at any
/// point, sees the old file (or none) or the new one whole, never a part (summary.json,
/// replay.html). \throws kelp::error naming the file when it cannot be written.
/// \param path the file to replace \param text its new content
KELP_SIM_API void write_file_atomically(const std::filesystem::path& path, const std::string& text);

/// \brief timeseries.csv, nodes.csv and events.csv of a run, in a directory (the columns are
/// documented in apps/tethered_pair/README.md). Writes the header lines when constructed.
class KELP_SIM_API RunLog {
 public:
  /// \brief Creates `dir` (and its parents) and the three files in it, each with its header line.
  /// \param dir the run's directory (existing files in it are truncated)
  /// \throws kelp::error when the files cannot be opened for writing; std::filesystem's error
  /// when the directory cannot be created.
  explicit RunLog(const std::filesystem::path& dir);

  /// \brief Appends one row to timeseries.csv (and writes every file's lines out when the row is
  /// a simulated second or more after the last time they were).
  /// \param r the row (its `asv` and `auv` must not be null)
  /// \throws kelp::error when a file cannot be written.
  void row(const LogRow& r);

  /// \brief Appends the tether's parting to events.csv
  /// (`t,event,segment,x,y,z,tension,obstacle,winding`, event `line_parted`): its time [s],
  /// segment, position NED [m] and axial force [N] (no obstacle, winding `nan`). Written at once.
  /// \param f the parting (tether/failure.hpp)
  /// \throws kelp::error when the file cannot be written.
  void line_parted(const kelp::tether::LineFailured& f);

  /// \brief Appends an entanglement event to events.csv (kelp/sim/entanglement.hpp): `entangled`
  /// (the winding about obstacle `obstacle` passed the threshold; `tension` nan) or `pinned`
  /// (`tension`: the axial force on the ROV's side of the contact less the boat's [N]); its
  /// time [s], no segment (`nan`), the contact's position NED [m], the obstacle's name and the
  /// winding about it then [rad]. Written at once.
  /// \param t time [s] \param event the event's name (`entangled` or `pinned`)
  /// \param position the contact's position, NED [m]
  /// \param tension the tension difference [N] (`pinned`), or NaN
  /// \param obstacle the obstacle's name, written as one CSV field (RFC 4180): enclosed in
  /// double quotes, each double quote in it doubled, when it holds a comma, a double quote or a
  /// line break; as it is otherwise
  /// \param winding the winding about it [rad]
  /// \throws kelp::error when the file cannot be written.
  void entanglement(double t, const char* event, const kelp::Vector3<double>& position,
                    double tension, const std::string& obstacle, double winding);

  /// \brief Appends the tether's node positions at time `t` [s] to nodes.csv, one line a node
  /// (`t,node,x,y,z,tension`): the node's NED position [m] and the axial tension [N] of the
  /// segment that starts at it (tether::segment_axial_force, as the step's force pass evaluates
  /// it; 0 for the last node, which starts no segment, and for a parted segment). Written out as
  /// row() says.
  /// \param[in] t time [s] \param[in] line the line model of `tether` (with a winch, the model
  /// of its current node count: system::SystemModel::tether_of) \param[in] tether its state
  /// \throws kelp::invalid_argument when `line` has not the state's node count; kelp::error when
  /// a file cannot be written.
  void nodes(double t, const kelp::tether::TetherModeld& line,
             const kelp::tether::TetherStated& tether);

  /// \brief Writes what is buffered to the files (e.g. before a status line of a long run).
  /// \throws kelp::error when a file cannot be written.
  void flush();
  /// \brief Writes what is buffered and closes the files (the destructor does too, quietly).
  /// \throws kelp::error when a file cannot be written.
  void close();

  ~RunLog() = default;
  RunLog(const RunLog&) = delete;
  RunLog& operator=(const RunLog&) = delete;

 private:
  friend struct CheckpointAccess;  // a run's checkpoint: the files' lengths, reopened there
  RunLog() = default;
  // A row or snapshot at `t` [s]: every file written out once t is 1 s past the last time.
  void flush_due(double t);
  const char* num(double v);
  LineFile ts_, nodes_, events_;
  double next_flush_ = 0;
  char buf_[64] = {};
};

}  // namespace sim
}  // namespace kelp
