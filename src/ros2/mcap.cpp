// The MCAP writer and the ROS 2 bag on it (kelp/sim/ros2/mcap.hpp): CRC32, McapWriter's and
// BagWriter's members, the QoS metadata.
#include "kelp/sim/ros2/mcap.hpp"

#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <initializer_list>

namespace kelp {
namespace ros2 {

std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc) {
  using Tables = std::array<std::array<std::uint32_t, 256>, 8>;
  static const Tables t = [] {
    Tables x{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      x[0][i] = c;
    }
    for (std::size_t k = 1; k < 8; ++k)
      for (std::size_t i = 0; i < 256; ++i)
        x[k][i] = (x[k - 1][i] >> 8) ^ x[0][x[k - 1][i] & 0xFFu];
    return x;
  }();
  const auto* p = static_cast<const std::uint8_t*>(data);
  crc = ~crc;
  for (; n >= 8; n -= 8, p += 8) {
    const std::uint32_t a = crc ^ (std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 |
                                   std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24);
    const std::uint32_t b = std::uint32_t(p[4]) | std::uint32_t(p[5]) << 8 |
                            std::uint32_t(p[6]) << 16 | std::uint32_t(p[7]) << 24;
    crc = t[7][a & 0xFFu] ^ t[6][(a >> 8) & 0xFFu] ^ t[5][(a >> 16) & 0xFFu] ^ t[4][a >> 24] ^
          t[3][b & 0xFFu] ^ t[2][(b >> 8) & 0xFFu] ^ t[1][(b >> 16) & 0xFFu] ^ t[0][b >> 24];
  }
  for (; n > 0; --n, ++p) crc = t[0][(crc ^ *p) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

namespace {
// Little-endian integers, length-prefixed strings and records appended to a byte buffer.
void put_u8(std::vector<std::uint8_t>& b, std::uint8_t v) { b.push_back(v); }
void put_u16(std::vector<std::uint8_t>& b, std::uint16_t v) {
  for (int i = 0; i < 2; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u32(std::vector<std::uint8_t>& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u64(std::vector<std::uint8_t>& b, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_string(std::vector<std::uint8_t>& b, const std::string& s) {
  put_u32(b, static_cast<std::uint32_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
void put_record(std::vector<std::uint8_t>& b, McapOp op, const std::vector<std::uint8_t>& content) {
  put_u8(b, static_cast<std::uint8_t>(op));
  put_u64(b, content.size());
  b.insert(b.end(), content.begin(), content.end());
}
}  // namespace

McapWriter::McapWriter(const std::filesystem::path& path, const McapOptions& options) {
  open(path, options);
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {
  }
}

void McapWriter::open(const std::filesystem::path& path, const McapOptions& options) {
  KELP_CHECK(!file_, "McapWriter::open: already open");
  KELP_CHECK(options.chunk_size > 0, "McapWriter: chunk_size must be > 0");
  options_ = options;
  path_ = path.string();
  file_ = std::fopen(path_.c_str(), "wb");
  if (!file_) throw kelp::error("McapWriter: cannot create " + path_);
  pos_ = 0;
  data_crc_ = 0;
  chunk_.reserve(options.chunk_size + 4096);
  emit(mcap_magic.data(), mcap_magic.size());
  rec_.clear();
  put_string(rec_, options.profile);
  put_string(rec_, options.library);
  emit_record(McapOp::header, rec_);
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding,
                                     const std::string& data) {
  KELP_CHECK(file_, "McapWriter::add_schema: not open");
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  std::vector<std::uint8_t> r;
  put_u16(r, id);
  put_string(r, name);
  put_string(r, encoding);
  put_string(r, data);  // uint32 length-prefixed bytes: the same layout as a string
  schemas_.push_back(r);
  emit_record(McapOp::schema, r);
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  KELP_CHECK(file_, "McapWriter::add_channel: not open");
  KELP_CHECK(schema_id <= schemas_.size(), "McapWriter::add_channel: unknown schema id");
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  std::vector<std::uint8_t> r;
  put_u16(r, id);
  put_u16(r, schema_id);
  put_string(r, topic);
  put_string(r, message_encoding);
  std::vector<std::uint8_t> m;
  for (const auto& [k, v] : metadata) {
    put_string(m, k);
    put_string(m, v);
  }
  put_u32(r, static_cast<std::uint32_t>(m.size()));
  r.insert(r.end(), m.begin(), m.end());
  channels_.push_back(r);
  emit_record(McapOp::channel, r);
  channel_counts_.push_back(0);
  index_.emplace_back();
  return id;
}

void McapWriter::write(std::uint16_t channel, std::uint32_t sequence, std::uint64_t log_time,
                       const std::uint8_t* data, std::size_t size) {
  KELP_CHECK(file_, "McapWriter::write: not open");
  KELP_CHECK(channel >= 1 && channel <= channels_.size(), "McapWriter::write: unknown channel id");
  const std::size_t c = channel - 1u;
  index_[c].emplace_back(log_time, static_cast<std::uint64_t>(chunk_.size()));
  put_u8(chunk_, static_cast<std::uint8_t>(McapOp::message));
  put_u64(chunk_, 2 + 4 + 8 + 8 + static_cast<std::uint64_t>(size));
  put_u16(chunk_, channel);
  put_u32(chunk_, sequence);
  put_u64(chunk_, log_time);
  put_u64(chunk_, log_time);
  chunk_.insert(chunk_.end(), data, data + size);
  if (chunk_messages_ == 0 || log_time < chunk_start_) chunk_start_ = log_time;
  if (chunk_messages_ == 0 || log_time > chunk_end_) chunk_end_ = log_time;
  if (messages_ == 0 || log_time < start_) start_ = log_time;
  if (messages_ == 0 || log_time > end_) end_ = log_time;
  ++chunk_messages_;
  ++messages_;
  ++channel_counts_[c];
  if (chunk_.size() >= options_.chunk_size) flush_chunk();
}

void McapWriter::close() {
  if (!file_) return;
  try {
    flush_chunk();
    // Data End: CRC32 of every byte before it.
    rec_.clear();
    put_u32(rec_, data_crc_);
    emit_record(McapOp::data_end, rec_);
    // The summary, built in memory (its CRC covers it through the footer's offsets).
    const std::uint64_t summary_start = pos_;
    std::vector<std::uint8_t> s;
    std::vector<std::array<std::uint64_t, 3>> groups;  // opcode, start, length
    const auto group = [&](McapOp op, const std::vector<std::vector<std::uint8_t>>& recs) {
      if (recs.empty()) return;
      const std::uint64_t start = summary_start + s.size();
      for (const auto& r : recs) put_record(s, op, r);
      groups.push_back({static_cast<std::uint64_t>(op), start, summary_start + s.size() - start});
    };
    group(McapOp::schema, schemas_);
    group(McapOp::channel, channels_);
    std::vector<std::uint8_t> st;
    put_u64(st, messages_);
    put_u16(st, static_cast<std::uint16_t>(schemas_.size()));
    put_u32(st, static_cast<std::uint32_t>(channels_.size()));
    put_u32(st, 0);  // attachments
    put_u32(st, 0);  // metadata
    put_u32(st, static_cast<std::uint32_t>(chunk_indexes_.size()));
    put_u64(st, messages_ ? start_ : 0);
    put_u64(st, messages_ ? end_ : 0);
    std::vector<std::uint8_t> counts;
    for (std::size_t c = 0; c < channel_counts_.size(); ++c) {
      if (channel_counts_[c] == 0) continue;
      put_u16(counts, static_cast<std::uint16_t>(c + 1));
      put_u64(counts, channel_counts_[c]);
    }
    put_u32(st, static_cast<std::uint32_t>(counts.size()));
    st.insert(st.end(), counts.begin(), counts.end());
    group(McapOp::statistics, {st});
    group(McapOp::chunk_index, chunk_indexes_);
    const std::uint64_t offsets_start = summary_start + s.size();
    for (const auto& g : groups) {
      std::vector<std::uint8_t> r;
      put_u8(r, static_cast<std::uint8_t>(g[0]));
      put_u64(r, g[1]);
      put_u64(r, g[2]);
      put_record(s, McapOp::summary_offset, r);
    }
    // Footer: summary start, summary offset start, CRC32 of the summary section through
    // the footer's summary_offset_start field.
    put_u8(s, static_cast<std::uint8_t>(McapOp::footer));
    put_u64(s, 8 + 8 + 4);
    put_u64(s, summary_start);
    put_u64(s, offsets_start);
    put_u32(s, crc32(s.data(), s.size()));
    s.insert(s.end(), mcap_magic.begin(), mcap_magic.end());
    emit(s.data(), s.size());
    finish();
  } catch (...) {
    finish_quietly();
    throw;
  }
}

// Writes bytes to the file, counting them and keeping the data section's CRC.
void McapWriter::emit(const void* p, std::size_t n) {
  if (n == 0) return;
  if (std::fwrite(p, 1, n, file_) != n) throw kelp::error("McapWriter: cannot write " + path_);
  data_crc_ = crc32(p, n, data_crc_);
  pos_ += n;
}
void McapWriter::emit_record(McapOp op, const std::vector<std::uint8_t>& content) {
  std::uint8_t head[9];
  head[0] = static_cast<std::uint8_t>(op);
  for (int i = 0; i < 8; ++i)
    head[1 + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(content.size()) >> (8 * i));
  emit(head, sizeof head);
  emit(content.data(), content.size());
}

void McapWriter::flush_chunk() {
  if (chunk_messages_ == 0) return;
  const std::uint64_t chunk_start = pos_;
  rec_.clear();
  put_u64(rec_, chunk_start_);
  put_u64(rec_, chunk_end_);
  put_u64(rec_, chunk_.size());
  put_u32(rec_, crc32(chunk_.data(), chunk_.size()));
  put_string(rec_, "");  // no compression
  put_u64(rec_, chunk_.size());
  std::uint8_t head[9];
  head[0] = static_cast<std::uint8_t>(McapOp::chunk);
  const std::uint64_t length = rec_.size() + chunk_.size();
  for (int i = 0; i < 8; ++i) head[1 + i] = static_cast<std::uint8_t>(length >> (8 * i));
  const std::uint64_t chunk_length = sizeof head + length;
  // Message Index records, one per channel with messages in the chunk, in channel order.
  const std::uint64_t index_start = chunk_start + chunk_length;
  offsets_.clear();
  indexes_.clear();
  for (std::size_t c = 0; c < index_.size(); ++c) {
    if (index_[c].empty()) continue;
    put_u16(offsets_, static_cast<std::uint16_t>(c + 1));
    put_u64(offsets_, index_start + indexes_.size());
    const std::uint32_t entries = static_cast<std::uint32_t>(16 * index_[c].size());
    put_u8(indexes_, static_cast<std::uint8_t>(McapOp::message_index));
    put_u64(indexes_, 2 + 4 + std::uint64_t(entries));
    put_u16(indexes_, static_cast<std::uint16_t>(c + 1));
    put_u32(indexes_, entries);
    for (const auto& [t, off] : index_[c]) {
      put_u64(indexes_, t);
      put_u64(indexes_, off);
    }
    index_[c].clear();
  }
  // The chunk and its indexes in one system call: a process stopped or killed at any point of its
  // own leaves a file that ends after a whole chunk and its indexes, which a streaming reader
  // reads to the end (only a kill while the kernel copies them can cut them).
  emit_at_once({{head, sizeof head},
                {rec_.data(), rec_.size()},
                {chunk_.data(), chunk_.size()},
                {indexes_.data(), indexes_.size()}});
  // The Chunk Index record for the summary.
  std::vector<std::uint8_t> ci;
  put_u64(ci, chunk_start_);
  put_u64(ci, chunk_end_);
  put_u64(ci, chunk_start);
  put_u64(ci, chunk_length);
  put_u32(ci, static_cast<std::uint32_t>(offsets_.size()));
  ci.insert(ci.end(), offsets_.begin(), offsets_.end());
  put_u64(ci, indexes_.size());
  put_string(ci, "");
  put_u64(ci, chunk_.size());  // compressed size: the records as stored
  put_u64(ci, chunk_.size());
  chunk_indexes_.push_back(std::move(ci));
  chunk_.clear();
  chunk_messages_ = 0;
}

void McapWriter::emit_at_once(std::initializer_list<std::pair<const void*, std::size_t>> parts) {
  // What the stdio buffer holds (the header, schemas and channels before the first chunk) first.
  if (std::fflush(file_) != 0) throw kelp::error("McapWriter: cannot write " + path_);
  std::array<iovec, 4> iov{};
  int n = 0;
  for (const auto& [p, size] : parts) {
    KELP_CHECK(n < int(iov.size()), "McapWriter::emit_at_once: too many parts");
    data_crc_ = crc32(p, size, data_crc_);
    pos_ += size;
    iov[std::size_t(n++)] = {const_cast<void*>(p), size};
  }
  const int fd = ::fileno(file_);
  int first = 0;
  while (first < n) {  // one writev(), repeated only for what the system did not take
    const ssize_t w = ::writev(fd, iov.data() + first, n - first);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw kelp::error("McapWriter: cannot write " + path_);
    auto left = std::size_t(w);
    while (first < n && left >= iov[std::size_t(first)].iov_len)
      left -= iov[std::size_t(first++)].iov_len;
    if (first < n) {
      iovec& v = iov[std::size_t(first)];
      v.iov_base = static_cast<char*>(v.iov_base) + left;
      v.iov_len -= left;
    }
  }
}

void McapWriter::finish() {
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw kelp::error("McapWriter: cannot write " + path_);
}
void McapWriter::finish_quietly() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
}

std::string offered_qos_yaml(const Qos& q) {
  std::string y = "- history: 1\n  depth: " + std::to_string(q.depth) +
                  "\n  reliability: " + std::to_string(static_cast<int>(q.reliability)) +
                  "\n  durability: " + std::to_string(static_cast<int>(q.durability)) +
                  "\n  deadline:\n    sec: 0\n    nsec: 0\n  lifespan:\n    sec: 0\n    nsec: 0\n"
                  "  liveliness: 1\n  liveliness_lease_duration:\n    sec: 0\n    nsec: 0\n"
                  "  avoid_ros_namespace_conventions: false";
  return y;
}

BagWriter::BagWriter(const std::filesystem::path& path, const McapOptions& options)
    : mcap_(path, options) {
  std::map<std::string, std::uint16_t> schema_ids;
  const auto schema = [&](const char* type, std::string text) {
    const auto it = schema_ids.find(type);
    if (it != schema_ids.end()) return it->second;
    const std::uint16_t id = mcap_.add_schema(type, "ros2msg", text);
    schema_ids.emplace(type, id);
    return id;
  };
  for (const Topic& t : topics()) {
    std::string text;
    switch (t.id) {
      case TopicId::clock:
        text = schema_text<rosgraph_msgs::Clock>();
        break;
      case TopicId::tf:
        text = schema_text<tf2_msgs::TFMessage>();
        break;
      case TopicId::boat_odom:
      case TopicId::rov_odom:
        text = schema_text<nav_msgs::Odometry>();
        break;
      case TopicId::rov_imu:
        text = schema_text<sensor_msgs::Imu>();
        break;
      case TopicId::end_forces:
        text = schema_text<geometry_msgs::WrenchStamped>();
        break;
      case TopicId::markers:
        text = schema_text<visualization_msgs::MarkerArray>();
        break;
      case TopicId::rov_thrusters:
      case TopicId::boat_thrusters:
        text = schema_text<sensor_msgs::JointState>();
        break;
      case TopicId::count:
        break;
    }
    channel_[static_cast<std::size_t>(t.id)] =
        mcap_.add_channel(schema(t.type, std::move(text)), t.name, "cdr",
                          {{"offered_qos_profiles", offered_qos_yaml(t.qos)}});
  }
}

void BagWriter::write(const Messages& m, bool markers) {
  const builtin_interfaces::Time& t = m.clock.clock;
  write(TopicId::clock, m.clock, t);
  write(TopicId::tf, m.tf, t);
  write(TopicId::boat_odom, m.boat_odom, t);
  write(TopicId::rov_odom, m.rov_odom, t);
  write(TopicId::rov_imu, m.rov_imu, t);
  write(TopicId::end_forces, m.boat_end_force, t);
  write(TopicId::end_forces, m.rov_end_force, t);
  if (markers) write(TopicId::markers, m.markers, t);
  write(TopicId::rov_thrusters, m.rov_thrusters, t);
  write(TopicId::boat_thrusters, m.boat_thrusters, t);
}

}  // namespace ros2
}  // namespace kelp
