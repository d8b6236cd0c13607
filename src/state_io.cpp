// State files (kelp/sim/state_io.hpp): the pair's and a fleet's state in kelp's archive
// (archive.hpp), their checks, and the atomic file helpers. The format is docs/state-files.md.
#include "kelp/sim/state_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "archive.hpp"
#include "kelp/sim/version.hpp"
#include "state_sections.hpp"

namespace kelp {
namespace sim {

namespace {

namespace ks = kelp::system;
namespace kt = kelp::tether;
namespace kv = kelp::vehicle;
using archive::ArchiveKind;
using archive::Reader;
using archive::Section;
using archive::tag;
using archive::Writer;

constexpr archive::Tag head_tag = tag("HEAD");
constexpr archive::Tag vehicle_tag = tag("VEHI");
constexpr archive::Tag propulsion_tag = tag("PROP");
constexpr archive::Tag point_mass_tag = tag("PMAS");
constexpr archive::Tag tether_tag = tag("TETH");

// The most nodes a tether can have (kelp/tether/model.hpp).
constexpr std::uint32_t max_nodes = std::uint32_t(kt::limits::max_segments) + 1;
// The Newton matrix's bounds (kelp/tether/implicit.hpp: the pause doubles up to 31).
constexpr int max_newton_pause = 31;

// ---- checks on a state (shared by save and load) ------------------------------------------------

// Where a check failed: "<input>: <part>: <message>".
struct Where {
  const std::string& input;
  std::string part;
  [[noreturn]] void fail(const std::string& message) const {
    throw state_error(input + ": " + part + ": " + message);
  }
  void check(bool ok, const std::string& message) const {
    if (!ok) fail(message);
  }
  // Runs one of the physics' own checks (the step's), naming the part in its message.
  template <class F>
  void physics(F&& f) const {
    try {
      f();
    } catch (const kelp::invalid_argument& e) {
      fail(e.what());
    }
  }
};

bool finite(double x) { return std::isfinite(x); }
template <class M>
bool all_finite(const M& m) {
  return m.array().isFinite().all();
}

void check_vehicle(const Where& w, const kv::VehicleStated& v, const Vector6<double>& nu_dot,
                   double time) {
  w.physics([&] { kv::detail::check_state(v); });
  w.check(all_finite(nu_dot), "its last acceleration (nu_dot) must be finite");
  w.check(v.time == time, "its clock (" + std::to_string(v.time) +
                              " s) differs from the system's (" + std::to_string(time) + " s)");
}

void check_propulsion(const Where& w, const kv::PropulsionStated& p) {
  w.check(p.thrust.size() == p.current.size(),
          "one thrust and one current per thruster are needed");
  w.check(all_finite(p.thrust), "the thrust must be finite");
  w.check(finite(p.battery.charge_drawn) && finite(p.battery.energy_drawn),
          "the battery's counters must be finite");
}

void check_point_mass(const Where& w, const ks::PointMassState<double>& x,
                      const Vector3<double>& acceleration) {
  w.check(all_finite(x.position) && all_finite(x.velocity) && all_finite(acceleration),
          "its position, velocity and last acceleration must be finite");
}

// Everything a tether step relies on, as far as it does not depend on the model.
void check_tether(const Where& w, const kt::TetherStated& t, double time) {
  const Eigen::Index nodes = t.position.cols();
  w.check(nodes >= 2 && nodes <= Eigen::Index(max_nodes),
          std::to_string(nodes) + " nodes, a tether has 2 to " + std::to_string(max_nodes));
  w.check(t.velocity.cols() == nodes, "as many velocities as positions are needed");
  w.check(all_finite(t.position), "its positions must be finite");
  w.check(all_finite(t.velocity), "its velocities must be finite");
  w.check(t.time == time, "its clock (" + std::to_string(t.time) +
                              " s) differs from the system's (" + std::to_string(time) + " s)");
  w.check(finite(t.time_carry), "its clock's carry (time_carry) must be finite");
  w.check(finite(t.previous_dt) && t.previous_dt >= 0.0,
          "its previous step (previous_dt) must be finite and >= 0");
  const bool history_sized =
      t.previous_position.cols() == nodes && t.previous_velocity.cols() == nodes;
  w.check(history_sized || (t.previous_dt == 0.0 && t.previous_position.cols() == 0 &&
                            t.previous_velocity.cols() == 0),
          "its previous positions and velocities must have one column per node");
  if (t.has_history())
    w.check(all_finite(t.previous_position) && all_finite(t.previous_velocity),
            "its previous positions and velocities must be finite");
  if (t.has_acceleration)
    w.check(t.acceleration.cols() == nodes && all_finite(t.acceleration),
            "its accelerations must have one finite column per node");
  w.check(t.parted.size() == 0 || t.parted.size() == nodes - 1,
          "its parted flags must be empty or one per segment");
  for (Eigen::Index s = 0; s < t.parted.size(); ++s)
    w.check(t.parted(s) <= 1, "a parted flag must be 0 or 1");
  w.check(finite(t.winch_length) && t.winch_length >= 0.0,
          "its winch segment length must be finite and >= 0");
  w.check(finite(t.payout_rate), "its payout rate must be finite");
  const kt::KeptNewtonMatrix<double>& k = t.newton;
  w.check(finite(k.gh) && k.gh >= 0.0, "the kept Newton matrix's gh must be finite and >= 0");
  w.check(k.age >= 0 && k.pause >= 0 && k.pause <= max_newton_pause && k.backoff >= 0 &&
              k.backoff <= max_newton_pause,
          "the kept Newton matrix's age, pause and backoff are out of range");
  const bool sized =
      k.factor.size() == kt::detail::newton_factor_size(int(nodes)) && k.branch.size() == nodes - 1;
  w.check(sized || (k.gh == 0.0 && k.factor.size() == 0 && k.branch.size() == 0),
          "the kept Newton matrix is not sized for the tether's nodes");
  if (k.gh > 0.0) {
    w.check(all_finite(k.factor), "the kept Newton matrix must be finite");
    for (Eigen::Index s = 0; s < k.branch.size(); ++s)
      w.check(k.branch(s) == 0.0 || k.branch(s) == 1.0 || k.branch(s) == 2.0,
              "the kept Newton matrix's branches must be 0, 1 or 2");
  }
}

void check_pair(const std::string& input, const ks::SystemStated& s) {
  Where{input, "the system's clock"}.check(finite(s.time), "must be finite");
  check_vehicle({input, "the ASV"}, s.asv, s.asv_nu_dot, s.time);
  check_vehicle({input, "the AUV"}, s.auv, s.auv_nu_dot, s.time);
  check_propulsion({input, "the ASV's propulsion"}, s.asv_propulsion);
  check_propulsion({input, "the AUV's propulsion"}, s.auv_propulsion);
  check_tether({input, "the tether"}, s.tether, s.time);
}

std::string nth(const char* what, std::size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

void check_fleet(const std::string& input, const ks::FleetStated& s) {
  const Where w{input, "the fleet"};
  w.check(finite(s.time), "its clock must be finite");
  w.check(s.vehicle_nu_dot.size() == s.vehicles.size() &&
              s.propulsion.size() == s.vehicles.size() &&
              s.point_mass_acceleration.size() == s.point_masses.size(),
          "one last acceleration and one propulsion state per vehicle, one last acceleration "
          "per point mass are needed");
  for (std::size_t i = 0; i < s.vehicles.size(); ++i) {
    check_vehicle({input, nth("vehicle", i)}, s.vehicles[i], s.vehicle_nu_dot[i], s.time);
    check_propulsion({input, nth("vehicle", i) + "'s propulsion"}, s.propulsion[i]);
  }
  for (std::size_t j = 0; j < s.point_masses.size(); ++j)
    check_point_mass({input, nth("point mass", j)}, s.point_masses[j],
                     s.point_mass_acceleration[j]);
  for (std::size_t k = 0; k < s.tethers.size(); ++k)
    check_tether({input, nth("tether", k)}, s.tethers[k], s.time);
}

// ---- checks against a model ---------------------------------------------------------------------

void check_propulsion_fits(const Where& w, const kv::PropulsionModeld* m,
                           const kv::PropulsionStated& p) {
  const Eigen::Index n = m ? m->size() : 0;
  w.check(p.thrust.size() == n, std::to_string(p.thrust.size()) +
                                    " thrusters, the system's vehicle has " + std::to_string(n));
}

void check_tether_fits(const Where& w, const kt::TetherModeld& line, const kt::WinchModeld* winch,
                       const kt::TetherStated& t) {
  const Eigen::Index nodes = t.position.cols();
  if (winch) {
    w.check(nodes >= winch->min_segments() + 1 && nodes <= winch->max_segments() + 1,
            std::to_string(nodes) + " nodes, its winch allows " +
                std::to_string(winch->min_segments() + 1) + " to " +
                std::to_string(winch->max_segments() + 1));
  } else {
    w.check(nodes == line.nodes(), std::to_string(nodes) + " nodes, the system's tether has " +
                                       std::to_string(line.nodes()));
    w.check(t.winch_length == 0.0 && t.payout_rate == 0.0,
            "a winch segment length or payout rate, but the system's tether has no winch");
  }
}

void check_pair_fits(const std::string& input, const ks::SystemModeld& m,
                     const ks::SystemStated& s) {
  check_propulsion_fits({input, "the ASV's propulsion"}, m.asv_propulsion(), s.asv_propulsion);
  check_propulsion_fits({input, "the AUV's propulsion"}, m.auv_propulsion(), s.auv_propulsion);
  check_tether_fits({input, "the tether"}, m.tether(), m.winch(), s.tether);
}

void check_fleet_fits(const std::string& input, const ks::FleetModeld& m,
                      const ks::FleetStated& s) {
  const Where w{input, "the fleet"};
  const auto counts = [](std::size_t a, std::size_t b, std::size_t c) {
    return std::to_string(a) + " vehicles, " + std::to_string(b) + " point masses and " +
           std::to_string(c) + " tethers";
  };
  w.check(s.vehicles.size() == std::size_t(m.vehicle_count()) &&
              s.point_masses.size() == std::size_t(m.point_mass_count()) &&
              s.tethers.size() == std::size_t(m.tether_count()),
          counts(s.vehicles.size(), s.point_masses.size(), s.tethers.size()) + ", the fleet has " +
              counts(std::size_t(m.vehicle_count()), std::size_t(m.point_mass_count()),
                     std::size_t(m.tether_count())));
  const auto& p = m.parameters();
  for (std::size_t i = 0; i < s.vehicles.size(); ++i)
    check_propulsion_fits({input, nth("vehicle", i) + " (" + p.vehicles[i].name + ")'s propulsion"},
                          m.propulsion(int(i)), s.propulsion[i]);
  for (std::size_t k = 0; k < s.tethers.size(); ++k)
    check_tether_fits({input, nth("tether", k) + " (" + p.tethers[k].name + ")"}, m.tether(int(k)),
                      m.winch(int(k)), s.tethers[k]);
}

// ---- writing ------------------------------------------------------------------------------------

void write_head(Writer& a, double time, std::size_t vehicles, std::size_t point_masses,
                std::size_t tethers) {
  a.begin(head_tag);
  a.f64(time);
  a.u32(std::uint32_t(vehicles));
  a.u32(std::uint32_t(point_masses));
  a.u32(std::uint32_t(tethers));
  a.end();
}

void write_vehicle(Writer& a, const kv::VehicleStated& v, const Vector6<double>& nu_dot) {
  a.begin(vehicle_tag);
  a.f64s(v.position.data(), 3);
  a.f64s(v.attitude.coeffs().data(), 4);  // x, y, z, w
  a.f64s(v.nu.data(), 6);
  a.f64(v.time);
  a.f64s(nu_dot.data(), 6);
  a.end();
}

void write_propulsion(Writer& a, const kv::PropulsionStated& p) {
  a.begin(propulsion_tag);
  a.u32(std::uint32_t(p.thrust.size()));
  a.f64s(p.thrust.data(), std::size_t(p.thrust.size()));
  a.f64s(p.current.data(), std::size_t(p.current.size()));
  a.f64(p.battery.charge_drawn);
  a.f64(p.battery.energy_drawn);
  a.f64(p.battery.voltage);
  a.f64(p.battery.current);
  a.end();
}

void write_point_mass(Writer& a, const ks::PointMassState<double>& x,
                      const Vector3<double>& acceleration) {
  a.begin(point_mass_tag);
  a.f64s(x.position.data(), 3);
  a.f64s(x.velocity.data(), 3);
  a.f64s(acceleration.data(), 3);
  a.end();
}

// `n` doubles of `m`, or zeros when `m` is empty (a state without that history: see
// check_tether).
template <class M>
void write_or_zeros(Writer& a, const M& m, std::size_t n) {
  if (m.size() == 0) {
    for (std::size_t i = 0; i < n; ++i) a.f64(0.0);
  } else {
    a.f64s(m.data(), n);
  }
}

void write_tether(Writer& a, const kt::TetherStated& t) {
  const auto nodes = std::size_t(t.position.cols());
  a.begin(tether_tag);
  a.f64(t.time);
  a.f64(t.time_carry);
  a.f64(t.previous_dt);
  a.f64(t.winch_length);
  a.f64(t.payout_rate);
  a.u32(std::uint32_t(nodes));
  a.f64s(t.position.data(), 3 * nodes);
  a.f64s(t.velocity.data(), 3 * nodes);
  write_or_zeros(a, t.previous_position, 3 * nodes);
  write_or_zeros(a, t.previous_velocity, 3 * nodes);
  for (std::size_t s = 0; s + 1 < nodes; ++s)
    a.u8(t.parted.size() ? t.parted(Eigen::Index(s)) : std::uint8_t(0));
  a.f64(t.newton.gh);
  a.i32(t.newton.age);
  a.i32(t.newton.pause);
  a.i32(t.newton.backoff);
  write_or_zeros(a, t.newton.factor, std::size_t(kt::detail::newton_factor_size(int(nodes))));
  write_or_zeros(a, t.newton.branch, nodes - 1);
  a.u8(std::uint8_t((t.has_acceleration ? 1 : 0) | (t.predict_from_acceleration ? 2 : 0)));
  if (t.has_acceleration)
    a.f64s(t.acceleration.data(), 3 * nodes);
  else
    for (std::size_t i = 0; i < 3 * nodes; ++i) a.f64(0.0);
  a.end();
}

// ---- reading ------------------------------------------------------------------------------------

struct Head {
  double time;
  std::uint32_t vehicles, point_masses, tethers;
};

Head read_head(Reader& r) {
  Section s = r.next(head_tag);
  Head h{};
  h.time = s.f64();
  h.vehicles = s.u32();
  h.point_masses = s.u32();
  h.tethers = s.u32();
  s.end();
  // Each part has its sections: counts beyond the sections there are refused before anything
  // is sized by them (a missing or an unknown section is then named by the reader).
  const std::size_t left = r.sections_left();
  if (2 * std::uint64_t(h.vehicles) > left || h.point_masses > left || h.tethers > left)
    r.fail("the header counts " + std::to_string(h.vehicles) + " vehicles, " +
           std::to_string(h.point_masses) + " point masses and " + std::to_string(h.tethers) +
           " tethers, the file holds " + std::to_string(left) + " sections after it");
  return h;
}

void read_vehicle(Reader& r, kv::VehicleStated& v, Vector6<double>& nu_dot) {
  Section s = r.next(vehicle_tag);
  s.f64s(v.position.data(), 3);
  s.f64s(v.attitude.coeffs().data(), 4);
  s.f64s(v.nu.data(), 6);
  v.time = s.f64();
  s.f64s(nu_dot.data(), 6);
  s.end();
}

void read_propulsion(Reader& r, kv::PropulsionStated& p) {
  Section s = r.next(propulsion_tag);
  const std::uint32_t n = s.count(std::uint32_t(kv::max_thrusters), 16, "thrusters");
  p.thrust.resize(n);
  p.current.resize(n);
  s.f64s(p.thrust.data(), n);
  s.f64s(p.current.data(), n);
  p.battery.charge_drawn = s.f64();
  p.battery.energy_drawn = s.f64();
  p.battery.voltage = s.f64();
  p.battery.current = s.f64();
  s.end();
}

void read_point_mass(Reader& r, ks::PointMassState<double>& x, Vector3<double>& acceleration) {
  Section s = r.next(point_mass_tag);
  s.f64s(x.position.data(), 3);
  s.f64s(x.velocity.data(), 3);
  s.f64s(acceleration.data(), 3);
  s.end();
}

void read_tether(Reader& r, kt::TetherStated& t) {
  Section s = r.next(tether_tag);
  t.time = s.f64();
  t.time_carry = s.f64();
  t.previous_dt = s.f64();
  t.winch_length = s.f64();
  t.payout_rate = s.f64();
  const std::uint32_t nodes = s.count(max_nodes, 0, "nodes");
  if (nodes < 2) s.fail("nodes: " + std::to_string(nodes) + ", a tether has at least 2");
  // The rest of the section, exactly (nodes is bounded, so this does not overflow).
  const auto n = std::size_t(nodes);
  const auto factor = std::size_t(kt::detail::newton_factor_size(int(nodes)));
  const std::size_t expected =
      4 * 3 * n * 8 + (n - 1) + 8 + 3 * 4 + factor * 8 + (n - 1) * 8 + 1 + 3 * n * 8;
  if (s.left() != expected)
    s.fail(std::to_string(nodes) + " nodes need " + std::to_string(expected) +
           " more bytes, the section has " + std::to_string(s.left()));
  t.position.resize(3, Eigen::Index(n));
  t.velocity.resize(3, Eigen::Index(n));
  t.previous_position.resize(3, Eigen::Index(n));
  t.previous_velocity.resize(3, Eigen::Index(n));
  s.f64s(t.position.data(), 3 * n);
  s.f64s(t.velocity.data(), 3 * n);
  s.f64s(t.previous_position.data(), 3 * n);
  s.f64s(t.previous_velocity.data(), 3 * n);
  t.parted.resize(Eigen::Index(n - 1));
  for (std::size_t i = 0; i + 1 < n; ++i) t.parted(Eigen::Index(i)) = s.u8();
  t.newton.gh = s.f64();
  t.newton.age = s.i32();
  t.newton.pause = s.i32();
  t.newton.backoff = s.i32();
  t.newton.factor.resize(Eigen::Index(factor));
  t.newton.branch.resize(Eigen::Index(n - 1));
  s.f64s(t.newton.factor.data(), factor);
  s.f64s(t.newton.branch.data(), n - 1);
  const std::uint8_t flags = s.u8();
  if (flags > 3) s.fail("its acceleration flags are " + std::to_string(flags) + ", not 0 to 3");
  t.has_acceleration = (flags & 1) != 0;
  t.predict_from_acceleration = (flags & 2) != 0;
  t.acceleration.resize(3, Eigen::Index(n));
  s.f64s(t.acceleration.data(), 3 * n);
  s.end();
}

// The pair's sections, from the reader's next section on.
ks::SystemStated read_pair_sections(Reader& r, const std::string& input) {
  const Head h = read_head(r);
  if (h.vehicles != 2 || h.point_masses != 0 || h.tethers != 1)
    r.fail("a pair's state has 2 vehicles, no point mass and 1 tether, the header says " +
           std::to_string(h.vehicles) + ", " + std::to_string(h.point_masses) + " and " +
           std::to_string(h.tethers));
  ks::SystemStated s;
  s.time = h.time;
  read_vehicle(r, s.asv, s.asv_nu_dot);
  read_propulsion(r, s.asv_propulsion);
  read_vehicle(r, s.auv, s.auv_nu_dot);
  read_propulsion(r, s.auv_propulsion);
  read_tether(r, s.tether);
  check_pair(input, s);
  return s;
}

ks::SystemStated read_pair(std::string_view bytes, const std::string& input) {
  Reader r(bytes, ArchiveKind::pair_state, input);
  ks::SystemStated s = read_pair_sections(r, input);
  r.end();
  return s;
}

ks::FleetStated read_fleet(std::string_view bytes, const std::string& input) {
  Reader r(bytes, ArchiveKind::fleet_state, input);
  const Head h = read_head(r);  // the counts are bounded by the sections that are there
  ks::FleetStated s;
  s.time = h.time;
  s.vehicles.resize(h.vehicles);
  s.vehicle_nu_dot.resize(h.vehicles);
  s.propulsion.resize(h.vehicles);
  s.point_masses.resize(h.point_masses);
  s.point_mass_acceleration.resize(h.point_masses);
  s.tethers.resize(h.tethers);
  for (std::size_t i = 0; i < h.vehicles; ++i) {
    read_vehicle(r, s.vehicles[i], s.vehicle_nu_dot[i]);
    read_propulsion(r, s.propulsion[i]);
  }
  for (std::size_t j = 0; j < h.point_masses; ++j)
    read_point_mass(r, s.point_masses[j], s.point_mass_acceleration[j]);
  for (std::size_t k = 0; k < h.tethers; ++k) read_tether(r, s.tethers[k]);
  r.end();
  check_fleet(input, s);
  return s;
}

// ---- files --------------------------------------------------------------------------------------

[[noreturn]] void io_fail(const std::string& path, const std::string& what, int err) {
  throw kelp::error(path + ": " + what + ": " + std::strerror(err));
}

// Closes a descriptor on every path out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

void write_file_atomically(const std::string& path, const std::string& bytes) {
  // A new file beside `path` (same directory, so the rename cannot cross file systems), named
  // after this process and a counter, created exclusively (never someone else's file).
  static std::atomic<unsigned> counter{0};
  std::string tmp;
  Fd f;
  for (int attempt = 0; attempt < 100 && f.fd < 0; ++attempt) {
    tmp = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
    f.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (f.fd < 0 && errno != EEXIST) io_fail(path, "cannot create " + tmp, errno);
  }
  if (f.fd < 0) io_fail(path, "cannot create a temporary file beside it", EEXIST);
  const auto fail = [&](const std::string& what) {
    const int err = errno;
    ::close(f.fd);
    f.fd = -1;
    ::unlink(tmp.c_str());
    io_fail(path, what, err);
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(f.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("cannot write " + tmp);
    done += std::size_t(n);
  }
  if (::fsync(f.fd) != 0) fail("cannot flush " + tmp);
  if (::close(f.fd) != 0) {
    f.fd = -1;
    const int err = errno;
    ::unlink(tmp.c_str());
    io_fail(path, "cannot close " + tmp, err);
  }
  f.fd = -1;
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    io_fail(path, "cannot rename " + tmp + " over it", err);
  }
  // The rename itself on disk: flush the directory (best effort: some file systems refuse).
  const std::size_t slash = path.find_last_of('/');
  const std::string dir =
      slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  Fd d;
  d.fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (d.fd >= 0) (void)::fsync(d.fd);
}

std::string read_file(const std::string& path) {
  Fd f;
  f.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f.fd < 0) io_fail(path, "cannot open", errno);
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) io_fail(path, "cannot stat", errno);
  if (!S_ISREG(st.st_mode)) throw state_error(path + ": not a regular file");
  if (std::uint64_t(st.st_size) > max_state_file_bytes)
    throw state_error(path + ": " + std::to_string(st.st_size) +
                      " bytes, larger than any state file (at most " +
                      std::to_string(max_state_file_bytes) + ")");
  std::string bytes(std::size_t(st.st_size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(f.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) io_fail(path, "cannot read", errno);
    if (n == 0) break;  // shorter than stat said (changed meanwhile): the reader says truncated
    done += std::size_t(n);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace

namespace state_sections {

void write_pair(Writer& a, const ks::SystemStated& state, const std::string& input) {
  check_pair(input, state);
  write_head(a, state.time, 2, 0, 1);
  write_vehicle(a, state.asv, state.asv_nu_dot);
  write_propulsion(a, state.asv_propulsion);
  write_vehicle(a, state.auv, state.auv_nu_dot);
  write_propulsion(a, state.auv_propulsion);
  write_tether(a, state.tether);
}

ks::SystemStated read_pair(Reader& r, const ks::SystemModeld& model, const std::string& input) {
  ks::SystemStated s = read_pair_sections(r, input);
  check_pair_fits(input, model, s);
  return s;
}

void write_file_durably(const std::string& path, const std::string& bytes) {
  write_file_atomically(path, bytes);
}

std::string read_whole_file(const std::string& path) { return read_file(path); }

}  // namespace state_sections

std::string save_state(const ks::SystemStated& state) {
  Writer a(ArchiveKind::pair_state, version());
  state_sections::write_pair(a, state, "state");
  return a.bytes();
}

std::string save_state(const ks::FleetStated& state) {
  check_fleet("state", state);
  Writer a(ArchiveKind::fleet_state, version());
  write_head(a, state.time, state.vehicles.size(), state.point_masses.size(), state.tethers.size());
  for (std::size_t i = 0; i < state.vehicles.size(); ++i) {
    write_vehicle(a, state.vehicles[i], state.vehicle_nu_dot[i]);
    write_propulsion(a, state.propulsion[i]);
  }
  for (std::size_t j = 0; j < state.point_masses.size(); ++j)
    write_point_mass(a, state.point_masses[j], state.point_mass_acceleration[j]);
  for (const auto& t : state.tethers) write_tether(a, t);
  return a.bytes();
}

ks::SystemStated load_system_state(std::string_view bytes, const std::string& input) {
  return read_pair(bytes, input);
}

ks::FleetStated load_fleet_state(std::string_view bytes, const std::string& input) {
  return read_fleet(bytes, input);
}

ks::SystemStated load_state(std::string_view bytes, const ks::SystemModeld& model,
                            const std::string& input) {
  ks::SystemStated s = read_pair(bytes, input);
  check_pair_fits(input, model, s);
  return s;
}

ks::FleetStated load_state(std::string_view bytes, const ks::FleetModeld& model,
                           const std::string& input) {
  ks::FleetStated s = read_fleet(bytes, input);
  check_fleet_fits(input, model, s);
  return s;
}

void save_state_file(const std::string& path, const ks::SystemStated& state) {
  write_file_atomically(path, save_state(state));
}

void save_state_file(const std::string& path, const ks::FleetStated& state) {
  write_file_atomically(path, save_state(state));
}

ks::SystemStated load_state_file(const std::string& path, const ks::SystemModeld& model) {
  return load_state(read_file(path), model, path);
}

ks::FleetStated load_state_file(const std::string& path, const ks::FleetModeld& model) {
  return load_state(read_file(path), model, path);
}

}  // namespace sim
}  // namespace kelp
