// Any tethered fleet (kelp/system/fleet.hpp): the pair as a fleet is the pair bit for bit; a
// vehicle – tether – point mass – tether – vehicle chain keeps its momentum and, undamped, its
// energy; a TMS hanging on its umbilical with its tether below it settles where the elastic
// hanging line puts it; bad fleets are refused naming the part, bad states and inputs naming
// their index; a failed step changes nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "kelp/environment/environment.hpp"
#include "kelp/system/fleet.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/presets.hpp"

namespace ks = kelp::system;
namespace kt = kelp::tether;
namespace kv = kelp::vehicle;
using kelp::Vector3;
using kelp::Vector6;

namespace {

bool same(const void* a, const void* b, std::size_t n) { return std::memcmp(a, b, n) == 0; }
template <typename M>
bool same(const M& a, const M& b) {
  return a.size() == b.size() && same(a.data(), b.data(), sizeof(double) * std::size_t(a.size()));
}
bool same(const kv::VehicleStated& a, const kv::VehicleStated& b) {
  return same(a.position, b.position) && same(a.nu, b.nu) &&
         same(a.attitude.coeffs(), b.attitude.coeffs()) && a.time == b.time;
}
bool same(const kt::TetherStated& a, const kt::TetherStated& b) {
  return same(a.position, b.position) && same(a.velocity, b.velocity) &&
         same(a.previous_position, b.previous_position) &&
         same(a.previous_velocity, b.previous_velocity) && a.time == b.time &&
         a.time_carry == b.time_carry && a.winch_length == b.winch_length;
}

// The NED momentum of a vehicle: R (M_RB + φ M_A) ν, linear part.
Vector3<double> body_momentum(const kv::VehicleModeld& m, const kv::VehicleStated& x) {
  const Vector6<double> p =
      (m.rigid_body_mass() + m.submerged_fraction(x, 0.0) * m.added_mass()) * x.nu;
  return x.attitude * Vector3<double>(p.head<3>());
}

// Everything's momentum: vehicles, point masses ((m + C_a ρ V) v, submerged), tether nodes.
Vector3<double> momentum(const ks::FleetModeld& model, ks::FleetWorkspaced& ws,
                         const ks::FleetStated& s) {
  Vector3<double> total = Vector3<double>::Zero();
  for (int i = 0; i < model.vehicle_count(); ++i)
    total += body_momentum(model.vehicle(i), s.vehicles[std::size_t(i)]);
  const double rho = model.environment().water_density();
  for (int j = 0; j < model.point_mass_count(); ++j) {
    const auto& p = model.parameters().point_masses[std::size_t(j)];
    total += (p.mass + p.added_mass_coefficient * rho * p.volume) *
             s.point_masses[std::size_t(j)].velocity;
  }
  for (int k = 0; k < model.tether_count(); ++k) {
    auto& tw = ws.tethers[std::size_t(k)].tether;
    const auto& x = s.tethers[std::size_t(k)];
    kt::compute_forces(model.tether(k), tw, model.environment(), s.time, x.position, x.velocity);
    for (int i = 0; i < model.tether(k).nodes(); ++i) {
      const Vector3<double> q = tw.tangent.col(i), v = x.velocity.col(i);
      total += tw.mass_iso(i) * v + tw.mass_tan(i) * q.dot(v) * q;
    }
  }
  return total;
}

// The undamped chain: ROV – 8 m line – clump (neutrally buoyant) – 8 m line – ROV, 10 m down.
ks::FleetParametersd chain() {
  ks::FleetParametersd p;
  kv::VehicleParametersd rov = kv::bluerov2_heavy<double>().parameters;
  rov.damping = kv::DampingParameters<double>{};
  rov.displaced_volume = rov.mass / rov.density;  // neutral: it stays at its depth
  p.vehicles.push_back({"rov1", rov, {}, {}});
  p.vehicles.push_back({"rov2", rov, {}, {}});
  ks::PointMassParametersd clump;
  clump.name = "clump";
  clump.mass = 20.0;
  clump.volume = 20.0 / kelp::seawater_density;
  clump.drag_area = 0.0;
  p.point_masses.push_back(clump);
  kt::TetherParametersd line = kt::presets::rov_tether(8.0, 0.4);
  line.normal_drag = line.tangential_drag = 0;
  line.internal_damping = 0;
  line.mass_per_length = 0.07;
  const Vector3<double> top(0, 0, -0.15);
  p.tethers.push_back({"a",
                       line,
                       ks::TetherEnd<double>::on_vehicle(0, top),
                       ks::TetherEnd<double>::on_point_mass(0),
                       {}});
  p.tethers.push_back({"b",
                       line,
                       ks::TetherEnd<double>::on_point_mass(0),
                       ks::TetherEnd<double>::on_vehicle(1, top),
                       {}});
  return p;
}

ks::FleetStated chain_start(const ks::FleetModeld& model, ks::FleetWorkspaced& ws) {
  std::vector<kv::VehicleStated> v(2);
  v[0].position = Vector3<double>(0, 0, 10);
  v[1].position = Vector3<double>(12, 0, 10);
  return ks::initial_state(model, ws, v, {Vector3<double>(6, 0, 11)});
}

}  // namespace

