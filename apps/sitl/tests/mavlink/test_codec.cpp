// The MAVLink codec of kelp-mission: CRC, message definitions, framing, and the stream parser
// against valid, truncated, corrupted and random input.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "mavlink/mavlink.hpp"
#include "message_utils.hpp"

using namespace kelp_sitl::mavlink;
using Bytes = std::vector<std::uint8_t>;

namespace {

Bytes from_hex(const std::string& hex) {
  Bytes out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// Recomputes the CRC of a v2 frame after its bytes were edited.
void fix_crc_v2(Bytes& f, std::uint8_t crc_extra) {
  const std::size_t len = f[1];
  std::uint16_t crc = crc_accumulate(f.data() + 1, kHeaderV2 - 1 + len, kCrcInit);
  crc = crc_accumulate(crc_extra, crc);
  f[kHeaderV2 + len] = static_cast<std::uint8_t>(crc & 0xFF);
  f[kHeaderV2 + len + 1] = static_cast<std::uint8_t>(crc >> 8);
}

Heartbeat sample_heartbeat() {
  Heartbeat hb;
  hb.custom_mode = 19;
  hb.type = kTypeSubmarine;
  hb.autopilot = kAutopilotArdupilotmega;
  hb.base_mode = 81;
  hb.system_status = 3;
  return hb;
}

}  // namespace

TEST_CASE("CRC-16/MCRF4XX check value", "[mavlink]") {
  CHECK(x25("123456789") == 0x6F91);
  CHECK(x25("") == 0xFFFF);
}

TEST_CASE("CRC_EXTRA of every message recomputed from its field list", "[mavlink]") {
  int count = 0;
  for_each_message_type([&](auto m) {
    using M = decltype(m);
    INFO(M::name);
    CHECK(compute_crc_extra<M>() == M::crc_extra);
    CHECK(field_bytes<M>(false) == M::min_length);
    CHECK(field_bytes<M>(true) == M::length);
    CHECK(base_fields_in_wire_order<M>());
    CHECK(find_message(M::msg_id) != nullptr);
    CHECK(find_message(M::msg_id)->crc_extra == M::crc_extra);
    ++count;
  });
  CHECK(count == 23);
  // Spot values of the XML (also checked by the static_assert in messages.hpp).
  CHECK(Heartbeat::crc_extra == 50);
  CHECK(ParamRequestRead::crc_extra == 214);
  CHECK(ParamRequestRead::length == 20);
  CHECK(ParamValue::crc_extra == 220);
  CHECK(ParamValue::length == 25);
  CHECK(SetPositionTargetGlobalInt::crc_extra == 5);
  CHECK(Statustext::crc_extra == 83);
}

TEST_CASE("Known frames (made by an independent implementation) decode and re-encode",
          "[mavlink]") {
  // node-mavlink 2.3.0's MavLinkProtocolV2(1, 1).serialize(...).
  const Bytes hb_bytes = from_hex("fd090000070101000000130000000c0351030338bf");
  const Bytes ack_bytes = from_hex("fd0300002a01014d0000900104b629");
  const Bytes text_bytes =
      from_hex("fd1c0000c80101fd00000250726541726d3a20416363656c7320696e636f6e73697374656e744a81");
  Parser p;
  const auto frames = p.feed(concat({hb_bytes, ack_bytes, text_bytes}));
  REQUIRE(frames.size() == 3);
  CHECK(p.stats().dropped() == 0);

  const auto hb = decode<Heartbeat>(frames[0]);
  REQUIRE(hb);
  CHECK(test::same_fields(*hb, sample_heartbeat()));
  CHECK(frames[0].seq == 7);
  CHECK(frames[0].sysid == 1);
  CHECK(frames[0].compid == 1);
  CHECK(encode_v2(sample_heartbeat(), 7, 1, 1) == hb_bytes);

  const auto ack = decode<CommandAck>(frames[1]);
  REQUIRE(ack);
  CHECK(ack->command == kCmdComponentArmDisarm);
  CHECK(ack->result == 4);
  CHECK(frames[1].len == 3);  // extensions all zero: truncated to the base fields
  CHECK(encode_v2(*ack, 42, 1, 1) == ack_bytes);

  const auto text = decode<Statustext>(frames[2]);
  REQUIRE(text);
  CHECK(text->severity == 2);
  CHECK(to_string(text->text) == "PreArm: Accels inconsistent");
  CHECK(encode_v2(*text, 200, 1, 1) == text_bytes);
  CHECK_FALSE(decode<Heartbeat>(frames[2]));
}

TEST_CASE("Every message round-trips through a v2 frame with random values", "[mavlink]") {
  std::mt19937_64 rng(1234);
  Parser p;
  for_each_message_type([&](auto m) {
    using M = decltype(m);
    INFO(M::name);
    for (int k = 0; k < 200; ++k) {
      test::RandomOptions opt;
      opt.zero_probability = (k % 4) * 0.3;  // 0, 0.3, 0.6, 0.9: many truncation lengths
      opt.printable_text = (k % 2) == 0;
      const M msg = test::random_message<M>(rng, opt);
      const auto seq = static_cast<std::uint8_t>(k);
      const Bytes bytes = encode_v2(msg, seq, 37, 191);
      std::array<std::uint8_t, 255> full{};
      encode_payload(msg, full.data());
      const std::size_t trimmed = trimmed_length(full.data(), M::length);
      REQUIRE(bytes.size() == kHeaderV2 + trimmed + 2);
      const auto frames = p.feed(bytes);
      REQUIRE(frames.size() == 1);
      const Frame& f = frames[0];
      CHECK(f.version == 2);
      CHECK(f.msg_id == M::msg_id);
      CHECK(f.len == trimmed);
      CHECK(f.seq == seq);
      CHECK(f.sysid == 37);
      CHECK(f.compid == 191);
      CHECK_FALSE(f.is_signed);
      const auto back = decode<M>(f);
      REQUIRE(back);
      std::string diff;
      const bool same = test::same_fields(*back, msg, &diff);
      INFO("first differing field: " << diff);
      CHECK(same);
    }
  });
  CHECK(p.stats().dropped() == 0);
  CHECK(p.stats().junk_bytes == 0);
  CHECK(p.buffered() == 0);
}

TEST_CASE("Truncation: trailing zeros removed, at least one byte kept", "[mavlink]") {
  Parser p;
  for_each_message_type([&](auto m) {
    using M = decltype(m);
    INFO(M::name);
    const M zero{};
    std::array<std::uint8_t, 255> full{};
    encode_payload(zero, full.data());
    if (trimmed_length(full.data(), M::length) == 1 && full[0] == 0) {
      const Bytes b = encode_v2(zero, 0, 1, 1);
      CHECK(b[1] == 1);  // all-zero payload: LEN 1
      CHECK(b.size() == kHeaderV2 + 1 + 2);
      const auto frames = p.feed(b);
      REQUIRE(frames.size() == 1);
      CHECK(test::same_fields(*decode<M>(frames[0]), zero));
    }
  });
  // Extension fields: only the last one set keeps the whole payload; none set truncates into
  // the base fields.
  ManualControl mc;
  mc.aux6 = -7;
  CHECK(encode_v2(mc, 0, 255, 190)[1] == ManualControl::length);
  mc.aux6 = 0;
  mc.z = 500;
  CHECK(encode_v2(mc, 0, 255, 190)[1] == 6);  // x, y = 0; z = 500 at bytes 4..5
  GpsRawInt gps;
  gps.yaw = 36000;
  const auto frames = p.feed(encode_v2(gps, 0, 1, 1));
  REQUIRE(frames.size() == 1);
  CHECK(frames[0].len == GpsRawInt::length);
  CHECK(decode<GpsRawInt>(frames[0])->yaw == 36000);
  CHECK(p.stats().dropped() == 0);
}

TEST_CASE("A payload shorter than the minimum length is accepted and zero-filled", "[mavlink]") {
  // LEN 0 (what node-mavlink sends for an all-zero payload) and a LEN inside the base fields.
  const std::uint8_t none[1] = {0};
  Bytes f0(kHeaderV2 + 2);
  frame_v2(Attitude::msg_id, Attitude::crc_extra, none, 0, 0, 1, 1, f0.data());
  const std::uint8_t two[2] = {0x34, 0x12};
  Bytes f2(kHeaderV2 + 2 + 2);
  frame_v2(Attitude::msg_id, Attitude::crc_extra, two, 2, 1, 1, 1, f2.data());
  Parser p;
  const auto frames = p.feed(concat({f0, f2}));
  REQUIRE(frames.size() == 2);
  CHECK(decode<Attitude>(frames[0])->time_boot_ms == 0);
  CHECK(decode<Attitude>(frames[1])->time_boot_ms == 0x1234);
  CHECK(decode<Attitude>(frames[1])->yawspeed == 0.0f);
}

TEST_CASE("MAVLink 1 frames are accepted", "[mavlink]") {
  std::mt19937_64 rng(99);
  Parser p;
  const auto cmd = test::random_message<CommandLong>(rng);
  const auto ack = test::random_message<CommandAck>(rng);
  const Bytes v1 = encode_v1(cmd, 9, 2, 3);
  CHECK(v1[0] == kStxV1);
  CHECK(v1.size() == kHeaderV1 + CommandLong::length + 2);
  const auto frames = p.feed(concat({v1, encode_v1(ack, 10, 2, 3), encode_v2(cmd, 11, 2, 3)}));
  REQUIRE(frames.size() == 3);
  CHECK(frames[0].version == 1);
  CHECK(frames[0].seq == 9);
  CHECK(frames[0].sysid == 2);
  CHECK(frames[0].compid == 3);
  CHECK(test::same_fields(*decode<CommandLong>(frames[0]), cmd));
  // v1 carries no extension fields: they decode as zero.
  CommandAck base_only = ack;
  base_only.progress = 0;
  base_only.result_param2 = 0;
  base_only.target_system = 0;
  base_only.target_component = 0;
  CHECK(frames[1].len == CommandAck::min_length);
  CHECK(test::same_fields(*decode<CommandAck>(frames[1]), base_only));
  CHECK(frames[2].version == 2);
}

TEST_CASE("Signed frames are accepted; the signature is skipped, not verified", "[mavlink]") {
  Bytes f = encode_v2(sample_heartbeat(), 5, 1, 1);
  f[2] = kIflagSigned;
  fix_crc_v2(f, Heartbeat::crc_extra);  // the flags are covered by the CRC
  for (int i = 0; i < 13; ++i) f.push_back(static_cast<std::uint8_t>(0xFD - i));  // looks like STX
  Parser p;
  const auto frames = p.feed(concat({f, encode_v2(sample_heartbeat(), 6, 1, 1)}));
  REQUIRE(frames.size() == 2);
  CHECK(frames[0].is_signed);
  CHECK(frames[0].seq == 5);
  CHECK(frames[1].seq == 6);
  CHECK(p.stats().dropped() == 0);
  CHECK(p.stats().junk_bytes == 0);
}

TEST_CASE("The parser resynchronises after a text banner and after junk", "[mavlink]") {
  const std::string banner =
      "Init ArduSub V4.7.0-dev (90700977)\n\nFree RAM: 262144\nFW Type: SITL\n";
  Bytes bytes(banner.begin(), banner.end());
  const Bytes hb = encode_v2(sample_heartbeat(), 1, 1, 1);
  bytes.insert(bytes.end(), hb.begin(), hb.end());
  Parser p;
  auto frames = p.feed(bytes);
  REQUIRE(frames.size() == 1);
  CHECK(p.stats().junk_bytes == banner.size());

  // Random junk between valid frames. A false start byte in the junk with an unknown message id
  // can hide a real frame only if the byte after its claimed end is a start byte, and one with a
  // known id only if its CRC matches by chance: rare, but possible, so a few losses are allowed.
  // No frame may be invented or altered.
  std::mt19937_64 rng(7);
  Parser q;
  std::vector<GlobalPositionInt> sent;
  Bytes stream;
  for (int k = 0; k < 1000; ++k) {
    const int junk = static_cast<int>(rng() % 40);
    for (int j = 0; j < junk; ++j) stream.push_back(static_cast<std::uint8_t>(rng()));
    sent.push_back(test::random_message<GlobalPositionInt>(rng));
    const Bytes good = encode_v2(sent.back(), static_cast<std::uint8_t>(k), 1, 1);
    stream.insert(stream.end(), good.begin(), good.end());
  }
  frames = q.feed(stream);
  CHECK(frames.size() >= sent.size() - 10);
  std::size_t next = 0;  // the frames received are a subsequence of those sent
  for (const Frame& f : frames) {
    const auto m = decode<GlobalPositionInt>(f);
    REQUIRE(m);
    while (next < sent.size() && !test::same_fields(*m, sent[next])) ++next;
    REQUIRE(next < sent.size());
    CHECK(f.seq == static_cast<std::uint8_t>(next));
    ++next;
  }
  CHECK(q.stats().junk_bytes > 0);
}

TEST_CASE("Sequence numbers are per sender and wrap from 255 to 0", "[mavlink]") {
  Sender gcs(255, 190);
  Sender other(1, 1);
  Parser p;
  std::vector<int> seqs;
  for (int i = 0; i < 300; ++i) {
    for (const Frame& f : p.feed(gcs.pack(Heartbeat{})))
      if (f.sysid == 255) seqs.push_back(f.seq);
    if (i % 3 == 0) p.feed(other.pack(Heartbeat{}));
  }
  REQUIRE(seqs.size() == 300);
  for (int i = 0; i < 300; ++i) CHECK(seqs[static_cast<std::size_t>(i)] == i % 256);
  CHECK(other.next_seq() == 100);
  CHECK(gcs.next_seq() == 300 % 256);
}

TEST_CASE("Corrupt frames are rejected, counted, and do not lose the next frame", "[mavlink]") {
  const Bytes good = encode_v2(sample_heartbeat(), 1, 1, 1);
  Parser p;
  std::size_t accepted = 0;
  auto feed = [&](const Bytes& b) { accepted += p.feed(b).size(); };

  SECTION("wrong CRC") {
    Bytes bad = good;
    bad[kHeaderV2] ^= 0x40;
    feed(concat({bad, good}));
    CHECK(accepted == 1);
    CHECK(p.stats().bad_crc == 1);
  }
  SECTION("wrong CRC_EXTRA (a different message definition)") {
    Bytes bad = good;
    fix_crc_v2(bad, static_cast<std::uint8_t>(Heartbeat::crc_extra + 1));
    feed(concat({bad, good}));
    CHECK(accepted == 1);
    CHECK(p.stats().bad_crc == 1);
  }
  SECTION("LEN above the message's full length") {
    Bytes bad = encode_v2(sample_heartbeat(), 1, 1, 1);
    bad[1] = Heartbeat::length + 1;
    bad.insert(bad.begin() + kHeaderV2, 0x55);
    fix_crc_v2(bad, Heartbeat::crc_extra);  // a valid CRC does not save it
    feed(concat({bad, good}));
    CHECK(accepted == 1);
    CHECK(p.stats().bad_length == 1);
  }
  SECTION("wrong LEN (shorter than sent): CRC fails, the frame after is found") {
    Bytes bad = good;
    bad[1] = 4;
    feed(concat({bad, good}));
    CHECK(accepted == 1);
    CHECK(p.stats().bad_crc == 1);
  }
  SECTION("unknown incompatibility flags") {
    Bytes bad = good;
    bad[2] = 0x02;
    fix_crc_v2(bad, Heartbeat::crc_extra);
    feed(concat({bad, good}));
    CHECK(accepted == 1);
    CHECK(p.stats().bad_flags == 1);
  }
  SECTION("unknown message id: skipped whole, no loss of sync") {
    const std::uint8_t payload[4] = {1, 2, 3, 4};
    Bytes unknown(kHeaderV2 + 4 + 2);
    frame_v2(12345, 0, payload, 4, 0, 1, 1, unknown.data());
    feed(concat({unknown, good, unknown, unknown, good}));
    CHECK(accepted == 2);
    CHECK(p.stats().unknown_msgid == 3);
    CHECK(p.stats().junk_bytes == 0);
  }
  SECTION("truncated frame followed by a good one") {
    const Bytes cut(good.begin(), good.begin() + 8);
    feed(concat({cut, good, good}));
    CHECK(accepted == 2);
    CHECK(p.stats().junk_bytes == cut.size());  // read as an unknown id: a false start
  }
  SECTION("truncated frame at the end of the stream waits, bounded") {
    const Bytes cut(good.begin(), good.end() - 1);
    feed(cut);
    CHECK(accepted == 0);
    CHECK(p.buffered() == cut.size());
    feed(Bytes{good.back()});
    CHECK(accepted == 1);
    CHECK(p.buffered() == 0);
  }
  CHECK(p.stats().frames == accepted);
}

TEST_CASE("Random bytes and mutated frames never crash the parser", "[mavlink]") {
  std::mt19937_64 rng(2024);
  ParserStats total;
  std::size_t frames_total = 0;
  for (int round = 0; round < 3000; ++round) {
    Parser p;
    Bytes buf;
    if (round % 2 == 0) {
      buf.resize(rng() % 600);
      for (auto& b : buf) {
        const auto r = rng() % 16;
        b = r == 0 ? kStxV2 : r == 1 ? kStxV1 : static_cast<std::uint8_t>(rng());
      }
    } else {
      // Valid frames with a few bytes flipped, dropped or inserted.
      for (int k = 0; k < 5; ++k) {
        const Bytes f = encode_v2(test::random_message<SetPositionTargetLocalNed>(rng), 0, 1, 1);
        buf.insert(buf.end(), f.begin(), f.end());
      }
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits && !buf.empty(); ++e) {
        const std::size_t at = rng() % buf.size();
        switch (rng() % 3) {
          case 0:
            buf[at] = static_cast<std::uint8_t>(rng());
            break;
          case 1:
            buf.erase(buf.begin() + static_cast<std::ptrdiff_t>(at));
            break;
          default:
            buf.insert(buf.begin() + static_cast<std::ptrdiff_t>(at), 0xFD);
            break;
        }
      }
    }
    // Random chunking must not change the outcome.
    std::size_t n_chunked = 0;
    for (std::size_t i = 0; i < buf.size();) {
      const std::size_t n = std::min<std::size_t>(buf.size() - i, 1 + rng() % 64);
      p.feed(buf.data() + i, n, [&](const Frame& f) {
        CHECK(find_message(f.msg_id) != nullptr);
        CHECK(f.len <= find_message(f.msg_id)->length);
        ++n_chunked;
      });
      CHECK(p.buffered() <= kMaxFrameLength);
      i += n;
    }
    Parser whole;
    CHECK(whole.feed(buf).size() == n_chunked);
    CHECK(whole.stats().junk_bytes == p.stats().junk_bytes);
    frames_total += n_chunked;
    total.bad_crc += p.stats().bad_crc;
    total.bad_length += p.stats().bad_length;
    total.bad_flags += p.stats().bad_flags;
    total.unknown_msgid += p.stats().unknown_msgid;
    total.junk_bytes += p.stats().junk_bytes;
  }
  // Every kind of rejection happened; mutated rounds still delivered most of their frames.
  CHECK(total.bad_crc > 0);
  CHECK(total.bad_length > 0);
  CHECK(total.bad_flags > 0);
  CHECK(total.unknown_msgid > 0);
  CHECK(total.junk_bytes > 0);
  CHECK(frames_total > 1500 * 2);
}

TEST_CASE("Text fields: NUL padding and the unterminated maximum length", "[mavlink]") {
  ParamSet ps;
  ps.param_id = to_chars<16>("FS_PILOT_TIMEOUT");  // exactly 16 characters: no terminator
  ps.param_value = 3.0f;
  ps.param_type = 9;
  Parser p;
  auto frames = p.feed(encode_v2(ps, 0, 255, 190));
  REQUIRE(frames.size() == 1);
  CHECK(to_string(decode<ParamSet>(frames[0])->param_id) == "FS_PILOT_TIMEOUT");
  ps.param_id = to_chars<16>("FS_GCS_ENABLE_AND_MORE");
  CHECK(to_string(ps.param_id) == "FS_GCS_ENABLE_AN");
  CHECK(to_string(to_chars<16>("")).empty());
}
