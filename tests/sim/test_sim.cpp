// kelp::sim: the closed loop stepped by hand gives simulate()'s run bit for bit, it samples and
// logs at the scenario's rates, it refuses to step past its end and bad scenarios with errors
// derived from kelp::error, the tether's line model travels from the file to the tether, and a
// step allocates nothing.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "../support/heap_counter.hpp"
#include "kelp/sim.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;

namespace {

using kelp_test::short_calm_run;

// The summary without what depends on the wall clock.
nlohmann::json deterministic(nlohmann::json s) {
  s.erase("wall_s");
  s.erase("realtime_factor");
  return s;
}

std::size_t lines_of(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

}  // namespace

TEST_CASE("a ClosedLoop stepped by hand runs what simulate() runs, bit for bit", "[sim]") {
  const ks::Scenario sc = short_calm_run();
  const nlohmann::json reference = deterministic(kelp_test::json_of(ks::simulate(sc)));

  ks::ClosedLoop loop(sc);
  CHECK(loop.total_steps() == 500);
  while (!loop.done()) loop.step();
  CHECK(kelp_test::json_of(loop.summary()) == reference);

  // In chunks of simulated time: the same run.
  ks::ClosedLoop chunked(sc);
  CHECK(chunked.run_for(1.234) == 123);
  CHECK(chunked.run_for(100.0) == 377);  // up to the end, not beyond
  CHECK(chunked.done());
  CHECK(kelp_test::json_of(chunked.summary()) == reference);
  CHECK(chunked.state().time == loop.state().time);
  CHECK(chunked.state().auv.position == loop.state().auv.position);
}

TEST_CASE("the closed loop samples at the log rate and flies the survey", "[sim]") {
  const ks::Scenario sc = short_calm_run();
  ks::ClosedLoop loop(sc);
  const double d0 = (loop.state().auv.position - loop.waypoints().front()).norm();
  loop.run();
  // 5 s at 5 Hz: samples at 0.2, 0.4, ..., 5 s (the one at t = 0 is logged, not accumulated).
  CHECK(loop.metrics().samples == 25);
  CHECK(loop.sample().t == loop.time());
  CHECK(std::abs(loop.time() - 5.0) < 1e-9);
  // The default survey's first corner is a side of the square (8 m) ahead of the ROV's start; it
  // heads there.
  const double d1 = (loop.state().auv.position - loop.waypoints().front()).norm();
  CHECK(d0 == Approx(sc.square_side).margin(0.01));
  CHECK(sc.square_side == 8.0);
  CHECK(d1 < d0 - 1.0);
  CHECK(loop.metrics().max_tension > 0.0);
  CHECK(std::isfinite(kelp_test::json_of(loop.summary())["energy_j"].get<double>()));
}

TEST_CASE("a ClosedLoop with a RunLog writes a row per sample and a snapshot per node tick",
          "[sim]") {
  const ks::Scenario sc = short_calm_run();
  const std::filesystem::path dir = std::filesystem::current_path() / "test_sim_log";
  std::filesystem::remove_all(dir);
  std::size_t nodes = 0;
  {
    ks::RunLog log(dir);
    ks::ClosedLoopOptions o;
    o.log = &log;
    ks::ClosedLoop loop(sc, o);
    nodes = static_cast<std::size_t>(loop.state().tether.position.cols());
    loop.run();
  }
  CHECK(lines_of(dir / "timeseries.csv") == 1 + 26);     // header, t = 0, 0.2, ..., 5 s
  CHECK(lines_of(dir / "nodes.csv") == 1 + 11 * nodes);  // header, t = 0, 0.5, ..., 5 s
  CHECK(nodes == 11);                                    // 10 m in 1 m segments
}

TEST_CASE("the closed loop refuses a step past its end and counts its steps", "[sim]") {
  ks::Scenario sc = short_calm_run();
  sc.duration = 0.05;
  ks::ClosedLoop loop(sc);
  loop.run();
  CHECK(loop.steps_taken() == 5);
  const double t = loop.time();
  CHECK_THROWS_AS(loop.step(), kelp::error);
  CHECK(loop.time() == t);
  CHECK_THROWS_AS(loop.run_for(-1.0), kelp::invalid_argument);
}

TEST_CASE("the closed loop counts the tether solver's work of every step and reports it",
          "[sim][solver_stats]") {
  ks::Scenario sc = short_calm_run();
  sc.duration = 0.5;
  ks::ClosedLoop loop(sc);
  // Every step's report, summed here by hand beside the loop's own statistics.
  long newton = 0, substeps = 0, evaluations = 0;
  int most = 0;
  while (!loop.done()) {
    const kelp::system::SystemReportd& r = loop.step();
    newton += r.tether.newton_iterations;
    substeps += r.tether.substeps;
    evaluations += r.tether.force_evaluations;
    most = std::max(most, r.tether.newton_iterations);
  }
  const kelp::system::SolverStatsd& st = loop.solver_stats();
  CHECK(st.steps == 50);
  CHECK(st.tether_steps == substeps);
  CHECK(st.tether_steps >= 50);  // 10 ms steps of at most 10 ms tether steps
  CHECK(st.newton_iterations == newton);
  CHECK(st.newton_iterations >= st.tether_steps);  // BDF2 makes at least one correction a step
  CHECK(st.max_step_newton_iterations == most);
  CHECK(st.force_evaluations == evaluations);
  CHECK(st.explicit_fallbacks == 0);
  CHECK(st.mean_step_newton_iterations() == Approx(newton / 50.0));
  const nlohmann::json j = kelp_test::json_of(loop.summary())["tether_solver"];
  INFO(j.dump());
  CHECK(j["steps"] == 50);
  CHECK(j["integrator"] == "bdf2");
  CHECK(j["newton_iterations"] == newton);
  CHECK(j["newton_iterations_per_step_max"] == most);
  CHECK(j["explicit_fallbacks"] == 0);
  CHECK(j["explicit_fallback"] == false);
  CHECK(j["worst_residual_m_s"].get<double>() <= j["residual_tolerance_m_s"].get<double>());
}

TEST_CASE("a scenario's tether.explicit_fallback is off unless set, and reaches the system",
          "[sim][solver_stats]") {
  CHECK_FALSE(ks::Scenario{}.explicit_fallback);
  CHECK_FALSE(ks::world_setup(ks::Scenario{}, "default").parameters.explicit_fallback);
  const ks::Scenario on =
      ks::parse_scenario(R"({"tether": {"explicit_fallback": true}})", "on.json");
  CHECK(on.explicit_fallback);
  CHECK(ks::world_setup(on, "on.json").parameters.explicit_fallback);
  // The summary's echo reads back to the same setting.
  CHECK(ks::parse_scenario(kelp_test::json_of(on).dump(), "echo").explicit_fallback);
  CHECK_FALSE(
      ks::parse_scenario(kelp_test::json_of(ks::Scenario{}).dump(), "echo").explicit_fallback);
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"tether": {"explicit_fallback": 1}})", "bad.json"),
                    Catch::Contains("/tether/explicit_fallback"));
}