TEST_CASE("the pair as a fleet is the pair, bit for bit", "[system][fleet]") {
  // The paper's pair with both vehicles' propulsion, a winch on the boat and both hulls, in the
  // rough sea; three seeds of random thruster and winch commands (paying out on the whole), 200
  // steps each.
  ks::SystemParametersd pair = ks::presets::paper_system(10.0);
  kt::WinchParametersd w;
  w.min_length = 6;
  w.max_length = 20;
  w.max_speed = 0.5;
  w.max_acceleration = 0.5;
  pair.winch = w;
  pair.asv_hull = ks::blueboat_hull<double>();
  pair.auv_hull = ks::bluerov2_heavy_hull<double>();
  pair.coupling_corrections = 1;
  const auto env = ks::presets::environment<double>(ks::presets::Sea::rough);
  const ks::SystemModeld pm(pair, env);
  const ks::FleetModeld fm(ks::fleet_of(pair), env);
  REQUIRE(fm.vehicle_index("auv") == 1);
  REQUIRE(fm.tether_index("tether") == 0);
  for (unsigned seed : {1u, 2u, 3u}) {
    ks::SystemWorkspaced pws(pm);
    ks::FleetWorkspaced fws(fm);
    const auto start = ks::presets::paper_start(10.0);
    ks::SystemStated ps = ks::initial_state(pm, pws, start.asv, start.auv);
    ks::FleetStated fs = ks::initial_state(fm, fws, {start.asv, start.auv});
    REQUIRE(same(ps.tether, fs.tethers[0]));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    ks::SystemInputsd pin;
    ks::FleetInputsd fin(fm);
    int compared = 0, remeshes = 0;
    for (int k = 0; k < 200; ++k) {
      pin.asv_commands.resize(2);
      pin.auv_commands.resize(8);
      for (int j = 0; j < 2; ++j) pin.asv_commands[j] = 0.5 * u(rng);
      for (int j = 0; j < 8; ++j) pin.auv_commands[j] = 0.3 * u(rng);
      pin.asv.tau_ext << u(rng), u(rng), 0, 0, 0, 0;
      pin.winch_payout_rate = 0.2 * u(rng) + 0.5;
      fin.commands[0] = pin.asv_commands;
      fin.commands[1] = pin.auv_commands;
      fin.vehicles[0] = pin.asv;
      fin.vehicles[1] = pin.auv;
      fin.winch_payout_rates[0] = pin.winch_payout_rate;
      const ks::SystemReportd pr = ks::step(pm, pws, ps, pin, 0.01, {true});
      const ks::FleetReportd& fr = ks::step(fm, fws, fs, fin, 0.01, {true});
      remeshes += pr.remesh.inserted + pr.remesh.removed;
      const bool equal = ps.time == fs.time && same(ps.asv, fs.vehicles[0]) &&
                         same(ps.auv, fs.vehicles[1]) && same(ps.tether, fs.tethers[0]) &&
                         same(ps.asv_nu_dot, fs.vehicle_nu_dot[0]) &&
                         same(ps.auv_nu_dot, fs.vehicle_nu_dot[1]) &&
                         same(pr.force_on_asv, fr.force_at_start[0]) &&
                         same(pr.force_on_auv, fr.force_at_end[0]) &&
                         same(ps.auv_propulsion.thrust, fs.propulsion[1].thrust) &&
                         pr.energy.total() == fr.energy.total() &&
                         pr.tether.newton_iterations == fr.tether.newton_iterations;
      INFO("seed " << seed << ", step " << k);
      REQUIRE(equal);
      ++compared;
    }
    CHECK(compared == 200);
    CHECK(remeshes > 0);  // the winch did re-mesh the line
  }
  // A bad propulsion state is refused naming the vehicle's index in the fleet's state (it named
  // the literal "state.propulsion[i]"), the state unchanged.
  ks::FleetWorkspaced fws(fm);
  const auto start = ks::presets::paper_start(10.0);
  ks::FleetStated fs = ks::initial_state(fm, fws, {start.asv, start.auv});
  fs.propulsion[1].thrust(3) = std::nan("");
  const ks::FleetStated before = fs;
  CHECK_THROWS_WITH(ks::step(fm, fws, fs, ks::FleetInputsd(fm), 0.01),
                    Catch::StartsWith("state.propulsion[1]") && !Catch::Contains("[i]"));
  CHECK(fs.time == before.time);
  CHECK(same(fs.vehicles[1], before.vehicles[1]));
  CHECK(same(fs.tethers[0], before.tethers[0]));
}

