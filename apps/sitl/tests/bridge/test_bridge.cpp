// kelp-sitl's bridge in-process: servo packet parsing, the reply format, the thruster mapping and
// the lockstep rules that the loopback test (fake_sitl.py) does not reach (start with the first
// autopilot, missed frames, withheld replies).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bridge.hpp"
#include "default_world.hpp"
#include "kelp/sim/world.hpp"

using namespace kelp_sitl;

namespace {

std::vector<std::uint8_t> packet(std::uint16_t magic, std::uint32_t frame,
                                 const std::vector<std::uint16_t>& pwm) {
  const int n = magic == servo_magic_16 ? 16 : 32;
  std::vector<std::uint8_t> d(8 + 2 * static_cast<std::size_t>(n), 0);
  const auto put16 = [&](std::size_t i, std::uint16_t v) {
    d[i] = static_cast<std::uint8_t>(v & 0xFF);
    d[i + 1] = static_cast<std::uint8_t>(v >> 8);
  };
  put16(0, magic);
  put16(2, 1200);
  for (int b = 0; b < 4; ++b)
    d[4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(frame >> (8 * b));
  for (int i = 0; i < n; ++i)
    put16(8 + 2 * static_cast<std::size_t>(i),
          i < static_cast<int>(pwm.size()) ? pwm[static_cast<std::size_t>(i)] : 1000);
  return d;
}

struct Fixture {
  kelp::sim::Scenario scenario;
  kelp::sim::WorldSetup setup;
  kelp::system::SystemModeld model;
  kelp::system::SystemWorkspaced ws;
  Bridge bridge;
  std::vector<std::string> events;

  explicit Fixture(bool together)
      : scenario(calm()),
        setup(kelp::sim::world_setup(scenario, "test")),
        model(setup.parameters, setup.environment),
        ws(model),
        bridge(model, ws, kelp::system::initial_state(model, ws, setup.start.asv, setup.start.auv),
               setup.start, settings(together)) {
    bridge.on_event = [this](const std::string& s) { events.push_back(s); };
  }
  static kelp::sim::Scenario calm() {
    kelp::sim::Scenario s;
    s.sea = kelp::sim::Sea::calm;
    return s;
  }
  static BridgeSettings settings(bool together) {
    BridgeSettings b;
    b.start_together = together;
    b.peer_timeout = 1.0;
    return b;
  }
  int send(int slot, std::uint32_t frame, const std::vector<std::uint16_t>& pwm, double wall,
           Outbox& out) {
    out.clear();
    const auto d = packet(slot == sub ? servo_magic_16 : servo_magic_32, frame, pwm);
    bridge.receive(slot, d.data(), d.size(), Endpoint{0x0100007F, 5000}, wall, out);
    return out.count;
  }
};

nlohmann::json reply_json(const Outgoing& g) {
  const std::string s(g.data, g.size);
  REQUIRE(s.front() == '\n');
  REQUIRE(s.back() == '\n');
  return nlohmann::json::parse(s.substr(1, s.size() - 2));
}

}  // namespace

TEST_CASE("servo packets: both magics, exact sizes only", "[sitl]") {
  ServoPacket p;
  auto d16 = packet(servo_magic_16, 0x01020304u, {1100, 1900});
  REQUIRE(parse_servo_packet(d16.data(), d16.size(), p) == PacketError::none);
  CHECK(p.channels == 16);
  CHECK(p.frame_count == 0x01020304u);
  CHECK(p.frame_rate == 1200);
  CHECK(p.pwm[0] == 1100);
  CHECK(p.pwm[1] == 1900);
  CHECK(p.pwm[2] == 1000);
  CHECK(p.pwm[16] == 0);
  auto d32 = packet(servo_magic_32, 7, std::vector<std::uint16_t>(32, 1234));
  REQUIRE(parse_servo_packet(d32.data(), d32.size(), p) == PacketError::none);
  CHECK(p.channels == 32);
  CHECK(p.pwm[31] == 1234);
  // Wrong sizes, wrong magic, magic and size that disagree.
  CHECK(parse_servo_packet(d16.data(), 39, p) == PacketError::size);
  CHECK(parse_servo_packet(d32.data(), 73, p) == PacketError::size);
  CHECK(parse_servo_packet(d16.data(), 0, p) == PacketError::size);
  d16[0] ^= 0xFF;
  CHECK(parse_servo_packet(d16.data(), d16.size(), p) == PacketError::magic);
  auto mixed = packet(servo_magic_16, 0, {});
  mixed.resize(servo_packet_32_size, 0);
  CHECK(parse_servo_packet(mixed.data(), mixed.size(), p) == PacketError::size_mismatch);
}

TEST_CASE("replies: the format SITL's parser needs, and nothing non-finite", "[sitl]") {
  VehicleReply r;
  r.timestamp = 1.0 / 1200.0;
  r.accel_body = kelp::Vector3<double>(0, 0, -9.80665);
  r.position = kelp::Vector3<double>(1.5, -2, 5);
  char buf[max_reply_size];
  const std::size_t n = format_reply(r, buf, sizeof buf);
  REQUIRE(n > 0);
  const std::string s(buf, n);
  CHECK(s.rfind("\n{\"timestamp\":0.000833333,", 0) == 0);
  CHECK(s.find(": ") == std::string::npos);
  CHECK(s.find("\"position\":[1.5,-2,5]") != std::string::npos);
  CHECK(s.find("\"quaternion\":[1,0,0,0]") != std::string::npos);
  CHECK(s.find("rng_1") == std::string::npos);
  r.rangefinder = 12.5;
  const std::string with_rng(buf, format_reply(r, buf, sizeof buf));
  CHECK(with_rng.find(",\"rng_1\":12.5}\n") != std::string::npos);
  r.velocity.x() = NAN;
  CHECK(format_reply(r, buf, sizeof buf) == 0);
  r.velocity.x() = 0;
  CHECK(format_reply(r, buf, 40) == 0);  // too small a buffer: refused, not cut
}

TEST_CASE("thrusters: ArduSub's vertical motors below 1500 push up, Rover's throttle ahead",
          "[sitl]") {
  Fixture f(true);
  Outbox out;
  f.send(sub, 0, {1500, 1500, 1500, 1500, 1300, 1300, 1300, 1300}, 0, out);
  f.send(rover, 0, {1800, 1500, 1800, 1500}, 0, out);
  REQUIRE(out.count == 2);
  // T200 at command -0.5: ≈ −4.7 N each, along +z (down) ⇒ up; the boat's two ahead.
  for (int i = 0; i < 4; ++i) CHECK(f.bridge.auv_thrust()(i) == 0.0);
  for (int i = 4; i < 8; ++i) {
    CHECK(f.bridge.auv_command()(i) == Approx(-0.5));
    CHECK(f.bridge.auv_thrust()(i) == Approx(kelp::vehicle::t200_thrust(-0.5)));
    CHECK(f.bridge.auv_thrust()(i) < -3.0);
  }
  CHECK(f.bridge.asv_command()(0) == Approx(0.6));
  CHECK(f.bridge.asv_command()(1) == Approx(0.6));
  CHECK(f.bridge.asv_thrust()(0) > 5.0);
  // Inside the ±25 µs dead band, no pulse, or an implausible pulse: off.
  f.send(sub, 1, {1520, 1480, 0, 3000, 1500, 1500, 1500, 1500}, 0, out);
  CHECK(f.bridge.auv_thrust().head<4>().isZero());
  CHECK(f.bridge.counters(sub).pwm_out_of_range == 1);
}

TEST_CASE("lockstep: one clock for both, start with the first when asked, missed frames",
          "[sitl]") {
  SECTION("start together: the first autopilot waits") {
    Fixture f(true);
    Outbox out;
    CHECK(f.send(sub, 0, {}, 0, out) == 0);
    CHECK(f.bridge.steps() == 0);
    CHECK(f.send(rover, 0, {}, 0, out) == 2);
    CHECK(f.bridge.steps() == 1);
    CHECK(reply_json(out.items[0])["timestamp"] == reply_json(out.items[1])["timestamp"]);
    // The rover's next frame alone does not step: ArduSub has not asked yet.
    CHECK(f.send(rover, 1, {}, 0, out) == 0);
    CHECK(f.send(sub, 1, {}, 0, out) == 2);
    CHECK(f.bridge.steps() == 2);
  }
  SECTION("start with the first: the world runs, the other joins at the current time") {
    Fixture f(false);
    Outbox out;
    for (std::uint32_t k = 0; k < 12; ++k) REQUIRE(f.send(sub, k, {}, 0, out) == 1);
    CHECK(f.bridge.steps() == 12);
    CHECK(!f.bridge.joined(rover));
    CHECK(f.send(rover, 0, {}, 0, out) == 0);  // waits for ArduSub's next frame
    CHECK(f.send(sub, 12, {}, 0, out) == 2);
    CHECK(reply_json(out.items[1])["timestamp"].get<double>() == Approx(13.0 / 1200.0));
  }
  SECTION("frames jumped ahead are counted; the clock still advances one step per frame") {
    Fixture f(true);
    Outbox out;
    f.send(sub, 0, {}, 0, out);
    f.send(rover, 0, {}, 0, out);
    f.send(sub, 5, {}, 0, out);
    CHECK(f.send(rover, 1, {}, 0, out) == 2);
    CHECK(f.bridge.counters(sub).missed_frames == 4);
    CHECK(f.bridge.state().time == Approx(2.0 / 1200.0));
  }
  SECTION("a silent autopilot leaves after the time-out, not one the bridge keeps waiting") {
    Fixture f(true);
    Outbox out;
    f.send(sub, 0, {}, 0, out);
    f.send(rover, 0, {}, 0, out);
    f.send(sub, 1, {}, 0.1, out);  // ArduSub waits for ArduRover's frame 1
    out.clear();
    f.bridge.check_timeouts(0.9, out);
    CHECK(out.count == 0);
    f.bridge.check_timeouts(1.2, out);  // ArduRover silent 1.2 s > 1 s; ArduSub only waiting
    REQUIRE(out.count == 1);
    CHECK(out.items[0].slot == sub);
    CHECK(f.bridge.active(sub));
    CHECK(!f.bridge.active(rover));
    CHECK(f.bridge.counters(rover).timeouts == 1);
    // Back with the frame it was last answered for: the same answer again, no step.
    const std::uint64_t steps = f.bridge.steps();
    REQUIRE(f.send(rover, 0, {}, 2.0, out) == 1);
    CHECK(f.bridge.steps() == steps);
    CHECK(f.bridge.active(rover));
    CHECK(f.bridge.counters(rover).repeats == 1);
  }
}

TEST_CASE(
    "battery: the PWM drives the thrusters' propulsion and SITL is sent the battery's "
    "voltage and current",
    "[sitl][propulsion]") {
  // The format: "battery": {"voltage", "current"} (ArduPilot SIM_JSON's keytable), only when
  // known.
  VehicleReply r;
  char buf[max_reply_size];
  CHECK(std::string(buf, format_reply(r, buf, sizeof buf)).find("battery") == std::string::npos);
  r.battery_voltage = 15.25;
  r.battery_current = 12.5;
  const std::string s(buf, format_reply(r, buf, sizeof buf));
  CHECK(s.find(",\"battery\":{\"voltage\":15.25,\"current\":12.5}}\n") != std::string::npos);

  Fixture f(true);
  REQUIRE(f.model.auv_propulsion() != nullptr);
  Outbox out;
  std::uint32_t frame = 0;
  const auto both = [&](const std::vector<std::uint16_t>& sub_pwm) {
    f.send(sub, frame, sub_pwm, 0, out);
    f.send(rover, frame, {1700, 1500, 1700, 1500}, 0, out);
    ++frame;
  };
  // Idle: no current but the (zero) hotel load, the open-circuit voltage.
  both({1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500});
  REQUIRE(out.count == 2);
  const double ocv =
      kelp::vehicle::open_circuit_voltage(f.model.auv_propulsion()->parameters().battery, 1.0);
  nlohmann::json sub_reply = reply_json(out.items[0].slot == sub ? out.items[0] : out.items[1]);
  CHECK(sub_reply.at("battery").at("voltage").get<double>() == Approx(ocv).epsilon(1e-6));
  CHECK(sub_reply.at("battery").at("current").get<double>() == 0.0);
  // Full down on the vertical thrusters for 0.5 s: current drawn, the voltage sags, the thrust
  // builds up through the lag to the static thrust at that voltage.
  for (int k = 0; k < 600; ++k) both({1500, 1500, 1500, 1500, 1900, 1900, 1900, 1900});
  sub_reply = reply_json(out.items[0].slot == sub ? out.items[0] : out.items[1]);
  const double v = sub_reply.at("battery").at("voltage").get<double>();
  const double i = sub_reply.at("battery").at("current").get<double>();
  CHECK(i == Approx(4.0 * kelp::vehicle::t200_current(1.0, v)).epsilon(1e-4));
  CHECK(i > 20.0);
  CHECK(v < ocv - 0.5);
  CHECK(f.bridge.state().auv_propulsion.thrust(4) ==
        Approx(kelp::vehicle::t200_thrust(1.0, v)).epsilon(1e-3));
  CHECK(f.bridge.state().auv_propulsion.battery.charge_drawn > 0.5 * i * 0.4);
  // The boat's battery too.
  const nlohmann::json boat = reply_json(out.items[0].slot == rover ? out.items[0] : out.items[1]);
  CHECK(boat.at("battery").at("current").get<double>() > 1.0);
}

TEST_CASE("calm start: the ROV resting in the default world reads about g in its first second",
          "[sitl][start]") {
  // kelp-sitl's own world (default_world.hpp, world_setup, start_state), both autopilots at
  // neutral (1500 µs on every channel: no thrust), 1 s of frames at the bridge's rate. The
  // specific force is what the bridge sends as ArduSub's accelerometer (reply_of: v̇ + ω × v from
  // the state's auv_nu_dot, minus gravity, in body axes).
  const auto worst = [](const kelp::sim::Scenario& sc) {
    const kelp::sim::WorldSetup setup = kelp::sim::world_setup(sc, "test");
    const kelp::system::SystemModeld model(setup.parameters, setup.environment);
    kelp::system::SystemWorkspaced ws(model);
    Bridge bridge(model, ws, kelp::sim::start_state(model, ws, setup, sc), setup.start, {});
    const std::vector<std::uint16_t> neutral(16, 1500);
    const auto a = packet(servo_magic_16, 0, neutral), b = packet(servo_magic_32, 0, neutral);
    const double g = model.environment().gravity();
    double e = 0;
    Outbox out;
    for (std::uint32_t k = 0; k < 1200; ++k) {
      auto pa = packet(servo_magic_16, k, neutral), pb = packet(servo_magic_32, k, neutral);
      out.clear();
      bridge.receive(sub, pa.data(), pa.size(), Endpoint{0x0100007F, 5000}, 0, out);
      bridge.receive(rover, pb.data(), pb.size(), Endpoint{0x0100007F, 5001}, 0, out);
      REQUIRE(out.count == 2);
      REQUIRE(bridge.auv_thrust().isZero());
      e = std::max(e, std::abs(bridge.reply_of(sub).accel_body.norm() - g));
    }
    CHECK(bridge.state().time == Approx(1.0));
    return e;
  };
  kelp::sim::Scenario sc = default_scenario();
  const double calm = worst(sc);
  INFO("worst |f - g| with the default start: " << calm << " m/s^2");
  CHECK(calm < 3.0);
  // The same at the surface (the default world's start before the ROV went 8 m down), where the
  // waves act most.
  sc.auv_start = kelp::Vector3<double>(-4.0, 0.0, 0.3);
  const double surface = worst(sc);
  INFO("worst |f - g| starting at the surface: " << surface << " m/s^2");
  CHECK(surface < 3.0);
  // The start transient this guards against: the sea at full strength from t = 0.
  sc.start_ramp = 0;
  sc.start_with_water = false;
  const double abrupt = worst(sc);
  INFO("worst |f - g| at the surface without the ramp: " << abrupt << " m/s^2");
  CHECK(abrupt > 3.0);
}
