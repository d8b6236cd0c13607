// libFuzzer target: the MAVLink v1/v2 byte-stream parser and the payload codec
// (apps/sitl/mavlink/frame.hpp, messages.hpp, wire.hpp, enums.hpp).
//
// Input: byte 0 seeds the chunking (0: one feed() call; otherwise chunks of 1..64 bytes from a
// small generator), the rest is the TCP stream.
// Oracle:
// - The stream fed in chunks gives the same frames and the same statistics as fed at once (the
//   parser is a byte-stream parser: chunk boundaries must not matter); stats().frames counts the
//   callbacks; buffered() never exceeds one frame and the byte after it.
// - Every accepted frame is of a message this codec knows, version 1 or 2, LEN within the
//   message's length, payload zero beyond LEN, v1 frames carry an 8-bit id.
// - The frame decodes into exactly the message type of its id (decode<M> for every M); the
//   decoded message re-encodes to the same payload bytes; encode_v2 of it parses back to the same
//   message; the names of its enum fields print.
#include <cstring>
#include <vector>

#include "fuzz_common.hpp"
#include "mavlink/mavlink.hpp"

namespace mav = kelp_sitl::mavlink;

namespace {

struct Seen {
  std::vector<mav::Frame> frames;
  mav::ParserStats stats;
};

bool same_frame(const mav::Frame& a, const mav::Frame& b) {
  return a.version == b.version && a.len == b.len && a.incompat_flags == b.incompat_flags &&
         a.compat_flags == b.compat_flags && a.seq == b.seq && a.sysid == b.sysid &&
         a.compid == b.compid && a.msg_id == b.msg_id && a.is_signed == b.is_signed &&
         a.payload == b.payload;
}

bool same_stats(const mav::ParserStats& a, const mav::ParserStats& b) {
  return a.frames == b.frames && a.bad_crc == b.bad_crc && a.unknown_msgid == b.unknown_msgid &&
         a.bad_length == b.bad_length && a.bad_flags == b.bad_flags && a.junk_bytes == b.junk_bytes;
}

Seen parse(const std::uint8_t* d, std::size_t n, std::uint8_t chunk_seed) {
  mav::Parser parser;
  Seen seen;
  const auto on_frame = [&seen](const mav::Frame& f) { seen.frames.push_back(f); };
  if (chunk_seed == 0) {
    parser.feed(d, n, on_frame);
  } else {
    std::uint32_t x = 0x9E3779B9u ^ chunk_seed;
    std::size_t i = 0;
    while (i < n) {
      x ^= x << 13;
      x ^= x >> 17;
      x ^= x << 5;
      const std::size_t k = std::min<std::size_t>(n - i, 1 + x % 64);
      parser.feed(d + i, k, on_frame);
      KELP_FUZZ_REQUIRE(parser.buffered() <= mav::kMaxFrameLength + 1, "parser buffer bound");
      i += k;
    }
  }
  seen.stats = parser.stats();
  KELP_FUZZ_REQUIRE(seen.stats.frames == seen.frames.size(), "stats().frames vs callbacks");
  return seen;
}

template <class M>
void names_of(const M& m) {
  // Enum fields that a ground station prints.
  if constexpr (std::is_same_v<M, mav::CommandAck>) {
    KELP_FUZZ_REQUIRE(!mav::result_name(m.result).empty(), "result_name");
    KELP_FUZZ_REQUIRE(!mav::command_name(m.command).empty(), "command_name");
  } else if constexpr (std::is_same_v<M, mav::CommandLong>) {
    KELP_FUZZ_REQUIRE(!mav::command_name(m.command).empty(), "command_name");
  } else if constexpr (std::is_same_v<M, mav::Statustext>) {
    KELP_FUZZ_REQUIRE(!mav::severity_name(m.severity).empty(), "severity_name");
    KELP_FUZZ_REQUIRE(mav::to_string(m.text).size() <= m.text.size(), "statustext length");
  } else if constexpr (std::is_same_v<M, mav::ParamSet> || std::is_same_v<M, mav::ParamValue>) {
    KELP_FUZZ_REQUIRE(mav::to_string(m.param_id).size() <= m.param_id.size(), "param_id length");
  }
}

void check_frame(const mav::Frame& f) {
  const mav::MessageInfo* info = mav::find_message(f.msg_id);
  KELP_FUZZ_REQUIRE(info != nullptr, "accepted a frame of an unknown message");
  KELP_FUZZ_REQUIRE(f.version == 1 || f.version == 2, "frame version");
  KELP_FUZZ_REQUIRE(f.len <= info->length, "LEN above the message's length");
  KELP_FUZZ_REQUIRE(f.version == 2 || f.msg_id < 256, "v1 frame with a 24-bit id");
  KELP_FUZZ_REQUIRE(f.version == 2 || (!f.is_signed && f.incompat_flags == 0), "v1 flags");
  for (std::size_t i = f.len; i < f.payload.size(); ++i)
    KELP_FUZZ_REQUIRE(f.payload[i] == 0, "payload not zero-filled beyond LEN");
  int decoded = 0;
  mav::for_each_message_type([&](auto tag) {
    using M = decltype(tag);
    const std::optional<M> m = mav::decode<M>(f);
    KELP_FUZZ_REQUIRE(m.has_value() == (f.msg_id == M::msg_id), "decode<M> iff the id matches");
    if (!m) return;
    ++decoded;
    std::array<std::uint8_t, 255> payload{};
    const std::size_t n = mav::encode_payload(*m, payload.data());
    KELP_FUZZ_REQUIRE(n == M::length, "encode_payload length");
    KELP_FUZZ_REQUIRE(std::memcmp(payload.data(), f.payload.data(), n) == 0,
                      "decoded message does not re-encode to its payload");
    names_of(*m);
    // encode_v2 → parse → the same payload.
    const std::vector<std::uint8_t> wire = mav::encode_v2(*m, f.seq, f.sysid, f.compid);
    mav::Parser p;
    const std::vector<mav::Frame> back = p.feed(wire);
    KELP_FUZZ_REQUIRE(back.size() == 1 && p.buffered() == 0, "encode_v2 frame not parsed back");
    KELP_FUZZ_REQUIRE(back[0].msg_id == M::msg_id && back[0].payload == f.payload &&
                          back[0].seq == f.seq && back[0].sysid == f.sysid &&
                          back[0].compid == f.compid,
                      "encode_v2 frame parsed back differently");
  });
  KELP_FUZZ_REQUIRE(decoded == 1, "frame decoded into other than exactly one message type");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t seed = data[0];
  const std::uint8_t* stream = data + 1;
  const std::size_t n = size - 1;
  const Seen whole = parse(stream, n, 0);
  const Seen chunked = parse(stream, n, seed == 0 ? 1 : seed);
  KELP_FUZZ_REQUIRE(whole.frames.size() == chunked.frames.size(), "chunking changed the frames");
  for (std::size_t i = 0; i < whole.frames.size(); ++i)
    KELP_FUZZ_REQUIRE(same_frame(whole.frames[i], chunked.frames[i]), "chunking changed a frame");
  KELP_FUZZ_REQUIRE(same_stats(whole.stats, chunked.stats), "chunking changed the statistics");
  for (const mav::Frame& f : whole.frames) check_frame(f);
  return 0;
}
