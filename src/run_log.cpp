// The run's CSV log (kelp/sim/run_log.hpp): timeseries.csv's columns and RunLog's members.
#include "kelp/sim/run_log.hpp"

namespace kelp {
namespace sim {

const std::vector<std::string>& timeseries_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c = {"t",
                                  "asv_x",
                                  "asv_y",
                                  "asv_z",
                                  "asv_roll",
                                  "asv_pitch",
                                  "asv_yaw",
                                  "asv_u",
                                  "asv_v",
                                  "asv_r",
                                  "auv_x",
                                  "auv_y",
                                  "auv_z",
                                  "auv_roll",
                                  "auv_pitch",
                                  "auv_yaw",
                                  "auv_u",
                                  "auv_v",
                                  "auv_w",
                                  "auv_target_x",
                                  "auv_target_y",
                                  "auv_target_z",
                                  "auv_error",
                                  "asv_error",
                                  "asv_thrust_port",
                                  "asv_thrust_starboard"};
    for (int i = 1; i <= 8; ++i) c.push_back("auv_thrust_" + std::to_string(i));
    c.insert(c.end(), {"asv_command_port", "asv_command_starboard"});
    for (int i = 1; i <= 8; ++i) c.push_back("auv_command_" + std::to_string(i));
    c.insert(c.end(), {"tension_asv", "tension_auv"});
    // Propulsion.
    c.insert(c.end(), {"asv_voltage", "asv_soc", "asv_current_port", "asv_current_starboard",
                       "auv_voltage", "auv_soc"});
    for (int i = 1; i <= 8; ++i) c.push_back("auv_current_" + std::to_string(i));
    // The tether: turns at the ROV, parted segments; its length out, the winch's rate and pull.
    c.insert(c.end(), {"tether_turns", "tether_parted_segments", "tether_length", "payout_rate",
                       "winch_pull"});
    // Entanglement: the largest winding about an obstacle now, and which obstacle.
    c.insert(c.end(), {"tether_winding", "tether_winding_obstacle"});
    return c;
  }();
  return columns;
}

RunLog::RunLog(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  ts_.open(dir / "timeseries.csv");
  nodes_.open(dir / "nodes.csv");
  events_.open(dir / "events.csv");
  if (!ts_ || !nodes_ || !events_)
    throw kelp::error("cannot write the run's CSV files in " + dir.string());
  const std::vector<std::string>& columns = timeseries_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) ts_ << (i ? "," : "") << columns[i];
  ts_ << '\n';
  nodes_ << "t,node,x,y,z,tension\n";
  events_ << "t,event,segment,x,y,z,tension,obstacle,winding\n";
}

void RunLog::row(const LogRow& r) {
  bool first = true;
  for_each_value(r, [&](double v) {
    if (!first) ts_ << ',';
    first = false;
    ts_ << num(v);
  });
  ts_ << '\n';
}

void RunLog::line_parted(const kelp::tether::LineFailured& f) {
  events_ << num(f.time) << ",line_parted," << f.segment;
  for (double v : {f.position.x(), f.position.y(), f.position.z(), f.tension})
    events_ << ',' << num(v);
  events_ << ",," << num(std::numeric_limits<double>::quiet_NaN()) << '\n';
  events_.flush();
}

void RunLog::entanglement(double t, const char* event, const kelp::Vector3<double>& position,
                          double tension, const std::string& obstacle, double winding) {
  events_ << num(t) << ',' << event << ',' << num(std::numeric_limits<double>::quiet_NaN());
  for (double v : {position.x(), position.y(), position.z(), tension}) events_ << ',' << num(v);
  events_ << ',' << obstacle << ',' << num(winding) << '\n';
  events_.flush();
}

void RunLog::nodes(double t, const kelp::tether::TetherModeld& line,
                   const kelp::tether::TetherStated& tether) {
  const Eigen::Index n = tether.position.cols();
  KELP_CHECK(line.nodes() == n && tether.velocity.cols() == n,
             "RunLog::nodes: the line model has " + std::to_string(line.nodes()) +
                 " nodes, the state " + std::to_string(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const double tension =
        i + 1 < n ? kelp::tether::segment_axial_force(line, tether, static_cast<int>(i)) : 0.0;
    nodes_ << num(t) << ',' << i << ',' << num(tether.position(0, i)) << ','
           << num(tether.position(1, i)) << ',' << num(tether.position(2, i)) << ',' << num(tension)
           << '\n';
  }
}

void RunLog::flush() {
  ts_.flush();
  nodes_.flush();
}

void RunLog::close() {
  ts_.close();
  nodes_.close();
  events_.close();
}

const char* RunLog::num(double v) {
  std::snprintf(buf_, sizeof buf_, "%.6g", v);
  return buf_;
}

}  // namespace sim
}  // namespace kelp
