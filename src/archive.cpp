// kelp's binary archive (archive.hpp): the writer, the reader and its checks.
#include "archive.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "kelp/sim/ros2/mcap.hpp"  // kelp::ros2::crc32 (zlib's CRC-32)
#include "kelp/sim/state_error.hpp"

namespace kelp {
namespace sim {
namespace archive {

namespace {

void put_le(std::string& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}

std::uint64_t get_le(const char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= std::uint64_t(static_cast<unsigned char>(p[i])) << (8 * i);
  return v;
}

std::uint32_t crc_of(std::string_view bytes) { return ros2::crc32(bytes.data(), bytes.size()); }

}  // namespace

std::string kind_name(std::uint16_t kind) {
  switch (kind) {
    case std::uint16_t(ArchiveKind::pair_state):
      return "pair state";
    case std::uint16_t(ArchiveKind::fleet_state):
      return "fleet state";
    case std::uint16_t(ArchiveKind::run_checkpoint):
      return "run checkpoint";
    default:
      return "kind " + std::to_string(kind);
  }
}

std::string tag_name(const Tag& t) {
  std::string s = "'";
  for (char c : t) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F) {
      s.push_back(c);
    } else {
      static const char hex[] = "0123456789abcdef";
      s += "\\x";
      s.push_back(hex[u >> 4]);
      s.push_back(hex[u & 0xFu]);
    }
  }
  return s + "'";
}

// ---- Writer -------------------------------------------------------------------------------------

Writer::Writer(ArchiveKind kind, std::string_view writer_version)
    : kind_(std::uint16_t(kind)),
      writer_(writer_version.substr(0, std::min(writer_version.size(), max_writer_bytes))) {}

void Writer::begin(Tag t) {
  if (open_ != 0) throw std::logic_error("archive::Writer::begin: a section is open");
  payload_.append(t.data(), t.size());
  open_ = payload_.size();
  put_le(payload_, 0, 8);  // its length, set by end()
}

void Writer::end() {
  if (open_ == 0) throw std::logic_error("archive::Writer::end: no section is open");
  const std::uint64_t n = payload_.size() - (open_ + 8);
  std::string len;
  put_le(len, n, 8);
  payload_.replace(open_, 8, len);
  open_ = 0;
}

void Writer::u8(std::uint8_t v) { put_le(payload_, v, 1); }
void Writer::u16(std::uint16_t v) { put_le(payload_, v, 2); }
void Writer::u32(std::uint32_t v) { put_le(payload_, v, 4); }
void Writer::u64(std::uint64_t v) { put_le(payload_, v, 8); }
void Writer::i32(std::int32_t v) { put_le(payload_, std::uint32_t(v), 4); }
void Writer::f64(double v) {
  std::uint64_t bits = 0;
  static_assert(sizeof bits == sizeof v, "IEEE-754 double");
  std::memcpy(&bits, &v, sizeof v);
  put_le(payload_, bits, 8);
}
void Writer::f64s(const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) f64(v[i]);
}

void Writer::text(std::string_view s) {
  if (s.size() > 0xFFFFFFFFu) throw std::length_error("archive::Writer::text: longer than 4 GiB");
  u32(std::uint32_t(s.size()));
  payload_.append(s.data(), s.size());
}

std::string Writer::bytes() const {
  if (open_ != 0) throw std::logic_error("archive::Writer::bytes: a section is open");
  std::string out(reinterpret_cast<const char*>(magic.data()), magic.size());
  put_le(out, archive_format, 2);
  put_le(out, kind_, 2);
  put_le(out, writer_.size(), 1);
  out += writer_;
  put_le(out, payload_.size(), 8);
  out += payload_;
  put_le(out, crc_of(out), 4);
  return out;
}

// ---- Section ------------------------------------------------------------------------------------

const char* Section::take(std::size_t n) {
  if (n > left())
    fail("truncated: " + std::to_string(n) + " more bytes needed, " + std::to_string(left()) +
         " left");
  const char* p = body_.data() + at_;
  at_ += n;
  return p;
}

std::uint8_t Section::u8() { return std::uint8_t(get_le(take(1), 1)); }
std::uint16_t Section::u16() { return std::uint16_t(get_le(take(2), 2)); }
std::uint32_t Section::u32() { return std::uint32_t(get_le(take(4), 4)); }
std::uint64_t Section::u64() { return get_le(take(8), 8); }
std::int32_t Section::i32() {
  const std::uint32_t u = u32();
  std::int32_t v = 0;
  std::memcpy(&v, &u, sizeof v);
  return v;
}
double Section::f64() {
  const std::uint64_t bits = u64();
  double v = 0;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}
void Section::f64s(double* v, std::size_t n) {
  if (n > left() / 8) take(n * 8);  // fails with the sizes, before any partial read
  for (std::size_t i = 0; i < n; ++i) v[i] = f64();
}

std::string_view Section::text(std::size_t max, const char* what) {
  const std::uint32_t n = u32();
  if (n > max)
    fail(std::string(what) + ": " + std::to_string(n) + " bytes, more than the " +
         std::to_string(max) + " allowed");
  return std::string_view(take(n), n);
}

