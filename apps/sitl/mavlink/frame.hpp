// MAVLink framing: v2 encoding (with payload truncation) and a byte-stream parser for v1 and v2
// frames, as specified by MAVLink's C library (pymavlink/generator/C/include_v2.0/
// mavlink_helpers.h: mavlink_finalize_message_buffer, _mav_trim_payload, mavlink_frame_char_buffer;
// protocol.h for the flags).
//
// v2 frame: 0xFD, LEN, INCOMPAT_FLAGS, COMPAT_FLAGS, SEQ, SYSID, COMPID, MSGID (3 bytes, LE),
// payload (LEN bytes), CRC (LE), and a 13-byte signature when INCOMPAT_FLAGS has bit 0 (signed).
// v1 frame: 0xFE, LEN, SEQ, SYSID, COMPID, MSGID (1 byte), payload, CRC.
// The CRC (crc.hpp) covers everything after the start byte up to the end of the payload, then
// the message's CRC_EXTRA byte.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "crc.hpp"
#include "messages.hpp"
#include "wire.hpp"

namespace kelp_sitl::mavlink {

inline constexpr std::uint8_t kStxV1 = 0xFE;
inline constexpr std::uint8_t kStxV2 = 0xFD;
inline constexpr std::uint8_t kIflagSigned = 0x01;  // MAVLINK_IFLAG_SIGNED
inline constexpr std::size_t kHeaderV1 = 6;
inline constexpr std::size_t kHeaderV2 = 10;
inline constexpr std::size_t kSignatureLength = 13;
inline constexpr std::size_t kMaxFrameLength = kHeaderV2 + 255 + 2 + kSignatureLength;  // 280

// Static facts about one message type, looked up by id when parsing.
struct MessageInfo {
  std::uint32_t msg_id;
  const char* name;
  std::uint8_t crc_extra;
  std::uint8_t min_length;
  std::uint8_t length;
};

namespace detail {
template <class... Ms>
constexpr std::array<MessageInfo, sizeof...(Ms)> make_table(MessageList<Ms...>) {
  return {MessageInfo{Ms::msg_id, Ms::name, Ms::crc_extra,
                      static_cast<std::uint8_t>(Ms::min_length),
                      static_cast<std::uint8_t>(Ms::length)}...};
}
}  // namespace detail

inline constexpr auto kMessageTable = detail::make_table(AllMessages{});

// The message with this id, or nullptr if this codec does not know it.
inline const MessageInfo* find_message(std::uint32_t msg_id) {
  for (const MessageInfo& m : kMessageTable)
    if (m.msg_id == msg_id) return &m;
  return nullptr;
}

// One received frame. payload holds LEN bytes followed by zeros, so a truncated payload decodes
// as if its trailing zeros had been sent.
struct Frame {
  std::uint8_t version = 2;  // 1 or 2
  std::uint8_t len = 0;      // payload length on the wire
  std::uint8_t incompat_flags = 0;
  std::uint8_t compat_flags = 0;
  std::uint8_t seq = 0;
  std::uint8_t sysid = 0;
  std::uint8_t compid = 0;
  std::uint32_t msg_id = 0;
  bool is_signed = false;  // a signature was present (and skipped: it is not verified)
  std::array<std::uint8_t, 255> payload{};
};

// The message in f, if f carries an M.
template <class M>
std::optional<M> decode(const Frame& f) {
  if (f.msg_id != M::msg_id) return std::nullopt;
  return decode_payload<M>(f.payload.data());
}

// Length of a v2 payload after MAVLink 2's truncation of trailing zero bytes; at least 1 byte
// is kept (_mav_trim_payload).
inline std::size_t trimmed_length(const std::uint8_t* payload, std::size_t n) {
  while (n > 1 && payload[n - 1] == 0) --n;
  return n;
}

// Writes a v2 frame around a raw payload (already truncated or not: it is sent as given) and
// returns its size. out must hold kHeaderV2 + len + 2 bytes. For tests and for messages this
// codec does not define; ordinary code uses encode_v2.
inline std::size_t frame_v2(std::uint32_t msg_id, std::uint8_t crc_extra,
                            const std::uint8_t* payload, std::size_t len, std::uint8_t seq,
                            std::uint8_t sysid, std::uint8_t compid, std::uint8_t* out) {
  out[0] = kStxV2;
  out[1] = static_cast<std::uint8_t>(len);
  out[2] = 0;  // incompat flags: not signed
  out[3] = 0;  // compat flags
  out[4] = seq;
  out[5] = sysid;
  out[6] = compid;
  out[7] = static_cast<std::uint8_t>(msg_id);
  out[8] = static_cast<std::uint8_t>(msg_id >> 8);
  out[9] = static_cast<std::uint8_t>(msg_id >> 16);
  for (std::size_t i = 0; i < len; ++i) out[kHeaderV2 + i] = payload[i];
  std::uint16_t crc = crc_accumulate(out + 1, kHeaderV2 - 1 + len, kCrcInit);
  crc = crc_accumulate(crc_extra, crc);
  out[kHeaderV2 + len] = static_cast<std::uint8_t>(crc & 0xFF);
  out[kHeaderV2 + len + 1] = static_cast<std::uint8_t>(crc >> 8);
  return kHeaderV2 + len + 2;
}

// A complete v2 frame of msg, payload truncated.
template <class M>
std::vector<std::uint8_t> encode_v2(const M& msg, std::uint8_t seq, std::uint8_t sysid,
                                    std::uint8_t compid) {
  std::array<std::uint8_t, 255> payload{};
  const std::size_t n = trimmed_length(payload.data(), encode_payload(msg, payload.data()));
  std::array<std::uint8_t, kMaxFrameLength> out{};
  const std::size_t size =
      frame_v2(M::msg_id, M::crc_extra, payload.data(), n, seq, sysid, compid, out.data());
  return std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(size));
}

