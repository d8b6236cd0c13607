// Stopping a run cleanly (kelp/sim/stop.hpp) and what a killed run leaves (kelp/sim/run_log.hpp):
// the stop request and the programs' signal handlers (the second signal's default action back,
// an ignored signal left ignored), simulate() stopped mid-run (the summary of the time reached,
// the log whole), the log on the file in whole lines at least once a simulated second while the
// run goes on, no allocation in a logged step, events.csv's obstacle names quoted as CSV, and
// files written atomically.
#include <algorithm>
#include <catch2/catch.hpp>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "../support/heap_counter.hpp"
#include "kelp/sim.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The file ends with a newline and every line has the header's column count; returns the last
// line's first field (its time), or -1 without rows.
double whole_lines(const fs::path& p) {
  const std::string text = slurp(p);
  REQUIRE(!text.empty());
  CHECK(text.back() == '\n');
  std::size_t start = 0, columns = 0;
  double last = -1;
  for (std::size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1) {
    const std::string line = text.substr(start, end - start);
    const std::size_t n = 1 + std::size_t(std::count(line.begin(), line.end(), ','));
    if (columns == 0) {
      columns = n;
      continue;
    }
    CHECK(n == columns);
    last = std::stod(line.substr(0, line.find(',')));
  }
  return last;
}

using Handler = void (*)(int);
Handler handler_of(int signal) {
  struct sigaction sa {};
  sigaction(signal, nullptr, &sa);
  return sa.sa_handler;
}

}  // namespace

TEST_CASE("a program's handlers: the first signal requests a stop, the second ends the process",
          "[sim][stop]") {
  ks::clear_stop();
  CHECK_FALSE(ks::stop_requested());
  CHECK(ks::stop_signal() == 0);
  // A signal the program was started with ignored stays ignored.
  std::signal(SIGINT, SIG_IGN);
  ks::install_stop_handlers();
  CHECK(handler_of(SIGINT) == SIG_IGN);
  CHECK(handler_of(SIGTERM) != SIG_DFL);
  std::raise(SIGTERM);
  CHECK(ks::stop_requested());
  CHECK(ks::stop_signal() == SIGTERM);
  CHECK(ks::interrupted_exit_status() == 143);
  // The first signal put SIGTERM's default action back (a second one ends the process) and left
  // the ignored SIGINT alone.
  CHECK(handler_of(SIGTERM) == SIG_DFL);
  CHECK(handler_of(SIGINT) == SIG_IGN);
  std::signal(SIGINT, SIG_DFL);
  ks::install_stop_handlers();
  std::raise(SIGINT);
  CHECK(ks::stop_signal() == SIGTERM);  // the first request's signal is kept
  CHECK(handler_of(SIGINT) == SIG_DFL);
  CHECK(handler_of(SIGTERM) == SIG_DFL);
  ks::clear_stop();
  CHECK_FALSE(ks::stop_requested());
  ks::request_stop();
  CHECK(ks::interrupted_exit_status() == 130);
  ks::clear_stop();
}

TEST_CASE("simulate() stopped mid-run: the summary of the time reached and the log whole",
          "[sim][stop]") {
  ks::clear_stop();
  const ks::Scenario sc = kelp_test::short_calm_run();  // 5 s, rows at 5 Hz
  const fs::path dir = fs::current_path() / "test_stop_run";
  fs::remove_all(dir);
  ks::SimulateOptions o;
  o.log_dir = dir.string();
  long polls = 0;
  o.should_stop = [&polls] { return ++polls > 123; };  // stops before step 124
  const ks::RunSummary s = ks::simulate(sc, o);
  CHECK_FALSE(s.completed);
  CHECK(s.simulated_s == Approx(1.23).margin(1e-9));
  CHECK(s.tether_solver.steps == 123);
  CHECK(kelp_test::json_of(s)["completed"] == false);
  CHECK(whole_lines(dir / "timeseries.csv") == Approx(1.2).margin(1e-9));
  CHECK(whole_lines(dir / "nodes.csv") == Approx(1.0).margin(1e-9));
  whole_lines(dir / "events.csv");

  // The process-wide request (a program's signal) stops it before its first step.
  ks::request_stop(SIGINT);
  const ks::RunSummary none = ks::simulate(sc);
  ks::clear_stop();
  CHECK_FALSE(none.completed);
  CHECK(none.simulated_s == 0.0);
  // A run to its end.
  ks::Scenario tiny = sc;
  tiny.duration = 0.05;
  const ks::RunSummary all = ks::simulate(tiny);
  CHECK(all.completed);
  CHECK(all.simulated_s == 0.05);
  CHECK(kelp_test::json_of(all)["completed"] == true);
}

