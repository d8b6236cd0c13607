// kelp-replay: the 3-D replay (replay.html, docs/replay.md) of an existing run directory:
// kelp-tethered-pair's (a fleet's too), kelp-sitl's, or a kelp-sweep run kept with --keep-series
// (<sweep>/runs/<hash>/). Reads timeseries.csv, nodes.csv and summary.json; writes replay.html
// into the directory (or --out), or with --json the replay data alone.
#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "common/replay_template.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/stop.hpp"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{
      "kelp-replay: writes replay.html, the run in 3-D in any browser (one file, no network), "
      "into a run directory of kelp-tethered-pair, kelp-sitl or kelp-sweep --keep-series"};
  std::string dir, out, json_out, title, source;
  app.add_option("DIR", dir, "the run directory (timeseries.csv, nodes.csv, summary.json)")
      ->required();
  app.add_option("--out", out, "where to write the page (default: DIR/replay.html)");
  app.add_option("--json", json_out, "write the replay data (JSON) to this file instead of a page");
  app.add_option("--title", title, "the page's title (default: program, scenario, duration)");
  app.add_option("--source", source, "the program that made the run (default: told from DIR)")
      ->check(CLI::IsMember({"kelp-tethered-pair", "kelp-sitl", "kelp-sweep"}));
  app.footer(
      "Exit status: 0 written, 1 not a run directory or a file error, 2 no page template, 130 / "
      "143 stopped by SIGINT / SIGTERM before the page was written (nothing written). The page "
      "(or the data) is written to a temporary file beside it and renamed: never half a page.");
  // SIGINT or SIGTERM: the page is not written (kelp/sim/stop.hpp); a second signal stops at once.
  // Installed before anything else, so that a signal in the first milliseconds is a clean stop.
  kelp::sim::install_stop_handlers();
  CLI11_PARSE(app, argc, argv);
  kelp::sim::ReplayOptions o;
  o.title = title;
  o.source = source;
  const auto stopped = [] {
    if (!kelp::sim::stop_requested()) return false;
    std::fprintf(stderr, "kelp-replay: stopped by %s; nothing written\n",
                 kelp::sim::stop_signal() == SIGTERM ? "SIGTERM" : "SIGINT");
    return true;
  };
  try {
    if (!json_out.empty()) {
      const std::string data = kelp::sim::replay_data_json(dir, o) + '\n';
      if (stopped()) return kelp::sim::interrupted_exit_status();
      kelp::sim::write_file_atomically(json_out, data);
      std::printf("kelp-replay: replay data of %s in %s\n", dir.c_str(), json_out.c_str());
      return 0;
    }
    const std::string page = kelp_apps::find_replay_template(KELP_REPLAY_TEMPLATE_BUILD);
    if (page.empty()) {
      std::fprintf(stderr, "kelp-replay: %s\n", kelp_apps::replay_template_missing_note().c_str());
      return 2;
    }
    // DIR/replay.html or --out, through a temporary file beside it (the same file system).
    const fs::path written = out.empty() ? fs::path(dir) / "replay.html" : fs::path(out);
    std::ifstream in(page, std::ios::binary);
    if (!in) throw kelp::error("cannot read the replay template " + page);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string html = kelp::sim::replay_html(text, kelp::sim::replay_data_json(dir, o));
    if (stopped()) return kelp::sim::interrupted_exit_status();
    kelp::sim::write_file_atomically(written, html);
    std::error_code ec;
    const auto size = fs::file_size(written, ec);
    std::printf("kelp-replay: %s (%.1f MB); open it in a browser: file://%s\n",
                written.string().c_str(), static_cast<double>(size) / 1e6,
                fs::absolute(written).string().c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kelp-replay: %s\n", e.what());
    return 1;
  }
}
