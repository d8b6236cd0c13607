// libFuzzer target: kelp-sitl's lockstep bridge fed arbitrary datagrams from both autopilots
// (apps/sitl/bridge.hpp: Bridge::receive and check_timeouts over parse_servo_packet), with
// the calm default world of kelp::sim (its tether in two segments).
//
// Input: byte 0 = settings (bit 0: start_together), then records, at most 48:
//   op [u8: bit 0 slot, bit 1 check_timeouts instead of a datagram, bits 2-7 wall-clock advance
//   in 0.1 s], len [u8], len bytes of datagram.
// Oracle: every call appends at most 2 replies, each to a slot that sent packets, of the form
// "\n{json}\n" with a parseable JSON object; per slot, valid packets + malformed ones = the
// datagrams sent; steps never decrease; physics time stays finite. Any exception, crash or
// sanitizer report is a finding.
#include <memory>
#include <nlohmann/json.hpp>

#include "bridge.hpp"
#include "fuzz_common.hpp"
#include "kelp/sim/world.hpp"

using namespace kelp_sitl;

namespace {

struct World {
  kelp::sim::WorldSetup setup;
  kelp::system::SystemModeld model;
  kelp::system::SystemWorkspaced ws;
  kelp::system::SystemStated initial;
  static kelp::sim::Scenario calm() {
    kelp::sim::Scenario s;
    s.sea = kelp::sim::Sea::calm;
    // Two segments instead of twenty: the bridge's state machine is the target, and with the
    // coverage instrumentation's comparison tracing the tether's loops took half of every run.
    s.segment_length = 5.0;
    return s;
  }
  World()
      : setup(kelp::sim::world_setup(calm(), "fuzz")),
        model(setup.parameters, setup.environment),
        ws(model),
        initial(kelp::system::initial_state(model, ws, setup.start.asv, setup.start.auv)) {}
};

World& world() {
  static World w;
  return w;
}

void check_outbox(const Outbox& out, const std::array<std::uint64_t, 2>& valid) {
  KELP_FUZZ_REQUIRE(out.count >= 0 && out.count <= 2, "more than two replies in one call");
  for (int i = 0; i < out.count; ++i) {
    const Outgoing& g = out.items[static_cast<std::size_t>(i)];
    KELP_FUZZ_REQUIRE(g.slot == sub || g.slot == rover, "reply to an unknown slot");
    KELP_FUZZ_REQUIRE(valid[static_cast<std::size_t>(g.slot)] > 0,
                      "reply to an autopilot that sent no valid packet");
    KELP_FUZZ_REQUIRE(g.data != nullptr && g.size >= 4 && g.size < max_reply_size, "reply size");
    const std::string s(g.data, g.size);
    KELP_FUZZ_REQUIRE(s.front() == '\n' && s.back() == '\n', "reply framing");
    try {
      const nlohmann::json j = nlohmann::json::parse(s.substr(1, s.size() - 2));
      KELP_FUZZ_REQUIRE(j.is_object() && j.contains("timestamp"), "reply JSON");
    } catch (const nlohmann::json::exception& e) {
      kelp_fuzz::finding(std::string("reply is not JSON: ") + e.what());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  World& w = world();
  kelp_fuzz::Reader in(data, size);
  BridgeSettings settings;
  settings.start_together = (in.u8(1) & 1) != 0;
  settings.peer_timeout = 1.0;
  Bridge bridge(w.model, w.ws, w.initial, w.setup.start, settings);
  bridge.on_event = [](const std::string& e) { KELP_FUZZ_REQUIRE(!e.empty(), "empty event line"); };
  double wall = 0.0;
  std::array<std::uint64_t, 2> sent{0, 0}, valid{0, 0};
  std::uint64_t steps = 0;
  Outbox out;
  for (int record = 0; record < 48 && in.remaining() > 0; ++record) {
    const std::uint8_t op = in.u8();
    const int slot = op & 1;
    wall += 0.1 * (op >> 2);
    out.clear();
    if (op & 2) {
      bridge.check_timeouts(wall, out);
    } else {
      std::size_t n = in.u8();
      std::size_t avail = 0;
      const std::uint8_t* rest = in.rest(avail);
      n = std::min(n, avail);
      // The datagram in its own buffer, so that ASan sees any read past its end.
      const std::unique_ptr<std::uint8_t[]> d(new std::uint8_t[n == 0 ? 1 : n]);
      std::copy(rest, rest + n, d.get());
      in = kelp_fuzz::Reader(rest + n, avail - n);
      ServoPacket pkt;
      if (parse_servo_packet(d.get(), n, pkt) == PacketError::none)
        ++valid[static_cast<std::size_t>(slot)];
      ++sent[static_cast<std::size_t>(slot)];
      bridge.receive(slot, d.get(), n,
                     Endpoint{0x0100007F, static_cast<std::uint16_t>(5000 + slot)}, wall, out);
    }
    check_outbox(out, valid);
    for (int s = 0; s < 2; ++s) {
      const PeerCounters& c = bridge.counters(s);
      KELP_FUZZ_REQUIRE(c.packets == valid[static_cast<std::size_t>(s)] &&
                            c.packets + c.malformed == sent[static_cast<std::size_t>(s)],
                        "datagram counters");
    }
    KELP_FUZZ_REQUIRE(bridge.steps() >= steps, "steps decreased");
    steps = bridge.steps();
    KELP_FUZZ_REQUIRE(std::isfinite(bridge.state().time), "physics time not finite");
  }
  return 0;
}
