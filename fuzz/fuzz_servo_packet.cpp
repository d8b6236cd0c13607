// libFuzzer target: ArduPilot SITL's JSON-interface servo packet parser and the reply writer
// (apps/sitl/protocol.hpp).
//
// Oracle:
// - parse_servo_packet(input) accepts exactly the 40-byte packets with the 16-channel magic and
//   the 72-byte ones with the 32-channel magic; what it reads re-encodes to the input byte for
//   byte; channels beyond the packet's count are 0; a rejected datagram leaves `out` untouched.
// - format_reply(reply with fields from the input's bytes, buffer of a fuzzed capacity) returns 0
//   when a value is not finite or the buffer is too small (a full-size buffer may refuse only a
//   timestamp beyond 1e15 s); otherwise a length below the
//   capacity of "\n{...}\n" whose JSON parses (nlohmann) and holds the finite values it was given.
#include <nlohmann/json.hpp>
#include <vector>

#include "fuzz_common.hpp"
#include "protocol.hpp"

using namespace kelp_sitl;

namespace {

void check_packet(const std::uint8_t* data, std::size_t size) {
  ServoPacket out;
  out.magic = 0xBEEF;  // sentinel: a rejected datagram must not touch it
  const PacketError e = parse_servo_packet(data, size, out);
  const auto u16 = [data](std::size_t i) {
    return static_cast<std::uint16_t>(data[i] | (data[i + 1] << 8));
  };
  bool valid = false;
  if (size == servo_packet_16_size) valid = u16(0) == servo_magic_16;
  if (size == servo_packet_32_size) valid = u16(0) == servo_magic_32;
  KELP_FUZZ_REQUIRE((e == PacketError::none) == valid, "servo packet accepted iff well-formed");
  if (e != PacketError::none) {
    KELP_FUZZ_REQUIRE(out.magic == 0xBEEF, "rejected packet modified the output");
    KELP_FUZZ_REQUIRE(to_string(e) != nullptr, "error name");
    return;
  }
  KELP_FUZZ_REQUIRE(out.channels == (size == servo_packet_16_size ? 16 : 32), "channel count");
  std::vector<std::uint8_t> again(size);
  const auto put16 = [&again](std::size_t i, std::uint16_t v) {
    again[i] = static_cast<std::uint8_t>(v & 0xFF);
    again[i + 1] = static_cast<std::uint8_t>(v >> 8);
  };
  put16(0, out.magic);
  put16(2, out.frame_rate);
  for (int b = 0; b < 4; ++b)
    again[4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(out.frame_count >> (8 * b));
  for (int i = 0; i < out.channels; ++i)
    put16(8 + 2 * static_cast<std::size_t>(i), out.pwm[static_cast<std::size_t>(i)]);
  for (std::size_t i = static_cast<std::size_t>(out.channels); i < out.pwm.size(); ++i)
    KELP_FUZZ_REQUIRE(out.pwm[i] == 0, "channel beyond the packet's count not 0");
  KELP_FUZZ_REQUIRE(std::equal(again.begin(), again.end(), data), "servo packet round trip");
}

void check_reply(const std::uint8_t* data, std::size_t size) {
  kelp_fuzz::Reader in(data, size);
  VehicleReply r;
  const std::size_t cap = in.u32(static_cast<std::uint32_t>(max_reply_size)) % 1024;
  r.timestamp = in.f64(0.0);
  for (auto* v : {&r.gyro, &r.accel_body, &r.position, &r.velocity})
    for (int i = 0; i < 3; ++i) (*v)(i) = in.f64((*v)(i));
  r.attitude.w() = in.f64(1.0);
  r.attitude.x() = in.f64(0.0);
  r.attitude.y() = in.f64(0.0);
  r.attitude.z() = in.f64(0.0);
  r.rangefinder = in.f64(r.rangefinder);
  std::vector<char> buf(cap + 1, '\x7f');  // one guard byte past the capacity
  const std::size_t n = format_reply(r, buf.data(), cap);
  KELP_FUZZ_REQUIRE(buf[cap] == '\x7f', "format_reply wrote past its capacity");
  const bool finite = std::isfinite(r.timestamp) && r.gyro.allFinite() &&
                      r.accel_body.allFinite() && r.position.allFinite() &&
                      r.velocity.allFinite() && r.attitude.coeffs().allFinite();
  if (!finite) {
    KELP_FUZZ_REQUIRE(n == 0, "a reply with a non-finite value was not withheld");
    return;
  }
  if (n == 0) {
    // Only a small buffer may refuse a finite reply: every reply fits max_reply_size as long
    // as the timestamp (printed with %.9f, all its integer digits) is below ~1e80 s; past 1e15
    // s (30 million years of physics time) refusing it is accepted.
    KELP_FUZZ_REQUIRE(cap < max_reply_size || std::abs(r.timestamp) >= 1e15,
                      "finite reply refused with a full-size buffer");
    return;
  }
  KELP_FUZZ_REQUIRE(n < cap, "reply length not below the capacity");
  const std::string s(buf.data(), n);
  KELP_FUZZ_REQUIRE(s.size() >= 4 && s.front() == '\n' && s[n - 2] == '}' && s.back() == '\n',
                    "reply framing");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(s.substr(1, n - 2));
  } catch (const nlohmann::json::exception& e) {
    kelp_fuzz::finding(std::string("reply is not JSON: ") + e.what() + ": " + s);
  }
  KELP_FUZZ_REQUIRE(j.contains("timestamp") && j.contains("imu") && j.contains("position") &&
                        j.contains("velocity") && j.contains("quaternion"),
                    "reply misses a mandatory key");
  KELP_FUZZ_REQUIRE(j.contains("rng_1") == std::isfinite(r.rangefinder), "rng_1 iff finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  check_packet(data, size);
  check_reply(data, size);
  return 0;
}