TEST_CASE("the run log is on the file in whole lines at least once a simulated second",
          "[sim][stop]") {
  const fs::path dir = fs::current_path() / "test_stop_log";
  fs::remove_all(dir);
  ks::RunLog log(dir);
  ks::ClosedLoopOptions o;
  o.log = &log;
  ks::ClosedLoop loop(kelp_test::short_calm_run(), o);
  // While the run goes on (the log open, as when a run is killed), after every 7th step: what is
  // on the file ends on a whole line, and holds every line at least 1.2 s old (a second between
  // two writes and a row: a snapshot taken just after a write waits for the next).
  while (!loop.done()) {
    loop.step();
    if (loop.steps_taken() % 7 != 0) continue;
    const double ts = whole_lines(dir / "timeseries.csv");
    const double nodes = whole_lines(dir / "nodes.csv");
    CHECK(ts >= loop.time() - 1.2 - 1e-9);
    if (loop.time() >= 1.2) CHECK(nodes >= loop.time() - 1.7 - 1e-9);  // snapshots every 0.5 s
  }
}

TEST_CASE("a logged closed-loop step allocates nothing, the log's writes included",
          "[sim][stop][malloc]") {
  const fs::path dir = fs::current_path() / "test_stop_log_alloc";
  fs::remove_all(dir);
  ks::RunLog log(dir);
  ks::ClosedLoopOptions o;
  o.log = &log;
  ks::ClosedLoop loop(kelp_test::short_calm_run(), o);
  loop.run_for(0.1);
  const long before = kelp_test::heap_allocations();
  loop.run_for(3.0);  // three seconds: rows, snapshots and three writes of each file
  CHECK(kelp_test::heap_allocations() == before);
}

TEST_CASE("events.csv quotes an obstacle name that holds a comma, a quote or a line break",
          "[sim][stop]") {
  const fs::path dir = fs::current_path() / "test_stop_log_quoting";
  fs::remove_all(dir);
  {
    ks::RunLog log(dir);
    const kelp::Vector3<double> at(1, 2, 3);
    log.entanglement(1.0, "entangled", at, ks::LogRow::none, "pile", 6.5);
    log.entanglement(2.0, "entangled", at, ks::LogRow::none, "pile, north", 6.5);
    log.entanglement(3.0, "pinned", at, 4.0, "the \"big\" one", 7.0);
    log.entanglement(4.0, "entangled", at, ks::LogRow::none, "two\nlines", 6.5);
    log.entanglement(5.0, "entangled", at, ks::LogRow::none, "cr\r", 6.5);
    log.close();
  }
  // RFC 4180: a field with a comma, a double quote or a line break is enclosed in double quotes,
  // a double quote in it doubled; any other field is written as it is.
  CHECK(slurp(dir / "events.csv") ==
        "t,event,segment,x,y,z,tension,obstacle,winding\n"
        "1,entangled,nan,1,2,3,nan,pile,6.5\n"
        "2,entangled,nan,1,2,3,nan,\"pile, north\",6.5\n"
        "3,pinned,nan,1,2,3,4,\"the \"\"big\"\" one\",7\n"
        "4,entangled,nan,1,2,3,nan,\"two\nlines\",6.5\n"
        "5,entangled,nan,1,2,3,nan,\"cr\r\",6.5\n");
}

TEST_CASE("write_file_atomically replaces a file whole and leaves no temporary", "[sim][stop]") {
  const fs::path dir = fs::current_path() / "test_stop_atomic";
  fs::remove_all(dir);
  fs::create_directories(dir);
  ks::write_file_atomically(dir / "summary.json", "{\"a\": 1}\n");
  ks::write_file_atomically(dir / "summary.json", "{\"b\": 2}");
  CHECK(slurp(dir / "summary.json") == "{\"b\": 2}");
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  CHECK_THROWS_AS(ks::write_file_atomically(dir / "no" / "such.json", "x"), kelp::error);
}