TEST_CASE("bad scenarios throw scenario_error, a kelp::invalid_argument naming the path", "[sim]") {
  try {
    (void)ks::parse_scenario(R"({"tether": {"length": -3}})", "bad.json");
    FAIL("a negative tether length was accepted");
  } catch (const kelp::invalid_argument& e) {
    CHECK(dynamic_cast<const ks::scenario_error*>(&e) != nullptr);
    CHECK(std::string(e.what()).rfind("bad.json: /tether/length: ", 0) == 0);
  }
  CHECK_THROWS_AS(ks::load_scenario("/nonexistent/scenario.json"), ks::scenario_error);
  // A tether shorter than the distance between its ends at the start: refused by the world.
  ks::Scenario sc = short_calm_run();
  sc.auv_start =
      kelp::Vector3<double>(30.0, 0.0, 5.0);  // some 30 m from the boat, on a 10 m tether
  CHECK_THROWS_AS(ks::ClosedLoop(sc), ks::scenario_error);
}

TEST_CASE("the tether's line_model: parsed, written back, passed to the tether, checked", "[sim]") {
  // Default: kelp's line, and to_json leaves the key out.
  const ks::Scenario plain = ks::parse_scenario(R"({"tether": {"length": 10}})", "a.json");
  CHECK(plain.line_model == kelp::tether::LineModel::kelp);
  CHECK_FALSE(kelp_test::json_of(plain).at("tether").contains("line_model"));
  CHECK(ks::world_setup(plain, "a.json").parameters.tether.line_model ==
        kelp::tether::LineModel::kelp);
  // "moordyn": parsed, round-tripped through to_json, and reaching the tether's parameters.
  const ks::Scenario md =
      ks::parse_scenario(R"({"tether": {"length": 10, "line_model": "moordyn"}})", "b.json");
  CHECK(md.line_model == kelp::tether::LineModel::moordyn);
  CHECK(ks::parse_scenario(kelp_test::json_of(md).dump(), "c.json").line_model ==
        kelp::tether::LineModel::moordyn);
  CHECK(ks::world_setup(md, "b.json").parameters.tether.line_model ==
        kelp::tether::LineModel::moordyn);
  // Anything else is refused with the path, in the file and in a Scenario built by hand (a value
  // cast from an integer).
  try {
    (void)ks::parse_scenario(R"({"tether": {"line_model": "MoorDyn"}})", "d.json");
    FAIL("line_model \"MoorDyn\" was accepted");
  } catch (const ks::scenario_error& e) {
    CHECK(std::string(e.what()).rfind("d.json: /tether/line_model: ", 0) == 0);
  }
  CHECK_THROWS_AS(ks::parse_scenario(R"({"tether": {"line_model": 1}})", "e.json"),
                  ks::scenario_error);
  ks::Scenario bad = plain;
  bad.line_model = static_cast<kelp::tether::LineModel>(7);
  CHECK_THROWS_AS(ks::world_setup(bad, "f.json"), ks::scenario_error);
}

