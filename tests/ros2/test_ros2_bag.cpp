// A run's ROS 2 bag through kelp::sim::run_scenario: run.mcap beside the CSV log, and
// reference.csv, the same samples in kelp's own frames (NED/FRD) at full precision (%.17g), for
// the independent check of the bag (tests/ros2/node/check_bags.mjs, with @mcap/core and
// @foxglove/rosmsg2-serialization) which converts them to ROS's frames itself; a bad marker rate
// (or, for a run's bag, a row that lacks what the messages need) refused before any file or
// directory is created.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "../sim/sim_test_support.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/run.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/vehicle/state.hpp"

namespace {
void put(std::FILE* f, double v) { std::fprintf(f, ",%.17g", v); }
}  // namespace

TEST_CASE("run_scenario writes run.mcap beside the log; reference.csv for the npm check",
          "[ros2][sim]") {
  kelp::sim::Scenario sc;
  sc.duration = 6.0;
  sc.segment_length = 1.0;  // a coarse tether: a quick test
  sc.log_rate = 10.0;
  sc.node_rate = 2.0;
  sc.sea = kelp::sim::Sea::moderate;  // waves: the vehicles move, the tether pulls
  const std::filesystem::path dir = "ros2_bag_run";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::FILE* ref = std::fopen((dir / "reference.csv").c_str(), "w");
  REQUIRE(ref);
  std::fprintf(ref, "t");
  for (const char* v : {"boat", "rov"})
    for (const char* c : {"n", "e", "d", "qw", "qx", "qy", "qz", "u", "v", "w", "p", "q", "r",
                          "end_n", "end_e", "end_d", "fn", "fe", "fd"})
      std::fprintf(ref, ",%s_%s", v, c);
  for (const char* c : {"du", "dv", "dw", "dp", "dq", "dr"}) std::fprintf(ref, ",rov_nu_dot_%s", c);
  std::fprintf(ref, ",gravity\n");
  long samples = 0;
  // The same samples in a second bag of small chunks (many chunks, each indexed).
  const std::filesystem::path chunked = "ros2_bag_chunks";
  std::filesystem::remove_all(chunked);
  std::filesystem::create_directories(chunked);
  kelp::ros2::McapOptions small;
  small.chunk_size = 8192;
  kelp::sim::BagRecorder second(chunked / "run.mcap", sc.node_rate, small);
  kelp::sim::RunOptions o;
  o.out = dir.string();
  o.on_sample = [&](const kelp::sim::LogRow& r) {
    ++samples;
    second.record(r);
    std::fprintf(ref, "%.17g", r.t);
    const auto& p = r.tether->position;
    const kelp::vehicle::VehicleStated* x[2] = {r.asv, r.auv};
    const kelp::Vector3<double> end[2] = {p.col(0), p.col(p.cols() - 1)};
    const kelp::Vector3<double> force[2] = {r.force_on_asv, r.force_on_auv};
    for (int k = 0; k < 2; ++k) {
      for (int i = 0; i < 3; ++i) put(ref, x[k]->position(i));
      put(ref, x[k]->attitude.w());
      put(ref, x[k]->attitude.x());
      put(ref, x[k]->attitude.y());
      put(ref, x[k]->attitude.z());
      for (int i = 0; i < 6; ++i) put(ref, x[k]->nu(i));
      for (int i = 0; i < 3; ++i) put(ref, end[k](i));
      for (int i = 0; i < 3; ++i) put(ref, force[k](i));
    }
    for (int i = 0; i < 6; ++i) put(ref, r.auv_nu_dot(i));
    put(ref, r.gravity);
    std::fprintf(ref, "\n");
    // What the bag needs is there.
    CHECK(r.force_on_auv.allFinite());
    CHECK(r.auv_nu_dot.allFinite());
  };
  kelp::sim::run_scenario(sc, o);
  std::fclose(ref);
  second.close();
  std::filesystem::copy_file(dir / "reference.csv", chunked / "reference.csv");
  CHECK(second.bag().mcap().bytes_written() > 10000);
  CHECK(samples == 61);
  REQUIRE(std::filesystem::exists(dir / "run.mcap"));
  CHECK(std::filesystem::file_size(dir / "run.mcap") > 10000);

  SECTION("output.mcap false: no bag") {
    const std::filesystem::path off = "ros2_bag_off";
    std::filesystem::remove_all(off);
    kelp::sim::Scenario q = sc;
    q.duration = 0.5;
    q.mcap = false;
    kelp::sim::RunOptions oo;
    oo.out = off.string();
    kelp::sim::run_scenario(q, oo);
    CHECK(std::filesystem::exists(off / "timeseries.csv"));
    CHECK_FALSE(std::filesystem::exists(off / "run.mcap"));
    // The scenario key round-trips through JSON; on (the default) it is left out.
    CHECK(kelp::sim::parse_scenario(kelp_test::json_of(q).dump(), "q").mcap == false);
    CHECK_FALSE(kelp_test::json_of(sc).at("output").contains("mcap"));
  }
}

