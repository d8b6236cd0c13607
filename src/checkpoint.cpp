// A closed-loop run's checkpoint (kelp/sim/checkpoint.hpp, checkpoint.hpp): the loop's memory
// through the memory-visitor protocol (kelp/core/memory.hpp) in kelp's archive (archive.hpp),
// the output files' lengths, and the resume that reopens them there. The format is
// docs/checkpoints.md.
#include "checkpoint.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "archive.hpp"
#include "kelp/sim/checkpoint.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/version.hpp"
#include "state_sections.hpp"

namespace kelp {
namespace sim {

namespace {

using archive::ArchiveKind;
using archive::tag;

constexpr archive::Tag run_tag = tag("RUNH");
constexpr archive::Tag loop_tag = tag("LOOP");
constexpr archive::Tag auv_tag = tag("AUVC");
constexpr archive::Tag asv_tag = tag("ASVC");
constexpr archive::Tag navigation_tag = tag("NAVI");
constexpr archive::Tag monitor_tag = tag("MONI");
constexpr archive::Tag files_tag = tag("FILE");
constexpr archive::Tag bag_tag = tag("MCAP");

// The longest texts a checkpoint holds: the scenario, a random engine's state, an MCAP record
// list's element (a chunk is at most its size plus one message).
constexpr std::size_t max_text = std::size_t(1) << 30;

template <class T>
struct is_std_array : std::false_type {};
template <class T, std::size_t N>
struct is_std_array<std::array<T, N>> : std::true_type {};

// Saves memory (kelp/core/memory.hpp) into the open section of a writer.
struct SaveVisitor {
  archive::Writer& a;

  template <class... T>
  void operator()(const T&... x) {
    (put(x), ...);
  }
  template <class I, class H>
  void bounded(const I& i, const H& /*hi*/) {
    put(i);
  }
  template <class E>
  void choice(const E& e, int /*n*/) {
    a.u32(std::uint32_t(e));
  }
  template <class T, class F>
  void list(const std::vector<T>& v, std::size_t /*max*/, F&& f) {
    a.u32(std::uint32_t(v.size()));
    for (const T& x : v) f(x);
  }

  template <class T>
  void put(const T& x) {
    if constexpr (std::is_same_v<T, double>) {
      a.f64(x);
    } else if constexpr (std::is_same_v<T, bool>) {
      a.u8(x ? 1 : 0);
    } else if constexpr (std::is_integral_v<T>) {
      a.u64(static_cast<std::uint64_t>(x));  // two's complement for the signed
    } else if constexpr (std::is_same_v<T, std::vector<std::uint8_t>>) {
      a.text(std::string_view(reinterpret_cast<const char*>(x.data()), x.size()));
    } else if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
      static_assert(std::is_same_v<typename T::Scalar, double>, "checkpoints hold doubles");
      a.u32(std::uint32_t(x.rows()));
      a.u32(std::uint32_t(x.cols()));
      for (Eigen::Index j = 0; j < x.cols(); ++j)
        for (Eigen::Index i = 0; i < x.rows(); ++i) a.f64(x(i, j));
    } else if constexpr (std::is_same_v<T, Eigen::Quaterniond>) {
      a.f64s(x.coeffs().data(), 4);
    } else if constexpr (std::is_same_v<T, std::mt19937_64>) {
      // The engine's textual representation, which the C++ standard fixes ([rand.eng.mers]).
      std::ostringstream s;
      s << x;
      a.text(s.str());
    } else if constexpr (is_std_array<T>::value) {
      for (const auto& e : x) put(e);
    } else {
      x.visit_memory(*this);
    }
  }
};

// Restores memory from a section, checking every length, bound and choice.
struct LoadVisitor {
  archive::Section& s;

