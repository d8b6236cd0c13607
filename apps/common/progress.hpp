// The programs' progress bar on stderr (a process concern, so it lives with the programs, not in
// kelp::sim): kelp::sim::RunOptions::on_progress is called after every step.
#pragma once

#include <cstdio>
#include <functional>
#include <string>

namespace kelp_apps {

/// \brief A progress bar on stderr for a run of `duration` simulated seconds, redrawn every 500
/// steps (5 s simulated): `[#####   ]  12.3 / 120 s`. End it with progress_done().
inline std::function<void(long, long, double)> progress_bar(double duration) {
  return [duration](long k, long steps, double t) {
    if (k % 500 != 0) return;
    std::fprintf(stderr, "\r[%-40s] %5.1f / %.0f s",
                 std::string(static_cast<std::size_t>(40.0 * k / steps), '#').c_str(), t, duration);
  };
}

/// \brief Ends the bar's line.
inline void progress_done() { std::fprintf(stderr, "\n"); }

}  // namespace kelp_apps