TEST_CASE("a vehicle - tether - point mass - tether - vehicle chain keeps its momentum",
          "[system][fleet][momentum]") {
  // No drag, damping, current or waves: only the tethers act horizontally. ROV 2 is sent away at
  // 1 m/s; both lines go taut and the clump and ROV 1 follow.
  const ks::FleetModeld model(chain(), kelp::environment::Environmentd{});
  ks::FleetWorkspaced ws(model);
  ks::FleetStated s = chain_start(model, ws);
  s.vehicles[1].nu(0) = 1.0;
  const Vector3<double> p0 = momentum(model, ws, s);
  const ks::FleetInputsd in(model);
  double worst = 0, f_max = 0, clump_speed = 0;
  for (int k = 0; k < 1500; ++k) {  // 15 s
    const auto& r = ks::step(model, ws, s, in, 0.01);
    f_max = std::max(f_max, r.force_at_start[0].norm());
    clump_speed = std::max(clump_speed, s.point_masses[0].velocity.x());
    worst = std::max(worst, (momentum(model, ws, s) - p0).head<2>().norm());
  }
  INFO("initial momentum " << p0.head<2>().norm() << " kg m/s, worst change " << worst
                           << ", peak force on ROV 1 " << f_max << " N, clump's top speed "
                           << clump_speed << " m/s");
  CHECK(f_max > 1.0);        // the far line pulled ROV 1 through the clump
  CHECK(clump_speed > 0.2);  // the clump was dragged along
  CHECK(worst <= 0.01 * p0.head<2>().norm());
}

TEST_CASE("the undamped chain keeps its energy with the corrector", "[system][fleet][energy]") {
  // As the pair's energy test: RK4 tethers in 0.2 ms sub-steps, one corrector pass; bound 1 %
  // of the kinetic energy given to ROV 2.
  ks::FleetParametersd p = chain();
  p.tether_integrator = kt::Integrator::rk4;
  p.max_tether_dt = 2e-4;
  p.coupling_corrections = 1;
  const ks::FleetModeld model(p, kelp::environment::Environmentd{});
  ks::FleetWorkspaced ws(model);
  ks::FleetStated s = chain_start(model, ws);
  s.vehicles[1].nu(0) = 1.0;
  ks::FleetEnergy<double> e = ws.report.energy;
  ks::energy(model, s, e);
  const double e0 = e.total();
  // An energy not sized for the fleet, or another fleet's state, is refused (not written past).
  ks::FleetEnergy<double> unsized;
  CHECK_THROWS_AS(ks::energy(model, s, unsized), kelp::invalid_argument);
  ks::FleetStated other = s;
  other.tethers.pop_back();
  CHECK_THROWS_AS(ks::energy(model, other, e), kelp::invalid_argument);
  const double kinetic0 =
      0.5 * s.vehicles[1].nu.dot(model.vehicle(1).mass_matrix() * s.vehicles[1].nu);
  const ks::FleetInputsd in(model);
  double worst = 0, f_max = 0;
  for (int k = 0; k < 1000; ++k) {  // 10 s
    const auto& r = ks::step(model, ws, s, in, 0.01, {true});
    f_max = std::max(f_max, r.force_at_end[1].norm());
    worst = std::max(worst, std::abs(r.energy.total() - e0));
  }
  INFO("E0 " << e0 << " J, kinetic " << kinetic0 << " J, worst |E - E0| " << worst
             << " J, peak force on ROV 2 " << f_max << " N");
  CHECK(f_max > 2.0);
  CHECK(worst <= 0.01 * kinetic0);
}

