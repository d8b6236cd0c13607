/// \file
/// \brief An MCAP writer (McapWriter: chunked, indexed, with CRCs) and a ROS 2 bag on it
/// (BagWriter: kelp's topics as `cdr` messages with `ros2msg` schemas, readable by `ros2 bag`
/// with the MCAP storage plugin and by Foxglove).
///
/// Written from the MCAP format specification (mcap.dev/spec, "MCAP Format Specification",
/// major version 0; foxglove/mcap website/docs/spec/index.md) and its registry of well-known
/// encodings and profiles (website/docs/spec/registry.md: profile `ros2`, schema encoding
/// `ros2msg`, message encoding `cdr`, channel metadata `offered_qos_profiles`). A file is:
///
///     magic, Header, [Schema, Channel] records, Chunk records (Message records inside,
///     uncompressed, CRC32 of the records) each followed by its Message Index records,
///     Data End (CRC32 of the data section), the summary section (Schema, Channel, Statistics,
///     Chunk Index records, grouped by opcode), one Summary Offset record per group, Footer
///     (CRC32 of the summary through the footer's offsets), magic.
///
/// Every record is an opcode byte, a uint64 content length and the content; integers little
/// endian; strings a uint32 byte length and UTF-8 bytes; maps and arrays a uint32 byte length
/// and their entries. CRC32 is ISO-HDLC (zlib's: polynomial 0x04C11DB7 reflected, initial and
/// final XOR 0xFFFFFFFF).
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/ros2/cdr.hpp"
#include "kelp/sim/ros2/messages.hpp"

namespace kelp {
namespace sim {
struct CheckpointAccess;  // a run's checkpoint (kelp/sim/checkpoint.hpp)
class BagRecorder;
}  // namespace sim
namespace ros2 {

/// \brief CRC32 (ISO-HDLC, zlib's crc32) of `n` bytes, continuing from `crc` (0 to start).
///
/// Table-driven, eight bytes a step ("slicing by 8": table k gives the CRC of a byte followed by
/// k zero bytes), since every byte of a bag goes through it twice (chunk and data section CRCs).
/// \param data the bytes (may be null when n is 0) \param n their count
/// \param crc the CRC of the bytes before them (0 to start)
/// \return the CRC of everything so far (pass it as `crc` to continue). No throw.
KELP_SIM_API std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc = 0);

/// \brief The MCAP magic bytes, at the start and the end of every file.
inline constexpr std::array<std::uint8_t, 8> mcap_magic = {0x89, 'M',  'C',  'A',
                                                           'P',  0x30, '\r', '\n'};

/// \brief MCAP record opcodes (the specification's "Records").
enum class McapOp : std::uint8_t {
  header = 0x01,          ///< Header: profile and library
  footer = 0x02,          ///< Footer: summary offsets and CRC
  schema = 0x03,          ///< Schema: a message type's definition
  channel = 0x04,         ///< Channel: a topic on a schema
  message = 0x05,         ///< Message: one message on a channel
  chunk = 0x06,           ///< Chunk: a block of schemas, channels and messages
  message_index = 0x07,   ///< Message Index: a chunk's messages of one channel
  chunk_index = 0x08,     ///< Chunk Index: where a chunk is and what it holds
  statistics = 0x0B,      ///< Statistics: counts and time range
  summary_offset = 0x0E,  ///< Summary Offset: where each group of the summary is
  data_end = 0x0F         ///< Data End: the data section's CRC
};

/// \brief Options of an McapWriter.
struct McapOptions {
  std::string profile = "ros2";      ///< the Header's profile (registry: `ros2`, `ros1`, or "")
  std::string library = "kelp";      ///< the Header's library (free form)
  std::size_t chunk_size = 1 << 20;  ///< records gathered before a chunk is written [bytes]
};

/// \brief Writes an MCAP file: schemas, channels, then messages, gathered into uncompressed
/// chunks of about `chunk_size` bytes, each indexed; close() writes the summary and footer.
///
/// After the first chunk the buffers are reused: writing a message allocates nothing (the chunk
/// index grows by one entry a chunk).
///
/// Each completed chunk is written with its message indexes in one system call (writev) before
/// the next message is gathered: a process killed mid-run (SIGKILL) leaves a file without summary
/// and footer that ends after a whole chunk and its indexes, which a streaming reader (the
/// McapStreamReader of \@mcap/core) reads to the end, every message of every completed chunk; only
/// the open chunk (at most `chunk_size` bytes) is lost. Only a kill while the kernel copies a chunk
/// (Linux checks for one between pages) can cut it. An indexed reader needs the footer, which
/// close() writes.
class KELP_SIM_API McapWriter {
 public:
  /// Options of a writer (McapOptions).
  using Options = McapOptions;