  template <class... T>
  void operator()(T&... x) {
    (get(x), ...);
  }
  template <class I, class H>
  void bounded(I& i, const H& hi) {
    get(i);
    if (i < I(0) || i > I(hi))
      s.fail("an index (" + std::to_string(i) + ") out of its range 0 ... " + std::to_string(hi));
  }
  template <class E>
  void choice(E& e, int n) {
    const std::uint32_t v = s.u32();
    if (v >= std::uint32_t(n)) s.fail("a choice (" + std::to_string(v) + ") out of its range");
    e = static_cast<E>(v);
  }
  template <class T, class F>
  void list(std::vector<T>& v, std::size_t max, F&& f) {
    // Each element takes at least one byte: no list longer than the bytes that are there.
    const std::uint32_t n =
        s.count(std::uint32_t(std::min<std::size_t>(max, 0xFFFFFFFFu)), 1, "a list's length");
    v.resize(n);
    for (T& x : v) f(x);
  }

  template <class T>
  void get(T& x) {
    if constexpr (std::is_same_v<T, double>) {
      x = s.f64();
    } else if constexpr (std::is_same_v<T, bool>) {
      const std::uint8_t b = s.u8();
      if (b > 1) s.fail("a flag that is neither 0 nor 1");
      x = b == 1;
    } else if constexpr (std::is_integral_v<T>) {
      const std::uint64_t u = s.u64();
      if constexpr (std::is_signed_v<T>) {
        const auto v = static_cast<std::int64_t>(u);
        if (v < std::int64_t(std::numeric_limits<T>::min()) ||
            v > std::int64_t(std::numeric_limits<T>::max()))
          s.fail("an integer out of its type's range");
        x = static_cast<T>(v);
      } else {
        if (u > std::uint64_t(std::numeric_limits<T>::max()))
          s.fail("an integer out of its type's range");
        x = static_cast<T>(u);
      }
    } else if constexpr (std::is_same_v<T, std::vector<std::uint8_t>>) {
      const std::string_view b = s.text(max_text, "bytes");
      x.assign(b.begin(), b.end());
    } else if constexpr (std::is_base_of_v<Eigen::MatrixBase<T>, T>) {
      const std::uint32_t rows = s.u32(), cols = s.u32();
      if (Eigen::Index(rows) != x.rows() || Eigen::Index(cols) != x.cols())
        s.fail("a matrix of " + std::to_string(rows) + "x" + std::to_string(cols) + " where " +
               std::to_string(x.rows()) + "x" + std::to_string(x.cols()) + " is expected");
      for (Eigen::Index j = 0; j < x.cols(); ++j)
        for (Eigen::Index i = 0; i < x.rows(); ++i) x(i, j) = s.f64();
    } else if constexpr (std::is_same_v<T, Eigen::Quaterniond>) {
      s.f64s(x.coeffs().data(), 4);
    } else if constexpr (std::is_same_v<T, std::mt19937_64>) {
      std::istringstream in{std::string(s.text(max_text, "a random engine"))};
      std::mt19937_64 e;
      in >> e;
      if (!in) s.fail("a random engine's state that does not read back");
      x = e;
    } else if constexpr (is_std_array<T>::value) {
      for (auto& e : x) get(e);
    } else {
      x.visit_memory(*this);
    }
  }
};

// The checkpoint's header section (RUNH): what read_checkpoint_info returns, checked (steps in
// range, a finite interval); the loader reads the same before the run's state.
CheckpointInfo read_run_header(archive::Reader& r) {
  archive::Section s = r.next(run_tag);
  CheckpointInfo info;
  info.kelp_version = r.writer_version();
  info.scenario_json = std::string(s.text(max_text, "the scenario"));
  info.scenario_file = std::string(s.text(max_text, "the scenario file"));
  const std::uint64_t k = s.u64(), steps = s.u64();
  if (k > steps || steps > std::uint64_t(std::numeric_limits<long>::max()))
    s.fail("step counts out of range");
  info.steps_taken = long(k);
  info.total_steps = long(steps);
  info.time = s.f64();
  info.checkpoint_every = s.f64();
  if (!(std::isfinite(info.checkpoint_every) && info.checkpoint_every >= 0))
    s.fail("a checkpoint interval that is not a number >= 0");
  s.end();
  return info;
}

}  // namespace

// The members of the loop, the log and the bag that are not theirs to visit (friend of each).
struct CheckpointAccess {
  // What the loop knows beyond its system state, its controllers, its navigation and its
  // monitors: the step count, the winch's command, the statistics, the partings, the last
  // forces and the sample.
  template <class Loop, class V>
  static void loop_memory(Loop& l, V& v) {
    v(l.k_, l.inputs_.winch_payout_rate);
    auto& m = l.metrics_;
    v(m.samples, m.slack_samples, m.auv_squared_error_sum, m.auv_max_error,
      m.asv_squared_distance_sum, m.asv_max_distance, m.max_tension, m.auv_tension_sum,
      m.late_depth_error, m.late_auv_error, m.late_asv_distance);
    auto& st = l.solver_stats_;
    v(st.steps, st.tether_steps, st.newton_iterations, st.max_step_newton_iterations,
      st.retried_steps, st.explicit_fallbacks, st.force_evaluations, st.worst_residual,
      st.worst_rejected_residual);
    auto& r = l.remesh_;
    v(r.inserted, r.removed, r.kinetic_energy_lost, r.impulse_on_start, r.impulse_on_end);
    v(l.line_mass_start_, l.length_start_, l.min_length_, l.max_length_);
    v.list(l.failures_, l.failures_.capacity(), [&](auto& f) {
      v(f.time);
      v.bounded(f.segment, std::numeric_limits<int>::max());
      v(f.tension, f.position);
    });
    v(l.report_.force_on_asv, l.report_.force_on_auv);
    auto& x = l.sample_;
    v(x.t, x.auv_target, x.auv_error, x.asv_error, x.asv_thrust, x.asv_command, x.auv_thrust,
      x.auv_command, x.tension_asv, x.tension_auv, x.tether_length, x.payout_rate, x.winch_pull,
      x.asv_voltage, x.asv_soc, x.auv_voltage, x.auv_soc, x.asv_current, x.auv_current,
      x.tether_turns, x.parted_segments, x.tether_winding, x.winding_obstacle, x.force_on_asv,
      x.force_on_auv, x.auv_nu_dot, x.gravity);
  }