TEST_CASE("a TMS hanging on its umbilical with its tether below settles as the elastic line",
          "[system][fleet][static]") {
  // An anchor (the ship's sheave) 2 m down; a 30 m umbilical to a TMS (a 150 kg, 0.05 m³ point
  // mass); a 15 m tether hanging free below it. Vertical, still water: the tension along a
  // hanging elastic line grows linearly with the submerged weight below, so the TMS settles at
  // depth 2 + L1 + (T_P L1 + w1 L1²/2)/EA1 with T_P = W_TMS + w2 L2, and the anchor carries
  // T_P + w1 L1 (the lumped line is exact here: each segment's tension is the continuous line's
  // at its midpoint).
  ks::FleetParametersd p;
  kt::TetherParametersd umbilical = kt::presets::rov_tether(30.0, 2.0);
  umbilical.diameter = 0.02;
  umbilical.mass_per_length = 0.6;
  umbilical.axial_stiffness = 2e5;
  umbilical.internal_damping = 2e3;
  umbilical.breaking_strength = 0;  // an umbilical, not the ROV tether's 1.6 kN
  kt::TetherParametersd tether = kt::presets::rov_tether(15.0, 1.0);
  tether.diameter = 0.01;
  tether.mass_per_length = 0.15;
  tether.axial_stiffness = 5e4;
  tether.internal_damping = 500;
  tether.breaking_strength = 0;
  ks::PointMassParametersd tms;
  tms.name = "tms";
  tms.mass = 150;
  tms.volume = 0.05;
  tms.added_mass_coefficient = 0.5;
  tms.drag_area = 0.5;
  p.point_masses.push_back(tms);
  p.tethers.push_back({"umbilical",
                       umbilical,
                       ks::TetherEnd<double>::at_anchor({0, 0, 2}),
                       ks::TetherEnd<double>::on_point_mass(0),
                       {}});
  p.tethers.push_back({"tether",
                       tether,
                       ks::TetherEnd<double>::on_point_mass(0),
                       ks::TetherEnd<double>::hanging_free(),
                       {}});
  const ks::FleetModeld model(p, kelp::environment::Environmentd{});
  ks::FleetWorkspaced ws(model);
  ks::FleetStated s = ks::initial_state(model, ws, {}, {Vector3<double>(0, 0, 32)});
  const ks::FleetInputsd in(model);
  const ks::FleetReportd* r = nullptr;
  for (int k = 0; k < 3000; ++k) r = &ks::step(model, ws, s, in, 0.01);  // 30 s
  const double rho = model.environment().water_density(), g = model.environment().gravity();
  const double w1 = model.tether(0).submerged_weight_per_length(rho, g);
  const double w2 = model.tether(1).submerged_weight_per_length(rho, g);
  const double tp = (tms.mass - rho * tms.volume) * g + w2 * 15.0;
  const double depth = 2 + 30 + (tp * 30 + 0.5 * w1 * 30 * 30) / 2e5;
  const double top = tp + w1 * 30;
  INFO("TMS at " << s.point_masses[0].position.transpose() << " (expected depth " << depth
                 << "), speed " << s.point_masses[0].velocity.norm() << " m/s; anchor load "
                 << r->force_at_start[0].transpose() << " N (expected " << top << ")");
  CHECK(s.point_masses[0].velocity.norm() < 1e-4);
  CHECK(std::abs(s.point_masses[0].position.z() - depth) < 1e-4);
  CHECK(s.point_masses[0].position.head<2>().norm() < 1e-9);
  // The anchor's load: the line pulls it down (+z) with the whole submerged weight below it.
  CHECK(r->force_at_start[0].z() == Approx(top).epsilon(1e-4));
  // The free end's bottom hangs a tether's stretched length below the TMS.
  const auto& lower = s.tethers[1].position;
  const double stretch = 0.5 * w2 * 15 * 15 / 5e4;
  CHECK(lower(2, lower.cols() - 1) - s.point_masses[0].position.z() ==
        Approx(15 + stretch).epsilon(1e-6));
  CHECK(r->force_at_end[1].norm() == 0.0);  // nothing holds a free end
}

