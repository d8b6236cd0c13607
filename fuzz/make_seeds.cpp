// Writes the binary seed corpora of kelp's fuzz targets, with the project's own encoders and
// presets: `kelp_fuzz_seeds <dir>` fills <dir>/<target>/*.bin (the committed fuzz/corpus). The
// scenario and sweep seeds are copies of the example files, not written here.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/presets.hpp"
#include "mavlink/mavlink.hpp"
#include "protocol.hpp"

namespace fs = std::filesystem;
namespace mav = kelp_sitl::mavlink;
namespace kv = kelp::vehicle;
using Bytes = std::vector<std::uint8_t>;

namespace {

fs::path root;

void write(const std::string& target, const std::string& name, const Bytes& b) {
  const fs::path dir = root / target;
  fs::create_directories(dir);
  std::ofstream(dir / (name + ".bin"), std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

Bytes servo_packet(int channels, std::uint32_t frame, std::uint16_t pwm) {
  kelp_fuzz::Writer w;
  const std::uint16_t magic =
      channels == 16 ? kelp_sitl::servo_magic_16 : kelp_sitl::servo_magic_32;
  w.u8(static_cast<std::uint8_t>(magic & 0xFF));
  w.u8(static_cast<std::uint8_t>(magic >> 8));
  w.u8(static_cast<std::uint8_t>(1200 & 0xFF));
  w.u8(static_cast<std::uint8_t>(1200 >> 8));
  w.u32(frame);
  for (int i = 0; i < channels; ++i) {
    const std::uint16_t v = i < 8 ? pwm : static_cast<std::uint16_t>(i % 3 == 0 ? 0 : 1500);
    w.u8(static_cast<std::uint8_t>(v & 0xFF));
    w.u8(static_cast<std::uint8_t>(v >> 8));
  }
  return w.bytes;
}

void servo_seeds() {
  write("fuzz_servo_packet", "packet16_neutral", servo_packet(16, 1, 1500));
  write("fuzz_servo_packet", "packet16_forward", servo_packet(16, 1234567, 1700));
  write("fuzz_servo_packet", "packet32_neutral", servo_packet(32, 1, 1500));
  write("fuzz_servo_packet", "packet32_reverse", servo_packet(32, 99, 1100));
  // A reply-shaped input: capacity then 18 doubles (timestamp, gyro, accel, position, velocity,
  // quaternion, rangefinder).
  kelp_fuzz::Writer r;
  r.u32(512);
  for (double v : {12.5, 0.01, -0.02, 0.03, 0.1, 0.2, -9.8, 1.0, 2.0, 5.0, 0.5, 0.0, 0.1, 1.0, 0.0,
                   0.0, 0.0, 3.5})
    r.f64(v);
  write("fuzz_servo_packet", "reply", r.bytes);
}

// Bridge records: op (bit 0 slot, bit 1 check_timeouts, bits 2-7 wall advance), len, datagram.
void record(kelp_fuzz::Writer& w, int slot, int advance, const Bytes& d) {
  w.u8(static_cast<std::uint8_t>(slot | (advance << 2)));
  w.u8(static_cast<std::uint8_t>(d.size()));
  for (std::uint8_t b : d) w.u8(b);
}

void bridge_seeds() {
  {  // both join, a few lockstep frames, a re-send
    kelp_fuzz::Writer w;
    w.u8(1);
    for (std::uint32_t f = 1; f <= 4; ++f) {
      record(w, 0, 0, servo_packet(16, f, 1600));
      record(w, 1, 0, servo_packet(32, f, 1550));
    }
    record(w, 0, 0, servo_packet(16, 4, 1600));
    write("fuzz_bridge", "lockstep", w.bytes);
  }
  {  // not together; a restart; junk; a time-out and a return
    kelp_fuzz::Writer w;
    w.u8(0);
    record(w, 0, 0, servo_packet(16, 10, 1500));
    record(w, 0, 0, servo_packet(16, 11, 1500));
    record(w, 1, 0, servo_packet(16, 5, 1700));
    record(w, 0, 0, servo_packet(16, 2, 1500));
    record(w, 1, 0, Bytes{1, 2, 3});
    w.u8(static_cast<std::uint8_t>(2 | (20 << 2)));  // check_timeouts 2 s later
    record(w, 1, 0, servo_packet(16, 6, 1700));
    write("fuzz_bridge", "restart_timeout", w.bytes);
  }
}

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// A signed v2 frame: flags bit 0 and a 13-byte signature after the CRC (not verified).
Bytes signed_v2(const Bytes& unsigned_frame, std::uint8_t crc_extra) {
  Bytes f = unsigned_frame;
  f[2] = mav::kIflagSigned;
  const std::size_t len = f[1];
  std::uint16_t crc = mav::crc_accumulate(f.data() + 1, mav::kHeaderV2 - 1 + len, mav::kCrcInit);
  crc = mav::crc_accumulate(crc_extra, crc);
  f[mav::kHeaderV2 + len] = static_cast<std::uint8_t>(crc & 0xFF);
  f[mav::kHeaderV2 + len + 1] = static_cast<std::uint8_t>(crc >> 8);
  for (int i = 0; i < 13; ++i) f.push_back(static_cast<std::uint8_t>(0xA0 + i));
  return f;
}

void mavlink_seeds() {
  mav::Sender gcs(255, mav::kCompMissionPlanner), ap(1, mav::kCompAutopilot1);
  mav::Heartbeat hb;
  hb.type = mav::kTypeSubmarine;
  hb.autopilot = mav::kAutopilotArdupilotmega;
  hb.base_mode = mav::kModeFlagCustomModeEnabled | mav::kModeFlagSafetyArmed;
  hb.custom_mode = mav::sub_mode::kAltHold;
  mav::CommandLong cmd;
  cmd.command = mav::kCmdComponentArmDisarm;
  cmd.param1 = 1;
  cmd.target_system = 1;
  cmd.target_component = 1;
  mav::CommandAck ack;
  ack.command = mav::kCmdComponentArmDisarm;
  ack.result = 0;
  mav::Statustext st;
  st.severity = 6;
  st.text = mav::to_chars<50>("ArduSub V4.7.0-dev (90700977)");
  mav::ParamSet ps;
  ps.param_id = mav::to_chars<16>("SYSID_MYGCS");
  ps.param_value = 255;
  ps.param_type = 9;
  mav::GlobalPositionInt gp;
  gp.lat = 338103130;
  gp.lon = -1183938670;
  gp.alt = -5000;
  gp.hdg = 9000;
  mav::SetPositionTargetLocalNed sp;
  sp.type_mask = mav::kTypeMaskPosition;
  sp.coordinate_frame = mav::kFrameLocalNed;
  sp.x = 10;
  sp.y = -3;
  sp.z = 5;
  mav::Attitude att;
  att.roll = 0.1F;
  att.yaw = -1.5F;
  mav::Timesync ts;
  ts.tc1 = 0;
  ts.ts1 = 123456789;

  const Bytes hb2 = ap.pack(hb), hb1 = mav::encode_v1(hb, 7, 1, 1);
  const Bytes c2 = gcs.pack(cmd), a2 = ap.pack(ack), st2 = ap.pack(st), ps2 = gcs.pack(ps);
  const Bytes gp2 = ap.pack(gp), sp2 = gcs.pack(sp), att2 = ap.pack(att), ts2 = ap.pack(ts);
  const Bytes st1 = mav::encode_v1(st, 3, 1, 1);
  const Bytes hb2s = signed_v2(hb2, mav::Heartbeat::crc_extra);
  // An unknown message (id 0x01_23_45) skipped whole when a start byte follows it.
  const std::uint8_t junk_payload[4] = {1, 2, 3, 4};
  Bytes unknown(mav::kHeaderV2 + 4 + 2);
  mav::frame_v2(0x012345, 0, junk_payload, 4, 9, 1, 1, unknown.data());
  const Bytes banner{'A', 'r', 'd', 'u', 'S', 'u', 'b', '\r', '\n'};

  const auto seed = [](std::uint8_t chunking, const Bytes& stream) {
    return cat({Bytes{chunking}, stream});
  };
  write("fuzz_mavlink", "heartbeat_v2", seed(0, hb2));
  write("fuzz_mavlink", "heartbeat_v1", seed(3, hb1));
  write("fuzz_mavlink", "heartbeat_v2_signed", seed(0, hb2s));
  write("fuzz_mavlink", "command_long_ack", seed(17, cat({c2, a2})));
  write("fuzz_mavlink", "statustext_v1_v2", seed(1, cat({st1, st2})));
  write("fuzz_mavlink", "param_set", seed(0, ps2));
  write("fuzz_mavlink", "telemetry", seed(5, cat({gp2, att2, ts2, sp2})));
  write("fuzz_mavlink", "banner_unknown_mixed",
        seed(42, cat({banner, hb2, unknown, c2, Bytes{0xFD, 0x09}, gp2})));
}

void catenary_seed(const std::string& name, double D, double dz, double L, double w,
                   kelp::Vector3<double> a, kelp::Vector3<double> b, double EA, double seabed) {
  kelp_fuzz::Writer s;
  for (double v : {D, dz, L, w, a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), EA, 1e-14, 1e-12, seabed})
    s.f64(v);
  s.i32(30);
  write("fuzz_catenary", name, s.bytes);
}

void catenary_seeds() {
  const double inf = std::numeric_limits<double>::infinity();
  catenary_seed("slack", 5, 2, 10, 1.2, {0, 0, 0}, {5, 0, 2}, 0, inf);
  catenary_seed("taut", 8, 6, 10, 0.5, {0, 0, 0}, {8, 0, 6}, 3000, inf);
  catenary_seed("vertical", 0, 4, 10, 1.0, {0, 0, 0}, {0, 0, 4}, 0, inf);
  catenary_seed("nearly_taut", 9.999999, 0.01, 10, 0.01, {0, 0, 0}, {9.999, 0.1, 0.5}, 1e5, inf);
  catenary_seed("buoyant", 3, -1, 15, -0.011, {1, 2, 0.2}, {4, 2, 6}, 2920, inf);
  catenary_seed("seabed", 10, 0, 40, 2.0, {0, 0, 10}, {10, 0, 18}, 0, 20);
  catenary_seed("very_slack", 1e-3, 0, 100, 1, {0, 0, 0}, {1e-3, 0, 0}, 0, inf);
}

void tether_seed(const std::string& name, const kelp::tether::TetherParametersd& p,
                 std::uint8_t flags, double seabed, kelp::Vector3<double> a,
                 kelp::Vector3<double> b, double dt) {
  kelp_fuzz::Writer s;
  s.u8(static_cast<std::uint8_t>((p.segments - 1) % 64));
  s.u8(flags);
  for (double v :
       {p.length, p.diameter, p.mass_per_length, p.axial_stiffness, p.internal_damping,
        p.bending_stiffness, p.normal_drag, p.tangential_drag, p.normal_added_mass,
        p.tangential_added_mass, p.seabed_stiffness, p.seabed_damping, p.seabed_damping_depth,
        p.seabed_friction, p.friction_velocity, p.start_point_mass, p.end_point_mass})
    s.f64(v);
  for (double v : {1025.0, 9.81, seabed, 0.5, 0.1, 0.0}) s.f64(v);  // ρ, g, seabed, current
  for (double v : {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}) s.f64(v);
  for (double v : {0.2, 0.0, 0.0, -0.3, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.05}) s.f64(v);
  s.f64(dt);
  s.f64(1.5e-4);  // acceleration tolerance
  s.f64(0.0);     // slack band
  for (std::uint8_t v : {8, 32, 6, 6, 1}) s.u8(v);
  write("fuzz_tether_step", name, s.bytes);
}

void tether_seeds() {
  namespace tp = kelp::tether::presets;
  const double inf = std::numeric_limits<double>::infinity();
  tether_seed("rov_tether_10m", tp::rov_tether(10.0, 0.5), 0, inf, {0, 0, 0.1}, {6, 1, 5}, 1e-3);
  tether_seed("bead_chain_5m", tp::bead_chain(5.0), 0, inf, {0, 0, 0}, {3, 0, 3}, 1e-3);
  kelp::tether::TetherParametersd free_end;
  free_end.segments = 16;
  free_end.internal_damping = 100;
  free_end.end_point_mass = 2.0;
  tether_seed("free_end_seabed", free_end, 2 | 4, 12.0, {0, 0, 0}, {10, 0, 11.5}, 1e-2);
  kelp::tether::TetherParametersd bend;
  bend.segments = 8;
  bend.bending_stiffness = 0.5;
  bend.seabed_friction = 0.3;
  tether_seed("bending_straight", bend, 8, 30.0, {0, 0, 1}, {15, 5, 8}, 1e-3);
}

void vehicle_seed(const std::string& name, std::uint8_t flags, const kv::VehicleParametersd& p,
                  const kv::VehicleStated& x, const kelp::Vector6<double>& tau, double dt) {
  kelp_fuzz::Writer s;
  s.u8(flags);
  const auto m = [&s](const auto& mat) {
    for (Eigen::Index j = 0; j < mat.cols(); ++j)
      for (Eigen::Index i = 0; i < mat.rows(); ++i) s.f64(mat(i, j));
  };
  s.f64(p.mass);
  m(p.inertia);
  m(p.r_g);
  m(p.r_b);
  s.f64(p.displaced_volume);
  s.f64(p.density);
  s.f64(p.gravity);
  m(p.added_mass);
  m(p.damping.linear);
  m(p.damping.quadratic);
  for (double v :
       {p.waterplane_area, p.gm_transverse, p.gm_longitudinal, p.hull_height,
        p.wind_areas.frontal_area, p.wind_areas.lateral_area, p.wind_areas.length_overall,
        p.wind_coefficients.cx, p.wind_coefficients.cy, p.wind_coefficients.cn})
    s.f64(v);
  m(x.position);
  for (double v : {x.attitude.w(), x.attitude.x(), x.attitude.y(), x.attitude.z()}) s.f64(v);
  m(x.nu);
  m(tau);
  m(kelp::Vector6<double>::Zero().eval());  // τ_ext
  for (double v : {0.3, -0.1, 0.0, p.density, p.gravity, dt, 0.0}) s.f64(v);
  write("fuzz_vehicle_step", name, s.bytes);
}

void vehicle_seeds() {
  const kv::VehiclePresetd rov = kv::bluerov2_heavy<double>(), boat = kv::blueboat<double>();
  kv::VehicleStated x;
  x.position = {1, 2, 5};
  x.nu << 0.5, 0.1, 0.0, 0.0, 0.0, 0.2;
  kelp::Vector6<double> tau;
  tau << 20, 0, 5, 0, 0, 1;
  vehicle_seed("bluerov2_heavy", 0, rov.parameters, x, tau, 1e-3);
  kv::VehicleStated y;
  y.attitude = kelp::Quaternion<double>(Eigen::AngleAxisd(0.7, kelp::Vector3<double>::UnitZ()));
  y.nu << 1.0, 0.0, 0.0, 0.0, 0.0, 0.0;
  tau << 30, 0, 0, 0, 0, -2;
  vehicle_seed("blueboat", 1, boat.parameters, y, tau, 1e-2);
  vehicle_seed("bluerov2_free_surface", 2 | (2 << 2), rov.parameters, y, tau, 5e-3);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <corpus dir>\n", argv[0]);
    return 2;
  }
  root = argv[1];
  servo_seeds();
  bridge_seeds();
  mavlink_seeds();
  catenary_seeds();
  tether_seeds();
  vehicle_seeds();
  return 0;
}
