// kelp's binary archive (private to kelp::sim): the container of state files
// (kelp/sim/state_io.hpp, docs/state-files.md) and of a closed-loop run's checkpoint
// (kelp/sim/checkpoint.hpp, docs/checkpoints.md).
//
// An archive is a header, a payload of tagged sections and a CRC-32, little-endian throughout
// (written byte by byte, never as structs):
//
//   magic       8 bytes  89 'K' 'E' 'L' 'P' 0D 0A 1A
//   format      u16      archive_format (2)
//   kind        u16      what the payload holds (ArchiveKind)
//   writer      u8 n, n bytes   the kelp version that wrote it (informative, ASCII, n <= 64)
//   payload     u64 p    the payload's length in bytes, then p bytes of sections:
//                          tag  4 ASCII bytes (e.g. "TETH")
//                          len  u64, then len bytes of the section's body
//   crc         u32      CRC-32 (zlib's) of every byte before it, header included
//
// The reader treats its input as untrusted: every length is checked against the bytes that are
// really there before anything is allocated, and every failure is a kelp::sim::state_error whose
// message starts with the name the caller gave the input (a path, or "state").
//
// Adding a section: write it with Writer::begin / end at its place, read it with Reader::next
// at the same place. Sections are read in the order they were written, and a section the reader
// does not ask for (unknown), or one it asks for that is not there (missing), is an error; so
// is a section whose body is not read to its end. A change of the sections of a kind is a new
// archive_format (old files are then refused, naming both versions).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace kelp {
namespace sim {
namespace archive {

/// The magic bytes every archive starts with (PNG's pattern: a non-ASCII byte, the name, CR LF,
/// ^Z, so that a text-mode transfer or a truncated header shows).
inline constexpr std::array<std::uint8_t, 8> magic = {0x89, 'K', 'E', 'L', 'P', 0x0D, 0x0A, 0x1A};
/// The archive format this code writes and reads. Format 2 added a tether's accelerations
/// (TetherState::acceleration) after its kept Newton matrix; format 1 files are refused.
inline constexpr std::uint16_t archive_format = 2;
/// Bytes before the writer's version string: magic, format, kind, the string's length.
inline constexpr std::size_t fixed_header_bytes = 8 + 2 + 2 + 1;
/// Longest writer version string.
inline constexpr std::size_t max_writer_bytes = 64;

/// What an archive holds (the header's kind).
enum class ArchiveKind : std::uint16_t {
  pair_state = 1,      ///< kelp::system::SystemState<double> (the tethered pair)
  fleet_state = 2,     ///< kelp::system::FleetState<double>
  run_checkpoint = 3,  ///< a closed-loop run's checkpoint (checkpoint.cpp)
};
/// "pair state", "fleet state" or "kind <n>".
std::string kind_name(std::uint16_t kind);

/// A section tag: four ASCII characters.
using Tag = std::array<char, 4>;
/// The tag of a four-character literal: tag("TETH").
constexpr Tag tag(const char (&s)[5]) { return {s[0], s[1], s[2], s[3]}; }

/// Writes an archive: begin(tag), the section's values, end(), ..., then bytes().
class Writer {
 public:
  /// An archive of `kind`, written by kelp `writer_version`.
  Writer(ArchiveKind kind, std::string_view writer_version);

  /// Starts a section (the previous one must have ended).
  void begin(Tag t);
  /// Ends the current section (writes its length).
  void end();

  void u8(std::uint8_t v);
  void u16(std::uint16_t v);
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void i32(std::int32_t v);
  /// A double as its IEEE-754 bits (NaN payloads and signed zeros kept).
  void f64(double v);
  /// `n` doubles.
  void f64s(const double* v, std::size_t n);
  /// Bytes: a u32 length, then the bytes.
  void text(std::string_view s);

  /// The whole archive: header, payload, CRC. Every section must have ended.
  std::string bytes() const;

 private:
  std::uint16_t kind_;
  std::string writer_;
  std::string payload_;
  std::size_t open_ = 0;  // offset of the open section's length field, 0: none
};

class Reader;

/// One section's body, read front to back; every read checks the bytes left.
class Section {
 public:
  std::uint8_t u8();
  std::uint16_t u16();
  std::uint32_t u32();
  std::uint64_t u64();
  std::int32_t i32();
  double f64();
  void f64s(double* v, std::size_t n);
  /// Bytes written by Writer::text, at most `max`; `what` names them in the error.
  std::string_view text(std::size_t max, const char* what);
  /// A u32 count that must equal `expected`; `what` names it in the error.
  void expect_count(std::uint32_t expected, const char* what);
  /// A u32 count of elements of `element_bytes` each, at most `max` and no more than the bytes
  /// left hold (so that no allocation is ever sized by an unchecked length).
  std::uint32_t count(std::uint32_t max, std::size_t element_bytes, const char* what);
  /// Bytes not yet read.
  std::size_t left() const { return body_.size() - at_; }
  /// Checks that the whole body was read.
  void end() const;
  /// Throws kelp::sim::state_error: "<input>: section '<tag>' #<i>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

 private:
  friend class Reader;
  Section(std::string_view body, std::string context) : body_(body), context_(std::move(context)) {}
  const char* take(std::size_t n);
  std::string_view body_;
  std::size_t at_ = 0;
  std::string context_;
};

/// Reads an archive: the constructor checks the header, the length and the CRC and lists the
/// sections; next(tag) gives them in order; end() checks that none is left.
class Reader {
 public:
  /// \param bytes the archive (not copied: it must outlive the reader and its sections)
  /// \param kind the kind expected \param input names the input in errors (a path, "state")
  /// \throws kelp::sim::state_error naming what is wrong (not an archive, another format or
  /// kind, truncated or with bytes past its end, a CRC mismatch, a section running past the
  /// payload).
  Reader(std::string_view bytes, ArchiveKind kind, std::string input);

  /// The next section, which must have tag `t`. \throws state_error when it is missing or
  /// another section stands there.
  Section next(Tag t);
  /// Sections not yet read.
  std::size_t sections_left() const { return sections_.size() - next_; }
  /// Checks that every section was read. \throws state_error naming the first unknown one.
  void end() const;
  /// The kelp version that wrote the archive.
  const std::string& writer_version() const { return writer_; }
  /// Throws kelp::sim::state_error: "<input>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

 private:
  struct Entry {
    Tag tag;
    std::string_view body;
  };
  std::string input_;
  std::string writer_;
  std::vector<Entry> sections_;
  std::size_t next_ = 0;
  std::vector<std::size_t> seen_;  // how many of each tag were read, for "#i" in messages
  std::vector<Tag> seen_tags_;
};

/// "'TETH'" (non-printable bytes as \xNN).
std::string tag_name(const Tag& t);

}  // namespace archive
}  // namespace sim
}  // namespace kelp