TEST_CASE("a fleet refuses parts that do not fit together, naming the part",
          "[system][fleet][bad_input]") {
  const auto env = kelp::environment::Environmentd{};
  ks::FleetParametersd p = chain();
  p.tethers[1].end.index = 5;
  CHECK_THROWS_WITH(ks::FleetModeld(p, env),
                    Catch::Contains("tethers[1] (b).end") && Catch::Contains("out of range"));
  p = chain();
  p.vehicles[1].name = "rov1";
  CHECK_THROWS_WITH(ks::FleetModeld(p, env), Catch::Contains("\"rov1\" is used twice"));
  p = chain();
  p.point_masses[0].mass = -1;
  CHECK_THROWS_WITH(ks::FleetModeld(p, env), Catch::Contains("point_mass.mass"));
  p = chain();
  p.tethers[0].start = ks::TetherEnd<double>::hanging_free();
  p.tethers[0].end = ks::TetherEnd<double>::hanging_free();
  CHECK_THROWS_WITH(ks::FleetModeld(p, env), Catch::Contains("at most one end"));
  p = chain();
  p.tethers[0].start = ks::TetherEnd<double>::hanging_free();
  p.tethers[0].winch = kt::WinchParametersd{};
  CHECK_THROWS_WITH(ks::FleetModeld(p, env), Catch::Contains("winch needs a start end"));
  auto fresh = env;
  fresh.set_water_density(1000.0);
  CHECK_THROWS_WITH(ks::FleetModeld(chain(), fresh), Catch::Contains("rov1"));
}