void Section::expect_count(std::uint32_t expected, const char* what) {
  const std::uint32_t n = u32();
  if (n != expected)
    fail(std::string(what) + ": " + std::to_string(n) + " where " + std::to_string(expected) +
         " are expected");
}

std::uint32_t Section::count(std::uint32_t max, std::size_t element_bytes, const char* what) {
  const std::uint32_t n = u32();
  if (n > max)
    fail(std::string(what) + ": " + std::to_string(n) + ", more than the " + std::to_string(max) +
         " allowed");
  if (element_bytes > 0 && n > left() / element_bytes)
    fail(std::string(what) + ": " + std::to_string(n) + " of " + std::to_string(element_bytes) +
         " bytes each, but only " + std::to_string(left()) + " bytes are left");
  return n;
}

void Section::end() const {
  if (left() != 0) fail(std::to_string(left()) + " bytes past the end of its values");
}

void Section::fail(const std::string& message) const { throw state_error(context_ + message); }

// ---- Reader -------------------------------------------------------------------------------------

Reader::Reader(std::string_view bytes, ArchiveKind kind, std::string input)
    : input_(std::move(input)) {
  const std::size_t size = bytes.size();
  // The magic, as far as the input goes: a short input of another kind is "not an archive".
  const std::size_t m = std::min(size, magic.size());
  if (std::memcmp(bytes.data(), magic.data(), m) != 0)
    fail("not a kelp state file (its first bytes are not the magic \\x89KELP\\r\\n\\x1a)");
  if (size < fixed_header_bytes)
    fail("truncated: " + std::to_string(size) + " bytes, shorter than a header (" +
         std::to_string(fixed_header_bytes) + " bytes at least)");
  const auto format = std::uint16_t(get_le(bytes.data() + 8, 2));
  if (format != archive_format)
    fail("archive format " + std::to_string(format) + ", this kelp reads format " +
         std::to_string(archive_format) + " only");
  const auto k = std::uint16_t(get_le(bytes.data() + 10, 2));
  if (k != std::uint16_t(kind))
    fail("holds a " + kind_name(k) + ", a " + kind_name(std::uint16_t(kind)) + " is expected");
  const std::size_t wn = static_cast<unsigned char>(bytes[12]);
  if (wn > max_writer_bytes)
    fail("the writer's version is " + std::to_string(wn) + " bytes long, at most " +
         std::to_string(max_writer_bytes) + " are allowed");
  const std::size_t payload_at = fixed_header_bytes + wn + 8;
  if (size < payload_at + 4)
    fail("truncated: " + std::to_string(size) + " bytes, shorter than its header and checksum (" +
         std::to_string(payload_at + 4) + " bytes)");
  const std::uint64_t p = get_le(bytes.data() + fixed_header_bytes + wn, 8);
  const std::size_t available = size - payload_at - 4;
  if (p != available) {
    if (p > available)
      fail("truncated: the header says " + std::to_string(p) + " bytes of payload, " +
           std::to_string(available) + " are there");
    fail(std::to_string(available - p) + " bytes past the end given by its header");
  }
  const std::uint32_t stored = std::uint32_t(get_le(bytes.data() + size - 4, 4));
  const std::uint32_t actual = crc_of(bytes.substr(0, size - 4));
  if (stored != actual)
    fail("checksum mismatch (CRC-32 " + std::to_string(actual) + ", the file says " +
         std::to_string(stored) + "): the file is corrupt");
  writer_.assign(bytes.data() + fixed_header_bytes, wn);
  // The sections: each header within the payload, each body too.
  std::string_view payload = bytes.substr(payload_at, std::size_t(p));
  while (!payload.empty()) {
    if (payload.size() < 12)
      fail("a section header runs past the payload's end (" + std::to_string(payload.size()) +
           " bytes left)");
    Tag t{payload[0], payload[1], payload[2], payload[3]};
    const std::uint64_t n = get_le(payload.data() + 4, 8);
    if (n > payload.size() - 12)
      fail("section " + tag_name(t) + " says " + std::to_string(n) + " bytes, " +
           std::to_string(payload.size() - 12) + " are left in the payload");
    sections_.push_back({t, payload.substr(12, std::size_t(n))});
    payload.remove_prefix(12 + std::size_t(n));
  }
}

Section Reader::next(Tag t) {
  if (next_ == sections_.size()) fail("missing section " + tag_name(t));
  const Entry& e = sections_[next_];
  if (e.tag != t)
    fail("section " + tag_name(e.tag) + " where " + tag_name(t) + " is expected (unknown or " +
         "out of order)");
  ++next_;
  std::size_t i = 0;
  for (; i < seen_tags_.size(); ++i)
    if (seen_tags_[i] == t) break;
  if (i == seen_tags_.size()) {
    seen_tags_.push_back(t);
    seen_.push_back(0);
  }
  const std::size_t index = seen_[i]++;
  return Section(e.body, input_ + ": section " + tag_name(t) + " #" + std::to_string(index) + ": ");
}

void Reader::end() const {
  if (next_ != sections_.size())
    fail("unknown section " + tag_name(sections_[next_].tag) + " after the last one expected");
}

void Reader::fail(const std::string& message) const { throw state_error(input_ + ": " + message); }

}  // namespace archive
}  // namespace sim
}  // namespace kelp
