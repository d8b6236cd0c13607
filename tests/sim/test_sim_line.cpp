// kelp::sim's tether events: the turn counter (TurnCounter: the ROV's yaw relative to the tether
// at its attachment) counts N turns of a ROV spinning N times on the spot and about none when it
// does not spin; a line with a low breaking strength parts in a run, which goes on and reports
// the parting in summary.json and events.csv; the default (Fathom, 1557 N) line does not part.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "kelp/sim.hpp"
#include "kelp/system/presets.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;
namespace sp = kelp::system::presets;

namespace {

// The tether's last two nodes along +x from the attachment at the origin (the tether leaving the
// ROV towards the north), and a ROV heading psi.
struct Synthetic {
  kelp::tether::TetherStated tether;
  kelp::vehicle::VehicleStated rov;
  Synthetic() {
    tether.position = kelp::Matrix3X<double>::Zero(3, 3);
    tether.position.col(0) << 2, 0, 0;
    tether.position.col(1) << 1, 0, 0;
  }
  void heading(double psi) {
    rov.attitude = Eigen::Quaterniond(Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()));
  }
};

using kelp_test::short_calm_run;

}  // namespace

TEST_CASE("turn counter: N turns of the heading against a fixed tether are N turns",
          "[sim][turns]") {
  for (int sign : {1, -1})
    for (int n : {1, 3}) {
      Synthetic s;
      ks::TurnCounter c;
      const int per_turn = 100;
      for (int k = 0; k <= n * per_turn; ++k) {
        s.heading(sign * 2.0 * kelp::pi * k / per_turn);
        c.update(s.rov, s.tether, 2);
      }
      CHECK(c.turns() == Approx(sign * n).margin(1e-9));
      CHECK(c.max_abs_turns() == Approx(n).margin(1e-9));
    }
  // The tether turning with the ROV (an ROV circling its own tether's end with the same heading
  // relative to it) is no turn; the tether's azimuth turning under a fixed heading is −1 turn.
  // (Over the attachment's own segment: reference length 0.)
  Synthetic s;
  ks::TurnCounter with(0.0), under(0.0);
  for (int k = 0; k <= 100; ++k) {
    const double a = 2.0 * kelp::pi * k / 100;
    s.tether.position.col(1) << std::cos(a), std::sin(a), 0;
    s.heading(a);
    with.update(s.rov, s.tether, 2);
    s.heading(0.0);
    under.update(s.rov, s.tether, 2);
  }
  CHECK(with.turns() == Approx(0.0).margin(1e-9));
  CHECK(under.turns() == Approx(-1.0).margin(1e-9));
  // A vertical tether at the attachment: its azimuth is held, the ROV's own yaw counts.
  Synthetic v;
  v.tether.position.col(1) << 0, 0, -1;
  ks::TurnCounter vertical;
  for (int k = 0; k <= 200; ++k) {
    v.heading(2.0 * kelp::pi * k / 100);
    vertical.update(v.rov, v.tether, 2);
  }
  CHECK(vertical.turns() == Approx(2.0).margin(1e-9));
}

TEST_CASE("turn counter: a ROV spinning on the spot 3 times makes 3 turns; at rest, none",
          "[sim][turns]") {
  sp::PaperWorld<double> w(10.0, sp::Sea::calm);
  ks::TurnCounter spun, rest;
  kelp::system::SystemInputsd in;
  const int last = int(w.state.tether.position.cols()) - 1;
  spun.update(w.state.auv, w.state.tether, last);
  // Its own heading, unwrapped, to stop after exactly three turns.
  double heading = 0.0, prev = 0.0;
  const double target_rate = 2.0 * kelp::pi / 8.0;  // a turn in 8 s
  for (int k = 0; k < 10000 && heading < 3.0 * 2.0 * kelp::pi; ++k) {
    // Yaw torque from a proportional yaw-rate loop, nothing else.
    in.auv.tau.setZero();
    in.auv.tau(5) = 40.0 * (target_rate - w.state.auv.nu(5));
    (void)kelp::system::step(w.model, w.workspace, w.state, in, 0.01);
    const Eigen::Matrix3d r = w.state.auv.rotation();
    const double psi = std::atan2(r(1, 0), r(0, 0));
    heading += std::remainder(psi - prev, 2.0 * kelp::pi);
    prev = psi;
    spun.update(w.state.auv, w.state.tether, last);
  }
  INFO("turns " << spun.turns() << ", heading " << heading / (2.0 * kelp::pi) << " turns");
  CHECK(spun.turns() == Approx(3.0).margin(0.1));
  CHECK(spun.max_abs_turns() >= spun.turns());

  sp::PaperWorld<double> still(10.0, sp::Sea::calm);
  kelp::system::SystemInputsd none;
  rest.update(still.state.auv, still.state.tether, last);
  for (int k = 0; k < 2000; ++k) {
    (void)kelp::system::step(still.model, still.workspace, still.state, none, 0.01);
    rest.update(still.state.auv, still.state.tether, last);
  }
  INFO("at rest: " << rest.turns() << " turns, at most " << rest.max_abs_turns());
  CHECK(std::abs(rest.turns()) < 0.02);
  CHECK(rest.max_abs_turns() < 0.05);
}