  // An MCAP writer's bookkeeping: the file's length and its data section's CRC, the open chunk
  // and its message indexes, the records the summary repeats, the statistics.
  template <class W, class V>
  static void mcap_memory(W& w, V& v) {
    v(w.pos_, w.data_crc_, w.chunk_);
    const auto bytes = [&](auto& b) { v(b); };
    v.list(w.schemas_, 1u << 16, bytes);
    v.list(w.channels_, 1u << 16, bytes);
    v.list(w.chunk_indexes_, std::numeric_limits<std::uint32_t>::max(), bytes);
    v.list(w.channel_counts_, 1u << 16, [&](auto& c) { v(c); });
    v.list(w.index_, 1u << 16, [&](auto& c) {
      v.list(c, std::numeric_limits<std::uint32_t>::max(), [&](auto& e) { v(e.first, e.second); });
    });
    v(w.chunk_start_, w.chunk_end_, w.chunk_messages_, w.start_, w.end_, w.messages_);
  }

  static void save(archive::Writer& a, const ClosedLoop& l, RunLog* log, RunBag* bag,
                   double every) {
    SaveVisitor v{a};
    a.begin(run_tag);
    a.text(scenario_json(l.scenario_));
    a.text(l.options_.scenario_file);
    a.u64(std::uint64_t(l.k_));
    a.u64(std::uint64_t(l.steps_));
    a.f64(l.state_.time);
    a.f64(every);
    a.end();
    state_sections::write_pair(a, l.state_, "the run's state");
    a.begin(loop_tag);
    loop_memory(l, v);
    a.end();
    a.begin(auv_tag);
    v(l.auv_);
    a.end();
    a.begin(asv_tag);
    v(l.asv_);
    a.end();
    a.begin(navigation_tag);
    v(l.navigation_ != nullptr);
    if (l.navigation_) v(*l.navigation_);
    a.end();
    a.begin(monitor_tag);
    v(l.turns_, l.entanglement_);
    a.end();
    a.begin(files_tag);
    v(log != nullptr);
    if (log) {
      v(log->ts_.written_, log->nodes_.written_, log->events_.written_, log->next_flush_);
    }
    a.end();
    a.begin(bag_tag);
    const BagRecorder* recorder = bag ? bag->bag_.get() : nullptr;
    v(recorder != nullptr);
    if (recorder) {
      v(recorder->marker_period_, recorder->next_marker_, recorder->bag_.channel_,
        recorder->bag_.sequence_, std::uint64_t(recorder->bag_.mcap_.options_.chunk_size));
      mcap_memory(recorder->bag_.mcap_, v);
    }
    a.end();
  }