TEST_CASE("a fleet's bad state or input is named with its index", "[system][fleet][bad_input]") {
  ks::FleetParametersd p = chain();
  ks::PointMassParametersd buoy = p.point_masses[0];
  buoy.name = "buoy";  // a second point mass, on no tether
  p.point_masses.push_back(buoy);
  const ks::FleetModeld model(p, kelp::environment::Environmentd{});
  ks::FleetWorkspaced ws(model);
  std::vector<kv::VehicleStated> v(2);
  v[0].position = Vector3<double>(0, 0, 10);
  v[1].position = Vector3<double>(12, 0, 10);
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  const Vector3<double> clump(6, 0, 11);
  CHECK_THROWS_WITH(ks::initial_state(model, ws, v, {clump, Vector3<double>(3, nan, 5)}),
                    Catch::Contains("point_masses[1] must be finite"));
  const ks::FleetStated good = ks::initial_state(model, ws, v, {clump, Vector3<double>(3, 3, 5)});
  const ks::FleetInputsd no_input(model);
  // Each bad part of the state or the inputs in turn, the rest as given.
  const auto refused = [&](const ks::FleetStated& s, const ks::FleetInputsd& in) {
    ks::FleetStated x = s;
    try {
      ks::step(model, ws, x, in, 0.01);
    } catch (const kelp::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  ks::FleetStated s = good;
  s.point_masses[1].position.z() = nan;
  CHECK_THAT(refused(s, no_input), Catch::Contains("state.point_masses[1].position"));
  s = good;
  s.point_masses[1].velocity.x() = inf;
  CHECK_THAT(refused(s, no_input), Catch::Contains("state.point_masses[1].velocity"));
  s = good;
  s.point_mass_acceleration[1].y() = nan;
  CHECK_THAT(refused(s, no_input), Catch::Contains("state.point_mass_acceleration[1]"));
  s = good;
  s.vehicle_nu_dot[1](3) = nan;
  CHECK_THAT(refused(s, no_input), Catch::Contains("state.vehicle_nu_dot[1]"));
  s = good;
  s.vehicles[1].time += 1.0;
  CHECK_THAT(refused(s, no_input), Catch::Contains("state.vehicles[1].time"));
  s = good;
  s.tethers[1].time += 1.0;
  CHECK_THAT(refused(s, no_input), Catch::Contains("state.tethers[1].time"));
  s = good;
  s.tethers[1].payout_rate = nan;
  CHECK_THAT(refused(s, no_input),
             Catch::StartsWith("state.tethers[1]: state.payout_rate must be finite"));
  // A winch length the tether's step refuses (not finite, negative, or under 1 % of a segment):
  // refused there, with the tether named (its message named no tether). Tether 0 was stepped
  // before tether 1 refused: the whole state is restored.
  s = good;
  for (const double w : {-inf, nan, -1.0, 1e-6}) {
    INFO("winch_length " << w);
    s.tethers[1].winch_length = w;
    CHECK_THAT(refused(s, no_input), Catch::StartsWith("state.tethers[1]: state.winch_length must "
                                                       "be 0 (no winch) or in [0.01 l"));
    ks::FleetStated x = s;
    CHECK_THROWS_AS(ks::step(model, ws, x, no_input, 0.01), kelp::invalid_argument);
    CHECK(x.time == s.time);
    CHECK(same(x.tethers[0], s.tethers[0]));
    CHECK(same(x.vehicles[0], s.vehicles[0]));
    CHECK(same(x.point_masses[0].position, s.point_masses[0].position));
  }
  ks::FleetInputsd in = no_input;
  in.vehicles[1].tau(0) = nan;
  CHECK_THAT(refused(good, in), Catch::Contains("inputs.vehicles[1].tau must"));
  in = no_input;
  in.vehicles[1].tau_ext(5) = inf;
  CHECK_THAT(refused(good, in), Catch::Contains("inputs.vehicles[1].tau_ext"));
  in = no_input;
  in.winch_payout_rates[1] = nan;
  CHECK_THAT(refused(good, in), Catch::Contains("inputs.winch_payout_rates[1] must be finite"));
  in.winch_payout_rates[1] = 0.1;
  CHECK_THAT(refused(good, in), Catch::Contains("inputs.winch_payout_rates[1] must be 0"));
  CHECK(refused(good, no_input) == "(accepted)");
}

TEST_CASE("a failed fleet step throws and leaves every part of the state bit-identical",
          "[system][fleet][bad_input]") {
  const ks::FleetModeld model(chain(), kelp::environment::Environmentd{});
  ks::FleetWorkspaced ws(model);
  ks::FleetStated s = chain_start(model, ws);
  ks::FleetInputsd in(model);
  for (int k = 0; k < 10; ++k) ks::step(model, ws, s, in, 0.01);
  const ks::FleetStated before = s;
  const auto unchanged = [&] {
    bool ok = s.time == before.time;
    for (std::size_t i = 0; i < 2; ++i)
      ok = ok && same(s.vehicles[i], before.vehicles[i]) &&
           same(s.vehicle_nu_dot[i], before.vehicle_nu_dot[i]) &&
           same(s.tethers[i], before.tethers[i]);
    return ok && same(s.point_masses[0].position, before.point_masses[0].position) &&
           same(s.point_masses[0].velocity, before.point_masses[0].velocity);
  };
  // Bad input: a NaN wrench, the wrong input size, a stale clock.
  in.vehicles[1].tau(2) = std::nan("");
  CHECK_THROWS_AS(ks::step(model, ws, s, in, 0.01), kelp::invalid_argument);
  CHECK(unchanged());
  in = ks::FleetInputsd(model);
  in.winch_payout_rates.pop_back();
  CHECK_THROWS_WITH(ks::step(model, ws, s, in, 0.01), Catch::Contains("sized for the fleet"));
  CHECK(unchanged());
  // A numerical failure half-way: the second line parts nothing but its clump is given a NaN
  // drag area through an absurd speed: make the clump's state blow up inside the step by
  // sending it at 1e200 m/s (finite input, non-finite result).
  in = ks::FleetInputsd(model);
  ks::FleetStated fast = s;
  fast.point_masses[0].velocity.x() = 1e200;
  const ks::FleetStated fast_before = fast;
  CHECK_THROWS_AS(ks::step(model, ws, fast, in, 0.01), kelp::error);
  CHECK(same(fast.vehicles[0], fast_before.vehicles[0]));
  CHECK(same(fast.tethers[0], fast_before.tethers[0]));
  CHECK(same(fast.point_masses[0].velocity, fast_before.point_masses[0].velocity));
  // And the step still works afterwards.
  CHECK_NOTHROW(ks::step(model, ws, s, in, 0.01));
}