// A complete v1 frame of msg (base fields only, never truncated; msg_id must be < 256). MAVLink
// 2 senders do not need it; the parser accepts v1 frames and tests use this to make them.
template <class M>
std::vector<std::uint8_t> encode_v1(const M& msg, std::uint8_t seq, std::uint8_t sysid,
                                    std::uint8_t compid) {
  static_assert(M::msg_id < 256, "MAVLink 1 has 8-bit message ids");
  std::array<std::uint8_t, 255> payload{};
  encode_payload(msg, payload.data());
  const std::size_t n = M::min_length;
  std::vector<std::uint8_t> out(kHeaderV1 + n + 2);
  out[0] = kStxV1;
  out[1] = static_cast<std::uint8_t>(n);
  out[2] = seq;
  out[3] = sysid;
  out[4] = compid;
  out[5] = static_cast<std::uint8_t>(M::msg_id);
  std::copy(payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(n), out.begin() + 6);
  std::uint16_t crc = crc_accumulate(out.data() + 1, kHeaderV1 - 1 + n, kCrcInit);
  crc = crc_accumulate(M::crc_extra, crc);
  out[kHeaderV1 + n] = static_cast<std::uint8_t>(crc & 0xFF);
  out[kHeaderV1 + n + 1] = static_cast<std::uint8_t>(crc >> 8);
  return out;
}

// One sender (sysid, compid) with its own sequence number, which wraps 255 -> 0.
class Sender {
 public:
  Sender(std::uint8_t sysid, std::uint8_t compid) : sysid_(sysid), compid_(compid) {}

  template <class M>
  std::vector<std::uint8_t> pack(const M& msg) {
    return encode_v2(msg, seq_++, sysid_, compid_);
  }

  std::uint8_t sysid() const { return sysid_; }
  std::uint8_t compid() const { return compid_; }
  std::uint8_t next_seq() const { return seq_; }
  void set_next_seq(std::uint8_t s) { seq_ = s; }

 private:
  std::uint8_t sysid_;
  std::uint8_t compid_;
  std::uint8_t seq_ = 0;
};

// What the parser accepted and why it dropped the rest.
struct ParserStats {
  std::uint64_t frames = 0;         // accepted frames
  std::uint64_t bad_crc = 0;        // CRC mismatch (start byte dropped, rescanned after it)
  std::uint64_t unknown_msgid = 0;  // frames of unknown messages, skipped whole
  std::uint64_t bad_length = 0;     // LEN above the message's full length (start byte dropped)
  std::uint64_t bad_flags = 0;      // unknown INCOMPAT_FLAGS bits (start byte dropped)
  std::uint64_t junk_bytes = 0;     // bytes outside frames (and false start bytes) skipped
  std::uint64_t dropped() const { return bad_crc + unknown_msgid + bad_length + bad_flags; }
};

// Byte-stream parser for a TCP link. Feed it whatever arrives; it calls on_frame(const Frame&)
// for every accepted frame. It resynchronises on the next 0xFD/0xFE after junk (ArduSub prints a
// text banner before its first frame) and after a rejected frame. Signatures are skipped, not
// verified. Memory is one fixed buffer of kMaxFrameLength + 1 bytes.
//
// Policies: a frame with a CRC error, a LEN too long for its message or unknown flags may be a
// false start byte inside other data, so only its start byte is dropped and the bytes after it
// are scanned again. A frame of a message this codec does not know cannot have its CRC checked:
// it is skipped whole (counted in unknown_msgid) when the byte after its claimed end is a start
// byte; otherwise its start byte is taken for junk and the bytes after it are scanned again.
// So an unknown frame is skipped once the first byte after it has arrived.
class Parser {
 public:
  template <class F>
  void feed(const std::uint8_t* data, std::size_t n, F&& on_frame) {
    for (std::size_t i = 0; i < n; ++i) {
      buf_[n_++] = data[i];
      process(on_frame);
    }
  }

