// The run's CSV log (kelp/sim/run_log.hpp): timeseries.csv's columns and RunLog's members.
#include "kelp/sim/run_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

namespace {
// A block is written once this much has gathered; the capacity reserved leaves room for one more
// line of any length a run writes (a timeseries row is about 1 KB), so appending never allocates.
constexpr std::size_t block_size = 64 * 1024, reserved = 2 * block_size;

// Writes `n` bytes: one write(), repeated only for what the system did not take (a signal, a
// full disk). \returns 0, or the error number.
int write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) return errno;
    if (w == 0) return ENOSPC;
    p += w;
    n -= std::size_t(w);
  }
  return 0;
}

// Appends `field` to `s` as one CSV field (RFC 4180): as it is, or, when it holds a comma, a
// double quote or a line break (which would split the row), enclosed in double quotes with each
// double quote in it doubled.
void append_csv_field(std::string& s, const std::string& field) {
  if (field.find_first_of(",\"\r\n") == std::string::npos) {
    s += field;
    return;
  }
  s += '"';
  for (const char c : field) {
    if (c == '"') s += '"';
    s += c;
  }
  s += '"';
}
}  // namespace

LineFile::~LineFile() {
  try {
    close();
  } catch (...) {
  }
}

void LineFile::open(const std::filesystem::path& path) {
  KELP_CHECK(fd_ < 0, "LineFile::open: already open");
  path_ = path.string();
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) throw kelp::error("cannot write " + path_ + ": " + std::strerror(errno));
  text_.clear();
  text_.reserve(reserved);
  ended_ = 0;
  written_ = 0;
}

void LineFile::end_line() {
  text_ += '\n';
  ended_ = text_.size();
  if (ended_ >= block_size) write_out();
}

void LineFile::write_out() {
  if (fd_ < 0 || ended_ == 0) return;
  const int e = write_all(fd_, text_.data(), ended_);
  if (e == 0) written_ += ended_;
  text_.erase(0, ended_);  // the line not ended yet, if any, moves to the front
  ended_ = 0;
  if (e != 0) throw kelp::error("cannot write " + path_ + ": " + std::strerror(e));
}

void LineFile::close() {
  if (fd_ < 0) return;
  std::string error;
  try {
    write_out();
  } catch (const kelp::error& e) {
    error = e.what();
  }
  if (::close(fd_) != 0 && error.empty())
    error = "cannot write " + path_ + ": " + std::strerror(errno);
  fd_ = -1;
  if (!error.empty()) throw kelp::error(error);
}

void write_file_atomically(const std::filesystem::path& path, const std::string& text) {
  // The temporary's name is the process's own, so that two processes writing the same file do
  // not write into one temporary.
  std::filesystem::path tmp = path;
  tmp += ".tmp" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw kelp::error("cannot write " + path.string() + ": " + std::strerror(errno));
  int e = write_all(fd, text.data(), text.size());
  if (::close(fd) != 0 && e == 0) e = errno;
  std::error_code ec;
  if (e == 0) std::filesystem::rename(tmp, path, ec);
  if (e != 0 || ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw kelp::error("cannot write " + path.string() + ": " +
                      (e != 0 ? std::string(std::strerror(e)) : ec.message()));
  }
}

RunLog::RunLog(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  try {
    ts_.open(dir / "timeseries.csv");
    nodes_.open(dir / "nodes.csv");
    events_.open(dir / "events.csv");
  } catch (const kelp::error& e) {
    throw kelp::error("cannot write the run's CSV files in " + dir.string() + " (" + e.what() +
                      ")");
  }
  const std::vector<std::string>& columns = timeseries_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i) ts_.text() += ',';
    ts_.text() += columns[i];
  }
  ts_.end_line();
  nodes_.text() += "t,node,x,y,z,tension";
  nodes_.end_line();
  events_.text() += "t,event,segment,x,y,z,tension,obstacle,winding";
  events_.end_line();
  flush();  // the header lines at once
}

void RunLog::flush_due(double t) {
  if (t + 1e-9 < next_flush_) return;
  next_flush_ = t + 1.0;
  flush();
}

void RunLog::row(const LogRow& r) {
  bool first = true;
  for_each_value(r, [&](double v) {
    if (!first) ts_.text() += ',';
    first = false;
    ts_.text() += num(v);
  });
  ts_.end_line();
  flush_due(r.t);
}

void RunLog::line_parted(const kelp::tether::LineFailured& f) {
  std::string& s = events_.text();
  s += num(f.time);
  s += ",line_parted,";
  s += std::to_string(f.segment);
  for (double v : {f.position.x(), f.position.y(), f.position.z(), f.tension}) {
    s += ',';
    s += num(v);
  }
  s += ",,";
  s += num(std::numeric_limits<double>::quiet_NaN());
  events_.end_line();
  events_.write_out();
}

void RunLog::entanglement(double t, const char* event, const kelp::Vector3<double>& position,
                          double tension, const std::string& obstacle, double winding) {
  std::string& s = events_.text();
  s += num(t);
  s += ',';
  s += event;
  s += ',';
  s += num(std::numeric_limits<double>::quiet_NaN());
  for (double v : {position.x(), position.y(), position.z(), tension}) {
    s += ',';
    s += num(v);
  }
  s += ',';
  append_csv_field(s, obstacle);
  s += ',';
  s += num(winding);
  events_.end_line();
  events_.write_out();
}

void RunLog::nodes(double t, const kelp::tether::TetherModeld& line,
                   const kelp::tether::TetherStated& tether) {
  const Eigen::Index n = tether.position.cols();
  KELP_CHECK(line.nodes() == n && tether.velocity.cols() == n,
             "RunLog::nodes: the line model has " + std::to_string(line.nodes()) +
                 " nodes, the state " + std::to_string(n));
  std::string& s = nodes_.text();
  char index[24];
  for (Eigen::Index i = 0; i < n; ++i) {
    const double tension =
        i + 1 < n ? kelp::tether::segment_axial_force(line, tether, static_cast<int>(i)) : 0.0;
    s += num(t);
    s += ',';
    std::snprintf(index, sizeof index, "%ld", static_cast<long>(i));
    s += index;
    for (double v :
         {tether.position(0, i), tether.position(1, i), tether.position(2, i), tension}) {
      s += ',';
      s += num(v);
    }
    nodes_.end_line();
  }
  flush_due(t);
}

void RunLog::flush() {
  ts_.write_out();
  nodes_.write_out();
  events_.write_out();
}

void RunLog::close() {
  // Every file is closed, whatever fails; the first failure is reported.
  std::string error;
  for (LineFile* f : {&ts_, &nodes_, &events_}) {
    try {
      f->close();
    } catch (const kelp::error& e) {
      if (error.empty()) error = e.what();
    }
  }
  if (!error.empty()) throw kelp::error(error);
}

const char* RunLog::num(double v) {
  std::snprintf(buf_, sizeof buf_, "%.6g", v);
  return buf_;
}

}  // namespace sim
}  // namespace kelp
