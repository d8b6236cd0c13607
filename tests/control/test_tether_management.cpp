// Tether management strategies (kelp/control/tether_management.hpp): the payout rate each one
// commands from the pull, the line out and the ROV's depth and offset.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/control/tether_management.hpp"

namespace kc = kelp::control;

TEST_CASE("constant tension keeps the pull in its band", "[control][winch]") {
  kc::TetherManagementSettings s;
  s.strategy = kc::WinchStrategy::constant_tension;
  s.tension_low = 5;
  s.tension_high = 25;
  s.tension_gain = 0.02;
  kc::TetherManagementInput in;
  in.length = 20;
  in.pull = 15;
  CHECK(kc::winch_command(s, in) == 0.0);  // inside the band: hold
  in.pull = 35;
  CHECK(kc::winch_command(s, in) == Approx(0.2));  // too much pull: pay out
  in.pull = 0;
  CHECK(kc::winch_command(s, in) == Approx(-0.1));  // slack: reel in
}

TEST_CASE("slack and depth following drive the line out to their targets", "[control][winch]") {
  kc::TetherManagementSettings s;
  kc::TetherManagementInput in;
  in.depth = 12;
  in.horizontal_offset = 5;
  in.length = 20;
  s.strategy = kc::WinchStrategy::slack;
  s.slack = 0.3;
  s.length_gain = 0.5;
  CHECK(kc::target_length(s, in) == Approx(1.3 * 13.0));
  CHECK(kc::winch_command(s, in) == Approx(0.5 * (16.9 - 20.0)));
  s.strategy = kc::WinchStrategy::depth_following;
  s.extra_length = 3;
  s.length_per_depth = 1;
  s.length_per_offset = 0.5;
  CHECK(kc::target_length(s, in) == Approx(3 + 12 + 2.5));
  CHECK(kc::winch_command(s, in) == Approx(0.5 * (17.5 - 20.0)));
  in.depth = -1;  // above the winch: no depth term
  CHECK(kc::target_length(s, in) == Approx(3 + 2.5));
  s.strategy = kc::WinchStrategy::hold;
  CHECK(kc::winch_command(s, in) == 0.0);
}

TEST_CASE("strategy names and bad settings", "[control][winch][bad_input]") {
  for (kc::WinchStrategy w : {kc::WinchStrategy::hold, kc::WinchStrategy::constant_tension,
                              kc::WinchStrategy::slack, kc::WinchStrategy::depth_following})
    CHECK(kc::winch_strategy_from_name(kc::winch_strategy_name(w)) == w);
  CHECK_THROWS_AS(kc::winch_strategy_from_name("yank"), kelp::invalid_argument);
  kc::TetherManagementSettings s;
  s.tension_high = s.tension_low;
  CHECK_THROWS_AS(kc::validate(s), kelp::invalid_argument);
  s = {};
  s.slack = std::nan("");
  CHECK_THROWS_AS(kc::validate(s), kelp::invalid_argument);
  s = {};
  s.strategy = static_cast<kc::WinchStrategy>(17);  // e.g. an integer cast from a file
  CHECK_THROWS_AS(kc::validate(s), kelp::invalid_argument);
  CHECK_NOTHROW(kc::validate(kc::TetherManagementSettings{}));
}