  template <class F>
  void feed(const std::vector<std::uint8_t>& data, F&& on_frame) {
    feed(data.data(), data.size(), on_frame);
  }

  // Convenience: every frame in data.
  std::vector<Frame> feed(const std::uint8_t* data, std::size_t n) {
    std::vector<Frame> out;
    feed(data, n, [&out](const Frame& f) { out.push_back(f); });
    return out;
  }
  std::vector<Frame> feed(const std::vector<std::uint8_t>& data) {
    return feed(data.data(), data.size());
  }

  const ParserStats& stats() const { return stats_; }
  // Bytes held while waiting for the rest of a frame.
  std::size_t buffered() const { return n_; }

 private:
  static bool is_stx(std::uint8_t b) { return b == kStxV1 || b == kStxV2; }

  // Drops the first `count` buffered bytes.
  void consume(std::size_t count) {
    std::copy(buf_.begin() + static_cast<std::ptrdiff_t>(count),
              buf_.begin() + static_cast<std::ptrdiff_t>(n_), buf_.begin());
    n_ -= count;
  }

  // Drops the start byte of a rejected frame; the rest is scanned again.
  void reject_start() { consume(1); }

  // Examines the buffer as far as it goes; returns when more bytes are needed.
  template <class F>
  void process(F& on_frame) {
    while (n_ > 0) {
      if (!is_stx(buf_[0])) {
        std::size_t skip = 1;
        while (skip < n_ && !is_stx(buf_[skip])) ++skip;
        stats_.junk_bytes += skip;
        consume(skip);
        continue;
      }
      const bool v2 = buf_[0] == kStxV2;
      const std::size_t header = v2 ? kHeaderV2 : kHeaderV1;
      if (n_ < header) return;
      const std::size_t len = buf_[1];
      const std::uint8_t iflags = v2 ? buf_[2] : 0;
      if ((iflags & ~kIflagSigned) != 0) {
        ++stats_.bad_flags;
        reject_start();
        continue;
      }
      const std::uint32_t msg_id =
          v2 ? static_cast<std::uint32_t>(buf_[7] | (buf_[8] << 8) | (buf_[9] << 16)) : buf_[5];
      const MessageInfo* info = find_message(msg_id);
      if (info != nullptr && len > info->length) {
        ++stats_.bad_length;
        reject_start();
        continue;
      }
      const bool is_signed = (iflags & kIflagSigned) != 0;
      const std::size_t total = header + len + 2 + (is_signed ? kSignatureLength : 0);
      if (n_ < total) return;
      if (info == nullptr) {
        // No CRC check possible. Believe LEN only if another start byte follows the claimed
        // end, as in a stream of back-to-back frames; otherwise this was a false start.
        if (n_ < total + 1) return;
        if (is_stx(buf_[total])) {
          ++stats_.unknown_msgid;
          consume(total);
        } else {
          ++stats_.junk_bytes;
          reject_start();
        }
        continue;
      }
      std::uint16_t crc = crc_accumulate(buf_.data() + 1, header - 1 + len, kCrcInit);
      crc = crc_accumulate(info->crc_extra, crc);
      const std::uint16_t wire_crc =
          static_cast<std::uint16_t>(buf_[header + len] | (buf_[header + len + 1] << 8));
      if (crc != wire_crc) {
        ++stats_.bad_crc;
        reject_start();
        continue;
      }
      Frame f;
      f.version = v2 ? 2 : 1;
      f.len = static_cast<std::uint8_t>(len);
      f.incompat_flags = iflags;
      f.compat_flags = v2 ? buf_[3] : 0;
      f.seq = v2 ? buf_[4] : buf_[2];
      f.sysid = v2 ? buf_[5] : buf_[3];
      f.compid = v2 ? buf_[6] : buf_[4];
      f.msg_id = msg_id;
      f.is_signed = is_signed;
      std::copy(buf_.begin() + static_cast<std::ptrdiff_t>(header),
                buf_.begin() + static_cast<std::ptrdiff_t>(header + len), f.payload.begin());
      consume(total);
      ++stats_.frames;
      on_frame(static_cast<const Frame&>(f));
    }
  }

  // One frame and the byte after it (looked at for unknown messages).
  std::array<std::uint8_t, kMaxFrameLength + 1> buf_{};
  std::size_t n_ = 0;
  ParserStats stats_;
};

}  // namespace kelp_sitl::mavlink
