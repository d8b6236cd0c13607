// kelp-mission: flies the tethered mission on two ArduPilot SITL instances over MAVLink: the
// BlueROV2 Heavy AUV (ArduSub) dives, holds depth and surveys a square while the BlueBoat ASV
// (ArduRover) follows it on the surface. See mission/mission.hpp for the mission and
// mission/csv_log.hpp for the logs; params/*.parm for the vehicles' parameters. Periodic
// messages and the dive and survey time-outs follow the vehicles' own clocks (time_boot_ms), so
// a SITL --speedup changes nothing the vehicles see; a mode change kelp-mission did not command
// (a failsafe) is reported and ends the mission (exit 1).
//
//   kelp-mission --sub tcp:127.0.0.1:5760 --rover tcp:127.0.0.1:5770 --depth 5 --hold 60
//                --survey-side 10 --log kelp-mission-log
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

#include "mission/mission.hpp"

int main(int argc, char** argv) {
  kelp_sitl::mission::Options o;
  CLI::App app{
      "kelp-mission: MAVLink client that flies the tethered AUV + ASV mission on "
      "ArduSub and ArduRover SITL"};
  app.add_option("--sub", o.sub, "ArduSub link, tcp:HOST:PORT, or none")->capture_default_str();
  app.add_option("--rover", o.rover, "ArduRover (boat) link, tcp:HOST:PORT, or none")
      ->capture_default_str();
  app.add_option("--depth", o.depth,
                 "target depth below the sea surface, m (ArduSub's altitude, negated)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--depth-tolerance", o.depth_tolerance,
                 "the dive (or the rise from deeper) ends this far short of --depth, m")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--hold", o.hold, "time holding depth in ALT_HOLD, s")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--survey-side", o.survey_side, "side of the survey square, m (0: no survey)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--survey-radius", o.survey_radius, "a corner is reached within this distance, m")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--log", o.log_dir, "directory for the CSV logs")->capture_default_str();
  app.add_option("--connect-timeout", o.connect_timeout, "s to connect to each vehicle")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--heartbeat-timeout", o.heartbeat_timeout, "s to the first HEARTBEAT")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--arm-timeout", o.arm_timeout, "s of arming retries per vehicle")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--position-timeout", o.position_timeout,
                 "s for the sub's first LOCAL_POSITION_NED (its EKF needs GPS)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--mode-timeout", o.mode_timeout, "s of retries per mode change")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--dive-timeout", o.dive_timeout, "s of the sub's clock to reach the depth")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--leg-timeout", o.leg_timeout,
                 "s of the sub's clock per side of the survey square")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--retry-interval", o.retry_interval, "s between command retries")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--link-timeout", o.link_timeout,
                 "wall s without HEARTBEAT that count as a lost link")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--dive-throttle", o.dive_throttle,
                 "MANUAL_CONTROL z while diving (0..499; 500 is neutral; 1000 minus it "
                 "while rising to --depth from deeper)")
      ->capture_default_str()
      ->check(CLI::Range(0, 499));
  CLI11_PARSE(app, argc, argv);

  try {
    kelp_sitl::mission::Mission mission(o, std::cout, std::cerr);
    return mission.run();
  } catch (const std::exception& e) {  // bad options (e.g. an endpoint that does not parse)
    std::cerr << "kelp-mission: " << e.what() << std::endl;
    return 2;
  }
}