TEST_CASE("a custom sea's regular wave and stretching: parsed, written back, in the sea",
          "[sim][regular]") {
  // A regular wave alone (no significant_height): H 1.2 m, T 6 s, travelling east.
  const ks::Scenario sc = ks::parse_scenario(
      R"({"sea": {"regular": {"height": 1.2, "period": 6, "direction": 1.5707963267948966,
          "phase": 0.25}, "stretching": "wheeler"}})",
      "r.json");
  CHECK(sc.sea == ks::Sea::custom);
  CHECK(sc.regular_wave.enabled);
  CHECK(sc.regular_wave.height == 1.2);
  CHECK(sc.regular_wave.period == 6.0);
  CHECK_FALSE(sc.regular_wave.wavelength.has_value());
  CHECK(sc.wave_stretching == kelp::environment::WaveStretching::wheeler);
  const ks::WorldSetup w = ks::world_setup(sc, "r.json");
  const auto& waves = w.environment.waves();
  REQUIRE(waves.size() == 1);
  CHECK(waves.amplitude(0) == 0.6);
  CHECK(waves.omega(0) == Approx(2.0 * kelp::pi / 6.0));
  CHECK(waves.parameters().stretching == kelp::environment::WaveStretching::wheeler);
  // ζ at a probe 10 m east: A cos(k y − ω t + φ), deep water (the wave field's: the environment
  // brings it in over the scenario's start ramp).
  const double omega = 2.0 * kelp::pi / 6.0, k = omega * omega / kelp::standard_gravity;
  for (const double t : {0.0, 1.0, 2.5})
    CHECK(waves.elevation(0.0, 10.0, t) ==
          Approx(0.6 * std::cos(k * 10.0 - omega * t + 0.25)).margin(1e-9));
  // Written back (the summary's echo) and read again to the same wave.
  const std::string echo = kelp_test::json_of(sc).dump();
  INFO(echo);
  const ks::Scenario again = ks::parse_scenario(echo, "echo");
  CHECK(again.regular_wave.enabled);
  CHECK(again.regular_wave.height == 1.2);
  CHECK(again.regular_wave.period == 6.0);
  CHECK(again.regular_wave.phase == 0.25);
  CHECK(again.wave_stretching == kelp::environment::WaveStretching::wheeler);
  // Not written when absent; by wavelength on top of a JONSWAP sea.
  const ks::Scenario plain = ks::parse_scenario(R"({"sea": {"significant_height": 1}})", "p.json");
  CHECK_FALSE(plain.regular_wave.enabled);
  CHECK_FALSE(kelp_test::json_of(plain).at("sea").contains("regular"));
  CHECK_FALSE(kelp_test::json_of(plain).at("sea").contains("stretching"));
  const ks::Scenario both = ks::parse_scenario(
      R"({"sea": {"significant_height": 1, "regular": {"height": 0.5, "wavelength": 40}}})",
      "b.json");
  CHECK(ks::world_setup(both, "b.json").environment.waves().size() == 65);
}