  McapWriter() = default;
  /// \brief Opens `path` for writing (see open()).
  /// \param path the file to create \param options the profile, library and chunk size
  /// \throws kelp::error when the file cannot be written.
  explicit McapWriter(const std::filesystem::path& path, const McapOptions& options = {});
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;
  /// \brief Closes the file (close()); errors are swallowed here: call close() to see them.
  ~McapWriter();

  /// \brief Creates `path` and writes the magic and the Header record.
  /// \param path the file to create (truncated when it exists)
  /// \param options the profile, library and chunk size
  /// \throws kelp::error when the file cannot be written; kelp::invalid_argument when open.
  void open(const std::filesystem::path& path, const McapOptions& options = {});

  /// \brief Is a file open? \return true between open() and close()
  bool is_open() const { return file_ != nullptr; }

  /// \brief Adds a schema (a Schema record in the data section and the summary).
  /// \param name the type's name (e.g. "nav_msgs/msg/Odometry")
  /// \param encoding the schema encoding (e.g. "ros2msg") \param data the schema's text
  /// \returns its id (1, 2, …).
  /// \throws kelp::error on a write failure; kelp::invalid_argument when not open.
  std::uint16_t add_schema(const std::string& name, const std::string& encoding,
                           const std::string& data);

  /// \brief Adds a channel on schema `schema_id` (a Channel record in the data section and the
  /// summary).
  /// \param schema_id an id add_schema() returned \param topic the topic's name
  /// \param message_encoding the messages' encoding (e.g. "cdr")
  /// \param metadata the channel's metadata (e.g. `offered_qos_profiles`)
  /// \returns its id (1, 2, …).
  /// \throws kelp::error on a write failure; kelp::invalid_argument when not open or for an
  /// unknown schema.
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic,
                            const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata = {});

  /// \brief Writes a message on `channel` at `log_time` [ns] (publish time the same).
  /// \param channel an id add_channel() returned \param sequence the message's sequence number
  /// on its channel \param log_time its time [ns] \param data its serialised bytes (CDR for
  /// ROS 2) \param size their count
  /// \throws kelp::error on a write failure; kelp::invalid_argument when not open or for an
  /// unknown channel.
  void write(std::uint16_t channel, std::uint32_t sequence, std::uint64_t log_time,
             const std::uint8_t* data, std::size_t size);

  /// \brief Messages written so far. \return the count
  std::uint64_t message_count() const { return messages_; }
  /// \brief Bytes written to the file so far (the open chunk not included).
  /// \return the count [bytes]
  std::uint64_t bytes_written() const { return pos_; }

  /// \brief Writes the last chunk, Data End, the summary, the summary offsets, the footer and
  /// the closing magic, and closes the file. Does nothing when not open.
  /// \throws kelp::error on a write failure (the file is closed anyway).
  void close();

 private:
  friend struct kelp::sim::CheckpointAccess;  // a run's checkpoint: this writer's bookkeeping
  // Writes bytes to the file, counting them and keeping the data section's CRC.
  void emit(const void* p, std::size_t n);
  void emit_record(McapOp op, const std::vector<std::uint8_t>& content);