  // Flushes what the files hold to the disk (before the checkpoint that counts their bytes).
  static void flush_files(RunLog* log, RunBag* bag) {
    const auto sync = [](int fd, const std::string& path) {
      if (fd >= 0 && ::fdatasync(fd) != 0 && errno != EINVAL)
        throw kelp::error("cannot flush " + path + " to disk: " + std::strerror(errno));
    };
    if (log) {
      log->flush();
      for (const LineFile* f : {&log->ts_, &log->nodes_, &log->events_}) sync(f->fd_, f->path_);
    }
    if (bag && bag->bag_) {
      ros2::McapWriter& w = bag->bag_->bag_.mcap_;
      if (w.file_) {
        if (std::fflush(w.file_) != 0) throw kelp::error("cannot write " + w.path_);
        sync(::fileno(w.file_), w.path_);
      }
    }
  }

  // The loop's part of a checkpoint, read into `l`; the files' part is returned.
  struct Files {
    bool log = false;
    std::uint64_t ts = 0, nodes = 0, events = 0;
    double next_flush = 0;
    std::unique_ptr<BagRecorder> recorder;  // filled, its file not open yet
  };

  static Files load(archive::Reader& r, const std::string& input, ClosedLoop& l) {
    const CheckpointInfo head = read_run_header(r);
    if (head.scenario_json != scenario_json(l.scenario_))
      r.fail(
          "the checkpoint is of another scenario than the run's (its scenario differs; "
          "resume a run with the scenario it was started with)");
    if (head.total_steps != l.steps_)
      r.fail("the checkpoint's run has " + std::to_string(head.total_steps) + " steps, this one " +
             std::to_string(l.steps_));
    l.state_ = state_sections::read_pair(r, l.model_, input);
    kelp::system::fit_workspace(l.model_, l.workspace_, l.state_);
    const auto visit = [&](archive::Tag t, auto&& f) {
      archive::Section s = r.next(t);
      LoadVisitor v{s};
      try {
        f(v);
      } catch (const state_error&) {
        throw;
      } catch (const kelp::invalid_argument& e) {  // a value the object refuses (a voltage)
        s.fail(e.what());
      }
      s.end();
    };
    visit(loop_tag, [&](LoadVisitor& v) { loop_memory(l, v); });
    if (l.k_ != head.steps_taken)
      r.fail("the loop's step count differs from the header's (" +
             std::to_string(head.steps_taken) + ")");
    l.sample_.tether_model = &l.model_.tether_of(l.state_);
    visit(auv_tag, [&](LoadVisitor& v) { v(l.auv_); });
    visit(asv_tag, [&](LoadVisitor& v) { v(l.asv_); });
    visit(navigation_tag, [&](LoadVisitor& v) {
      bool has = false;
      v(has);
      if (has != (l.navigation_ != nullptr))
        v.s.fail(has ? "navigation from sensors, but the run's scenario has none"
                     : "no navigation, but the run's scenario has sensors");
      if (l.navigation_) v(*l.navigation_);
    });
    visit(monitor_tag, [&](LoadVisitor& v) { v(l.turns_, l.entanglement_); });
    Files f;
    visit(files_tag, [&](LoadVisitor& v) {
      v(f.log);
      if (f.log) v(f.ts, f.nodes, f.events, f.next_flush);
    });
    visit(bag_tag, [&](LoadVisitor& v) {
      bool has = false;
      v(has);
      if (!has) return;
      double period = 0, next = 0;
      v(period, next);
      if (!(period > 0 && std::isfinite(period))) v.s.fail("a bag's marker period that is not > 0");
      f.recorder.reset(new BagRecorder(1.0 / period));
      BagRecorder& b = *f.recorder;
      b.marker_period_ = period;
      b.next_marker_ = next;
      v(b.bag_.channel_, b.bag_.sequence_);
      std::uint64_t chunk_size = 0;
      v(chunk_size);
      if (chunk_size != ros2::McapOptions{}.chunk_size)
        v.s.fail("a bag of chunks of " + std::to_string(chunk_size) + " bytes, the run writes " +
                 std::to_string(ros2::McapOptions{}.chunk_size));
      mcap_memory(b.bag_.mcap_, v);
      const ros2::McapWriter& w = b.bag_.mcap_;
      if (w.index_.size() != w.channels_.size() || w.channel_counts_.size() != w.channels_.size())
        v.s.fail("a bag whose message indexes do not match its channels");
      for (const auto& c : b.bag_.channel_)
        if (c == 0 || c > w.channels_.size()) v.s.fail("a bag topic on an unknown channel");
    });
    r.end();
    return f;
  }