TEST_CASE("bad regular waves are refused naming the JSON path", "[sim][regular][bad_input]") {
  const auto refused = [](const char* text, const char* path) {
    INFO(text);
    try {
      const ks::Scenario sc = ks::parse_scenario(text, "bad.json");
      (void)ks::world_setup(sc, "bad.json");
      FAIL("accepted");
    } catch (const ks::scenario_error& e) {
      CHECK_THAT(e.what(), Catch::StartsWith(std::string("bad.json: ") + path));
    }
  };
  refused(R"({"sea": {"regular": {"height": -1, "period": 6}}})", "/sea/regular/height");
  refused(R"({"sea": {"regular": {"period": 6}}})", "/sea/regular");  // no height
  refused(R"({"sea": {"regular": {"height": 1, "period": 6, "wavelength": 50}}})",
          "/sea/regular: expected \"period\" or \"wavelength\"");
  refused(R"({"sea": {"regular": {"height": 1}}})", "/sea/regular: expected");
  refused(R"({"sea": {"regular": {"height": 1, "period": 0}}})", "/sea/regular/period");
  refused(R"({"sea": {"regular": {"height": 1, "wavelength": -3}}})", "/sea/regular/wavelength");
  refused(R"({"sea": {"regular": {"height": 1, "period": 6, "colour": 1}}})",
          "/sea/regular/colour");
  refused(R"({"sea": {"regular": {"height": 1, "period": "6"}}})", "/sea/regular/period");
  // Steeper than the breaking limit (λ = 25 m): the environment's check, named by the world.
  refused(R"({"sea": {"regular": {"height": 4, "wavelength": 25}}})",
          "/sea/regular: regular.height must be at most the breaking limit");
  refused(R"({"sea": {"stretching": "delta"}})", "/sea/stretching");
  ks::Scenario cast;
  cast.sea = ks::Sea::custom;
  cast.wave_stretching = static_cast<kelp::environment::WaveStretching>(9);
  CHECK_THROWS_AS(ks::world_setup(cast, "f.json"), ks::scenario_error);
}

TEST_CASE("a closed-loop step allocates nothing", "[sim][malloc]") {
  ks::ClosedLoop loop(short_calm_run());
  loop.run_for(0.1);  // past the first controller updates
  // Counted in the whole program: the library's code is compiled without Eigen's malloc check.
  const long before = kelp_test::heap_allocations();
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 100; ++k) loop.step();
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(kelp_test::heap_allocations() == before);
  CHECK(loop.steps_taken() == 110);
}