TEST_CASE("BagRecorder refuses a marker rate that is not > 0 before it creates its file",
          "[ros2][sim]") {
  const std::filesystem::path dir = "ros2_bag_bad_rate", file = dir / "run.mcap";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (const double rate : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    INFO("marker rate " << rate);
    CHECK_THROWS_AS(kelp::sim::BagRecorder(file, rate), kelp::invalid_argument);
    CHECK_FALSE(std::filesystem::exists(file));
  }
}

TEST_CASE("RunBag refuses a bad marker rate or row before it creates its directory",
          "[ros2][sim]") {
  const std::filesystem::path top = "ros2_run_bag_refused", file = top / "out" / "run.mcap";
  std::filesystem::remove_all(top);
  // A row with what the messages need: both vehicles and a straight 4-segment tether at rest.
  kelp::tether::TetherParametersd p;
  p.length = 4;
  p.segments = 4;
  const kelp::tether::TetherModeld line(p);
  kelp::tether::TetherStated x(line);
  for (int i = 0; i <= 4; ++i) x.position.col(i) = kelp::Vector3<double>(i, 0, 1);
  kelp::vehicle::VehicleStated asv, auv;
  auv.position = kelp::Vector3<double>(4, 0, 1);
  kelp::sim::LogRow row;
  row.asv = &asv;
  row.auv = &auv;
  row.tether_model = &line;
  row.tether = &x;
  row.force_on_asv.setZero();
  row.force_on_auv.setZero();
  for (const double rate : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    INFO("marker rate " << rate);
    std::filesystem::remove_all(top);
    kelp::sim::RunBag bag(file, rate);
    CHECK_THROWS_AS(bag.record(row), kelp::invalid_argument);
    CHECK_FALSE(std::filesystem::exists(top));
  }
  // A good rate, but a row the messages refuse: no tether, a time that is not a ROS time.
  kelp::sim::LogRow no_tether = row, no_time = row;
  no_tether.tether = nullptr;
  no_time.t = std::nan("");
  for (const kelp::sim::LogRow* bad : {&no_tether, &no_time}) {
    INFO((bad == &no_tether ? "no tether" : "a NaN time"));
    std::filesystem::remove_all(top);
    kelp::sim::RunBag refused(file, 2.0);
    CHECK_THROWS_AS(refused.record(*bad), kelp::invalid_argument);
    CHECK_FALSE(std::filesystem::exists(top));
  }
  // A bag whose first row was refused records the next good one: its directory and file are
  // created then.
  kelp::sim::RunBag bag(file, 2.0);
  CHECK_THROWS_AS(bag.record(no_tether), kelp::invalid_argument);
  bag.record(row);
  bag.close();
  CHECK(std::filesystem::exists(file));
}