TEST_CASE("a line with a low breaking strength parts in a run, which reports it",
          "[sim][failure]") {
  const std::filesystem::path dir = "sim_line_failure_run";
  std::filesystem::remove_all(dir);
  ks::Scenario sc = short_calm_run();
  sc.breaking_strength = 1.0;  // [N], below the line's working tension (up to ~2 N here)
  ks::SimulateOptions o;
  o.log_dir = dir.string();
  nlohmann::json s;
  REQUIRE_NOTHROW(s = kelp_test::json_of(ks::simulate(sc, o)));
  INFO(s["tether"].dump());
  const auto& failures = s["tether"]["line_failures"];
  REQUIRE(failures.is_array());
  REQUIRE(failures.size() >= 1);
  CHECK(failures[0]["time_s"].get<double>() > 0.0);
  CHECK(failures[0]["tension_n"].get<double>() > 1.0);
  const int seg = failures[0]["segment"].get<int>();
  CHECK(seg >= 0);
  CHECK(seg < 10);
  CHECK(s["tether"].contains("net_turns"));
  CHECK(s["scenario"]["tether"]["breaking_strength"].get<double>() == 1.0);
  // events.csv: its header and one row per parting; timeseries.csv: the new columns.
  std::ifstream ev(dir / "events.csv");
  std::string header, row;
  std::getline(ev, header);
  CHECK(header == "t,event,segment,x,y,z,tension,obstacle,winding");
  REQUIRE(std::getline(ev, row));
  CHECK(row.find(",line_parted," + std::to_string(seg) + ",") != std::string::npos);
  std::ifstream ts(dir / "timeseries.csv");
  std::getline(ts, header);
  CHECK(header.find(",tether_turns,tether_parted_segments") != std::string::npos);

  // The default line (the Fathom tether's 1557 N) holds.
  const nlohmann::json d = kelp_test::json_of(ks::simulate(short_calm_run()));
  CHECK(d["tether"]["line_failures"].empty());
  CHECK(std::abs(d["tether"]["net_turns"].get<double>()) < 1.0);
}

TEST_CASE("system::step reports a parting once, with coupling corrections, and restores it",
          "[sim][failure]") {
  // The paper's system with a 1 N line and one corrector pass: the step that parts the line
  // reports it once (the pass that is undone does not count), the state keeps one parted
  // segment, and later steps report none.
  auto params = sp::paper_system(10.0, sp::TetherKind::rov_tether);
  params.tether.breaking_strength = 1.0;
  params.coupling_corrections = 1;
  const kelp::system::SystemModeld model(params, sp::environment<double>(sp::Sea::calm));
  kelp::system::SystemWorkspaced ws(model);
  const auto start = sp::paper_start(10.0);
  kelp::system::SystemStated s = kelp::system::initial_state(model, ws, start.asv, start.auv);
  kelp::system::SystemInputsd in;
  in.auv.tau(0) = -30.0;  // the ROV pulls away from the boat
  int partings = 0, first = -1;
  for (int k = 0; k < 500; ++k) {
    const auto r = kelp::system::step(model, ws, s, in, 0.01);
    if (r.tether.partings > 0 && first < 0) first = k;
    partings += r.tether.partings;
    CHECK(s.tether.parted_segments() == partings);
  }
  INFO("first parting at step " << first);
  CHECK(first >= 0);
  CHECK(partings >= 1);
  CHECK(s.tether.position.allFinite());
}

// The scenario's "internal_damping_ratio" (MoorDyn's BA/-zeta) replaces the kind's BA with
// ratio * segment length * sqrt(EA * mass_per_length); with "internal_damping" too, it is refused.
TEST_CASE("scenario: the tether's internal damping as a damping ratio", "[sim][scenario]") {
  const ks::Scenario sc = ks::parse_scenario(
      R"({"tether": {"length": 10, "segment_length": 0.5, "internal_damping_ratio": 0.8}})",
      "ratio.json");
  REQUIRE(sc.internal_damping_ratio);
  const ks::WorldSetup w = ks::world_setup(sc, "ratio.json");
  const kelp::tether::TetherModeld m(w.parameters.tether);
  const auto& p = m.parameters();
  CHECK(p.internal_damping ==
        Approx(0.8 * m.segment_length() * std::sqrt(p.axial_stiffness * p.mass_per_length))
            .epsilon(1e-12));
  // The rov_tether's 100 N s is 34.8 times critical at 0.25 m segments, 17.4 at 0.5 m.
  CHECK(p.internal_damping < 5.0);
  // Written back, read the same.
  CHECK(ks::parse_scenario(ks::scenario_json(sc), "again.json").internal_damping_ratio == 0.8);
  const ks::Scenario both = ks::parse_scenario(
      R"({"tether": {"internal_damping": 50, "internal_damping_ratio": 0.8}})", "both.json");
  REQUIRE_THROWS_AS(ks::world_setup(both, "both.json"), kelp::invalid_argument);
}
