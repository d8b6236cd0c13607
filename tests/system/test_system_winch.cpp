// The boat's winch in system::step (SystemParameters::winch, SystemInputs::winch_payout_rate):
// the line pays out and reels back in during a coupled run with nodes inserted and removed,
// without allocating, and a failed step leaves the state (node count included) as it was, a
// non-finite payout rate in the state included.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>

#include "kelp/system/system.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/presets.hpp"

namespace ks = kelp::system;
namespace kt = kelp::tether;
namespace kv = kelp::vehicle;
using kelp::Vector3;

namespace {
ks::SystemParametersd winch_system() {
  ks::SystemParametersd p;
  p.asv = kv::blueboat<double>().parameters;
  p.auv = kv::bluerov2_heavy<double>().parameters;
  p.asv_attachment = Vector3<double>(-0.5, 0, 0);
  p.auv_attachment = Vector3<double>(0, 0, -0.15);
  p.tether = kt::presets::rov_tether(10.0, 0.5);
  kt::WinchParametersd w;
  w.min_length = 6;
  w.max_length = 20;
  w.max_speed = 0.5;
  w.max_acceleration = 0.5;
  p.winch = w;
  return p;
}

ks::SystemStated start(const ks::SystemModeld& model, ks::SystemWorkspaced& ws) {
  kv::VehicleStated asv, auv;
  auv.position = Vector3<double>(6, 0, 5);
  return ks::initial_state(model, ws, asv, auv);
}
}  // namespace

TEST_CASE("the boat's winch pays out and reels in during system::step without allocating",
          "[system][winch]") {
  kelp::environment::Environmentd env;
  const ks::SystemModeld model(winch_system(), env);
  ks::SystemWorkspaced ws(model);
  ks::SystemStated s = start(model, ws);
  const double l = model.winch()->segment_length();
  const double mu = model.tether().parameters().mass_per_length;
  const double m0 = kt::line_mass(model.tether_of(s), s.tether);
  CHECK(m0 == Approx(mu * 10.0).epsilon(1e-12));
  ks::SystemInputsd in;
  const double dt = 0.01;
  int inserted = 0, removed = 0;
  double longest = 0;
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 4000; ++k) {
    const double t = k * dt;
    in.winch_payout_rate = t < 10 ? 0.5 : (t < 15 ? 0.0 : -0.5);
    const ks::SystemReportd r = ks::step(model, ws, s, in, dt);
    inserted += r.remesh.inserted;
    removed += r.remesh.removed;
    longest = std::max(longest, kt::unstretched_length(model.tether_of(s), s.tether));
  }
  Eigen::internal::set_is_malloc_allowed(true);
  const kt::TetherModeld& line = model.tether_of(s);
  const double length = kt::unstretched_length(line, s.tether);
  // 10 s at 0.5 m/s with 1 s ramps up and down (0.5 m/s²): 5 m out; then 25 s of reeling in
  // stop at the winch's minimum, 6 m.
  CHECK(longest == Approx(15.0).epsilon(1e-9));
  CHECK(length == Approx(6.0).epsilon(1e-9));
  CHECK(inserted >= int(4.5 / l) - 1);
  CHECK(removed == inserted + int(std::lround(4.0 / l)));
  CHECK(line.segments() == model.tether().segments() + inserted - removed);
  CHECK(kt::line_mass(line, s.tether) == Approx(mu * length).epsilon(1e-12));
  CHECK(ws.tether.fits(line.nodes()));
  CHECK(s.tether.position.allFinite());
  // The energy and the static checks read the state's own line model.
  CHECK(std::isfinite(ks::energy(model, s).total()));
}

TEST_CASE("a failed winch step leaves the state as it was, node count included",
          "[system][winch][bad_input]") {
  kelp::environment::Environmentd env;
  const ks::SystemModeld model(winch_system(), env);
  ks::SystemWorkspaced ws(model);
  ks::SystemStated s = start(model, ws);
  ks::SystemInputsd in;
  in.winch_payout_rate = 0.5;
  for (int k = 0; k < 300; ++k) ks::step(model, ws, s, in, 0.01);
  const ks::SystemStated before = s;
  in.winch_payout_rate = std::nan("");
  CHECK_THROWS_AS(ks::step(model, ws, s, in, 0.01), kelp::invalid_argument);
  in.winch_payout_rate = 0.5;
  in.asv.tau(0) = std::nan("");
  CHECK_THROWS_AS(ks::step(model, ws, s, in, 0.01), kelp::invalid_argument);
  CHECK(s.tether.position == before.tether.position);
  CHECK(s.tether.winch_length == before.tether.winch_length);
  CHECK(s.time == before.time);
  // A system without a winch refuses a payout command.
  ks::SystemParametersd p = winch_system();
  p.winch.reset();
  const ks::SystemModeld fixed(p, env);
  ks::SystemWorkspaced fws(fixed);
  ks::SystemStated fs = start(fixed, fws);
  ks::SystemInputsd fin;
  fin.winch_payout_rate = 0.1;
  CHECK_THROWS_WITH(ks::step(fixed, fws, fs, fin, 0.01), Catch::Contains("no winch"));
}

TEST_CASE("system::step refuses a non-finite payout rate in the state and changes nothing",
          "[system][winch][bad_input]") {
  kelp::environment::Environmentd env;
  const ks::SystemModeld model(winch_system(), env);
  ks::SystemWorkspaced ws(model);
  ks::SystemStated s = start(model, ws);
  ks::SystemInputsd in;
  in.winch_payout_rate = 0.5;
  ks::step(model, ws, s, in, 0.01);
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    INFO("payout rate " << bad);
    ks::SystemStated x = s;
    x.tether.payout_rate = bad;
    const ks::SystemStated before = x;
    CHECK_THROWS_WITH(ks::step(model, ws, x, in, 0.01), Catch::Contains("state.payout_rate"));
    CHECK(x.time == before.time);
    CHECK(x.tether.time == before.tether.time);
    CHECK(x.tether.position == before.tether.position);
    CHECK(x.tether.velocity == before.tether.velocity);
    CHECK(x.tether.winch_length == before.tether.winch_length);
    CHECK(std::memcmp(&x.tether.payout_rate, &before.tether.payout_rate, sizeof(double)) == 0);
    CHECK(x.asv.position == before.asv.position);
    CHECK(x.auv.nu == before.auv.nu);
  }
  // The state as it was steps on.
  CHECK_NOTHROW(ks::step(model, ws, s, in, 0.01));
}
