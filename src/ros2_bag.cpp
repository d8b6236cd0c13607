// A run's samples as ROS 2 messages and its bag (kelp/sim/ros2.hpp): Ros2Sampler's,
// BagRecorder's and RunBag's (kelp/sim/run.hpp) members.
#include "kelp/sim/ros2.hpp"

#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <utility>

#include "kelp/sim/run.hpp"

namespace kelp {
namespace sim {

const ros2::RunSample& Ros2Sampler::sample(const LogRow& r) {
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

const ros2::Messages& Ros2Sampler::messages(const LogRow& r) {
  ros2::fill_messages(sample(r), m_);
  return m_;
}

namespace {
void check_marker_rate(double marker_rate) {
  KELP_CHECK(marker_rate > 0 && std::isfinite(marker_rate),
             "BagRecorder: the marker rate must be finite and > 0");
}

// The bag's path, once the marker rate is known to be finite and > 0: BagRecorder checks it here,
// in its bag's initialiser, so that a bad rate is refused before the file is created.
const std::filesystem::path& checked_bag_path(const std::filesystem::path& path,
                                              double marker_rate) {
  check_marker_rate(marker_rate);
  return path;
}
}  // namespace

BagRecorder::BagRecorder(const std::filesystem::path& path, double marker_rate,
                         const ros2::McapOptions& options)
    : bag_(checked_bag_path(path, marker_rate), options), marker_period_(1.0 / marker_rate) {}

void BagRecorder::record(const LogRow& r) {
  const ros2::Messages& m = sampler_.messages(r);
  const bool markers = r.t + 1e-9 >= next_marker_;
  if (markers) next_marker_ = r.t + marker_period_;
  bag_.write(m, markers);
}

RunBag::RunBag(std::filesystem::path file, double marker_rate)
    : file_(std::move(file)), marker_rate_(marker_rate) {}

RunBag::~RunBag() = default;

void RunBag::record(const LogRow& r) {
  if (!bag_) {
    // What BagRecorder would refuse, checked before the directory is created, so that a refused
    // first record leaves nothing on disk: the marker rate, and the row, by turning it into
    // messages as the recorder will (once per bag).
    check_marker_rate(marker_rate_);
    Ros2Sampler().messages(r);
    if (file_.has_parent_path()) std::filesystem::create_directories(file_.parent_path());
    bag_ = std::make_unique<BagRecorder>(file_, marker_rate_);
  }
  bag_->record(r);
}

void RunBag::close() {
  if (bag_) bag_->close();
}

std::unique_ptr<RunBag> open_run_bag(const Scenario& sc, const RunOptions& o,
                                     std::function<void(const LogRow&)>& on_sample) {
  if (!sc.mcap || o.out.empty()) return nullptr;
  auto bag = std::make_unique<RunBag>(std::filesystem::path(o.out) / "run.mcap", sc.node_rate);
  on_sample = [b = bag.get(), user = on_sample](const LogRow& r) {
    b->record(r);
    if (user) user(r);
  };
  return bag;
}

}  // namespace sim
}  // namespace kelp