  // Reopens `path` (which must hold at least `length` bytes) for appending at `length`.
  static void reopen(LineFile& f, const std::filesystem::path& path, std::uint64_t length) {
    f.path_ = path.string();
    f.fd_ = ::open(f.path_.c_str(), O_WRONLY | O_CLOEXEC);
    if (f.fd_ < 0) throw kelp::error("cannot write " + f.path_ + ": " + std::strerror(errno));
    if (::ftruncate(f.fd_, off_t(length)) != 0 || ::lseek(f.fd_, 0, SEEK_END) < 0)
      throw kelp::error("cannot truncate " + f.path_ + ": " + std::strerror(errno));
    f.text_.clear();
    f.text_.reserve(128 * 1024);
    f.ended_ = 0;
    f.written_ = length;
  }

  static std::unique_ptr<RunLog> reopen_log(const std::filesystem::path& dir, const Files& f) {
    std::unique_ptr<RunLog> log(new RunLog());
    reopen(log->ts_, dir / "timeseries.csv", f.ts);
    reopen(log->nodes_, dir / "nodes.csv", f.nodes);
    reopen(log->events_, dir / "events.csv", f.events);
    log->next_flush_ = f.next_flush;
    return log;
  }

  static std::unique_ptr<RunBag> reopen_bag(const std::filesystem::path& file, double marker_rate,
                                            std::unique_ptr<BagRecorder> recorder) {
    auto bag = std::make_unique<RunBag>(file, marker_rate);
    ros2::McapWriter& w = recorder->bag_.mcap_;
    w.path_ = file.string();
    w.file_ = std::fopen(w.path_.c_str(), "r+b");
    if (!w.file_) throw kelp::error("McapWriter: cannot write " + w.path_);
    if (::ftruncate(::fileno(w.file_), off_t(w.pos_)) != 0 || std::fseek(w.file_, 0, SEEK_END))
      throw kelp::error("cannot truncate " + w.path_ + ": " + std::strerror(errno));
    w.chunk_.reserve(w.options_.chunk_size + 4096);
    bag->bag_ = std::move(recorder);
    return bag;
  }

  static void attach(ClosedLoop& l, RunLog* log, std::function<void(const LogRow&)> on_sample) {
    l.options_.log = log;
    l.options_.on_sample = std::move(on_sample);
  }
};

namespace {

// The length of the file `path`, or a state_error when it is missing or shorter than `length`
// (the checkpoint is not this directory's).
void check_length(const std::string& input, const std::filesystem::path& path,
                  std::uint64_t length) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
    throw state_error(input + ": the run's " + path.filename().string() +
                      " is missing: the checkpoint is not this directory's");
  if (std::uint64_t(st.st_size) < length)
    throw state_error(input + ": the run's " + path.filename().string() + " holds " +
                      std::to_string(st.st_size) + " bytes, the checkpoint counts " +
                      std::to_string(length) + ": the file lost what the checkpoint relies on");
}

}  // namespace