  // Writes the open chunk (if it has messages) and its message indexes, at once (emit_at_once),
  // and keeps its chunk index entry.
  void flush_chunk();
  // Writes what the stdio buffer holds, then `parts` (at most 4) in one writev(), repeated only
  // for what the system did not take; counts them and keeps the data section's CRC.
  void emit_at_once(std::initializer_list<std::pair<const void*, std::size_t>> parts);

  void finish();
  void finish_quietly();

  Options options_;
  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t pos_ = 0;
  std::uint32_t data_crc_ = 0;
  std::vector<std::uint8_t> rec_, chunk_, offsets_, indexes_;
  std::vector<std::vector<std::uint8_t>> schemas_, channels_, chunk_indexes_;
  std::vector<std::uint64_t> channel_counts_;
  std::vector<std::vector<std::pair<std::uint64_t, std::uint64_t>>> index_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0, chunk_messages_ = 0;
  std::uint64_t start_ = 0, end_ = 0, messages_ = 0;
};

/// \brief The `offered_qos_profiles` channel metadata of a QoS, in ROS 2 Humble's form
/// (rosbag2_transport/src/rosbag2_transport/qos.cpp, humble: a YAML sequence of profiles, the
/// policies as rmw's integer enum values: history keep_last = 1, reliability reliable = 1 /
/// best_effort = 2, durability transient_local = 1 / volatile = 2, liveliness automatic = 1;
/// deadline, lifespan and lease duration 0 s = rmw's "default").
/// \param q the QoS \return the YAML text
KELP_SIM_API std::string offered_qos_yaml(const Qos& q);

/// \brief A ROS 2 bag (MCAP, profile `ros2`) of kelp's topics (ros2::topics()): one schema a
/// message type (`ros2msg`), one channel a topic (`cdr`, with its offered QoS), and write()
/// for the messages of a sample, logged at their header time (simulation time).
class KELP_SIM_API BagWriter {
 public:
  /// \brief Creates the bag at `path` with every topic's schema and channel.
  /// \param path the file to create \param options the MCAP options (profile `ros2`)
  /// \throws kelp::error when the file cannot be written.
  explicit BagWriter(const std::filesystem::path& path, const McapOptions& options = {});

  /// \brief Writes one message on topic `id`, logged at its stamp.
  /// \tparam M the topic's message struct (messages.hpp)
  /// \param id the topic \param m the message (serialised as CDR) \param stamp its log time
  /// \throws kelp::error on a write failure.
  template <class M>
  void write(TopicId id, const M& m, const builtin_interfaces::Time& stamp) {
    serialize(m, buf_);
    const auto c = static_cast<std::size_t>(id);
    mcap_.write(channel_[c], sequence_[c]++, to_nanoseconds(stamp), buf_.data(), buf_.size());
  }

  /// \brief Writes every message of a sample; `markers` false leaves /tether/markers out (a
  /// bag may carry the markers at a lower rate than the states).
  /// \param m the sample's messages (fill_messages()) \param markers whether to write the markers
  /// \throws kelp::error on a write failure.
  void write(const Messages& m, bool markers = true);

  /// \brief Finishes the file (summary, index, footer).
  /// \throws kelp::error on a write failure.
  void close() { mcap_.close(); }

  /// \brief The underlying MCAP writer (counts, bytes). \return the writer
  const McapWriter& mcap() const { return mcap_; }

 private:
  friend struct kelp::sim::CheckpointAccess;  // a run's checkpoint: the sequence numbers
  friend class kelp::sim::BagRecorder;        // its checkpoint's recorder, made here
  BagWriter() = default;                      // a run's checkpoint: a bag to continue
  McapWriter mcap_;
  std::array<std::uint16_t, static_cast<std::size_t>(TopicId::count)> channel_{};
  std::array<std::uint32_t, static_cast<std::size_t>(TopicId::count)> sequence_{};
  std::vector<std::uint8_t> buf_;
};

}  // namespace ros2
}  // namespace kelp