void write_checkpoint(const std::string& path, const ClosedLoop& loop, RunLog* log, RunBag* bag,
                      double every) {
  CheckpointAccess::flush_files(log, bag);
  archive::Writer a(ArchiveKind::run_checkpoint, version());
  CheckpointAccess::save(a, loop, log, bag, every);
  state_sections::write_file_durably(path, a.bytes());
}

namespace {

// The checkpoint file's bytes; a state_error when there is none.
std::string read_checkpoint_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw state_error(path +
                      ": no checkpoint: the run has none to resume from (a run writes one "
                      "with checkpoint_every, kelp-tethered-pair --checkpoint-every)");
  return state_sections::read_whole_file(path);
}

// The reader of a checkpoint's bytes, its kelp version checked.
archive::Reader checkpoint_reader(std::string_view bytes, const std::string& input) {
  archive::Reader r(bytes, ArchiveKind::run_checkpoint, input);
  if (r.writer_version() != version())
    r.fail("written by kelp " + r.writer_version() + ", this is kelp " + version() +
           ": a checkpoint resumes only in the kelp that wrote it");
  return r;
}

}  // namespace

std::string checkpoint_bytes(const ClosedLoop& loop) {
  archive::Writer a(ArchiveKind::run_checkpoint, version());
  CheckpointAccess::save(a, loop, nullptr, nullptr, 0.0);
  return a.bytes();
}

void restore_checkpoint(std::string_view bytes, const std::string& input, ClosedLoop& loop) {
  archive::Reader r = checkpoint_reader(bytes, input);
  const CheckpointAccess::Files f = CheckpointAccess::load(r, input, loop);
  if (f.log || f.recorder)
    throw state_error(input + ": the checkpoint's run wrote files, this one writes none");
}

void remove_checkpoint_temporaries(const std::string& path) {
  const std::filesystem::path p(path);
  const std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : ".";
  const std::string prefix = p.filename().string() + ".tmp.";
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) == 0) {
      std::error_code ignored;
      std::filesystem::remove(it->path(), ignored);
    }
  }
}

ResumedFiles resume_checkpoint(const std::string& path, ClosedLoop& loop,
                               const std::string& log_dir, const std::string& mcap,
                               double marker_rate, std::function<void(const LogRow&)> on_sample) {
  const std::string bytes = read_checkpoint_file(path);
  archive::Reader r = checkpoint_reader(bytes, path);
  CheckpointAccess::Files f = CheckpointAccess::load(r, path, loop);
  // Every check before any file is touched.
  const std::filesystem::path dir(log_dir);
  if (f.log != !log_dir.empty())
    throw state_error(path + (f.log ? ": the run wrote a CSV log, this one has no directory"
                                    : ": the run wrote no CSV log"));
  if (f.log) {
    check_length(path, dir / "timeseries.csv", f.ts);
    check_length(path, dir / "nodes.csv", f.nodes);
    check_length(path, dir / "events.csv", f.events);
  }
  if (bool(f.recorder) != !mcap.empty())
    throw state_error(path + (f.recorder ? ": the run wrote a bag (run.mcap), this one does not"
                                         : ": the run wrote no bag (run.mcap), this one does"));
  if (f.recorder) check_length(path, mcap, f.recorder->bag().mcap().bytes_written());
  ResumedFiles out;
  if (f.log) out.log = CheckpointAccess::reopen_log(dir, f);
  if (f.recorder) out.bag = CheckpointAccess::reopen_bag(mcap, marker_rate, std::move(f.recorder));
  std::function<void(const LogRow&)> sample = std::move(on_sample);
  if (out.bag)
    sample = [b = out.bag.get(), user = std::move(sample)](const LogRow& row) {
      b->record(row);
      if (user) user(row);
    };
  CheckpointAccess::attach(loop, out.log.get(), std::move(sample));
  return out;
}

CheckpointInfo read_checkpoint_info(const std::string& path) {
  const std::string bytes = read_checkpoint_file(path);
  archive::Reader r = checkpoint_reader(bytes, path);
  return read_run_header(r);
}

}  // namespace sim
}  // namespace kelp
