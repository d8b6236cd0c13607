/// \file
/// \brief The 3-D replay of a run: the data of a run directory (timeseries.csv, nodes.csv,
/// summary.json) as the JSON the replay page reads, and replay.html, the page's template with
/// that data inlined (one file that opens in a browser from file://, no network).
///
/// The data's format ("kelp-replay": version 1 for the tethered pair, version 2 for a fleet run's
/// vehicles, point masses, anchors and tethers) is documented in docs/replay.md. The sea is not
/// recorded in the run's files: it is rebuilt from the scenario the summary echoes
/// (world_setup(); a fleet's summary echoes it as `scenario_echo`), and its wave components are
/// exported with the formula kelp evaluates
/// (environment::Environment::surface_elevation):
/// \f[ \zeta(x, y, t) = r(t) \sum_j a_j \cos\big(k_j (x\cos\beta_j + y\sin\beta_j) - \omega_j t
///     + \varphi_j\big) \f]
/// with the start-up ramp r(t) = ½(1 − cos(π t/T)) on [0, T), 0 before, 1 after. A few dozen
/// values of ζ computed by kelp itself (`elevation_check`) let the page be checked against it.
///
/// kelp-tethered-pair (through run_scenario()) and kelp-sitl write replay.html at the end of a
/// run, kelp-replay for an existing run directory. Part of the compiled `kelp::sim` component
/// (src/replay.cpp builds the JSON and gives it out as text). Where a program finds the page's
/// template is the program's concern (apps/common/).
#pragma once

#include <filesystem>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"

namespace kelp {
namespace sim {

/// \brief A directory that is not a run (no timeseries.csv, nodes.csv or summary.json with the
/// scenario), a file of it that cannot be read or parsed, or a replay template without its data
/// marker.
class KELP_SIM_API replay_error : public kelp::error {
 public:
  using kelp::error::error;
};

/// \brief Options of replay_data_json() and write_replay().
struct ReplayOptions {
  /// The program that made the run: "kelp-tethered-pair", "kelp-sitl" or "kelp-sweep"; empty:
  /// told from the directory (a summary with ArduPilot's counters is kelp-sitl's, a run kept by
  /// kelp-sweep lies in `<sweep>/runs/` beside `<sweep>/sweep.json`).
  std::string source;
  /// The page's title; empty: the program, the scenario file and the duration.
  std::string title;
  /// Number of `elevation_check` samples (>= 0).
  int elevation_samples = 50;
};

/// \brief The ramp factor of the replay's formula: r(t) = ½(1 − cos(π t/T)) on [0, T), 0
/// for t < 0, 1 from T on and always 1 for T = 0 (environment::Environment::ramp_factor).
/// \param t the time [s] \param ramp the ramp's duration T [s] (≤ 0 or NaN: no ramp)
/// \return r(t), in [0, 1]
KELP_SIM_API double replay_ramp(double t, double ramp);

/// \brief The replay data ("kelp-replay" version 1, docs/replay.md) of the run in `dir`, as JSON
/// text (compact, as replay_script() inlines it). A fleet run's directory (kelp/sim/fleet_run.hpp,
/// told by its summary) gives version 2: every vehicle's pose and hull box, every point mass,
/// anchor and tether (its nodes, end forces and length), the sea, seabed and obstacles of the
/// scenario its summary echoes (`scenario_echo`, else the scenario file it names). The pair's:
/// timeseries.csv (vehicles, target, errors, thrusts, commands, end tensions at the log rate),
/// nodes.csv (the tether's nodes and, when logged, its segment tensions at the node rate),
/// summary.json (its `scenario` rebuilds the sea: wave components, ramp, `elevation_check`; the
/// waypoints; obstacles and a seabed when the scenario has them). Display data is rounded
/// (positions to 1 mm, angles to 1e-4 rad, tensions, thrusts and errors to 0.01, commands to
/// 1e-4, times to 1e-6 s); the waves and `elevation_check` keep every digit.
/// \throws replay_error when `dir` is not a run directory or one of its files cannot be read (a
/// fleet's: also when neither the echoed scenario nor the scenario file is there, or nodes.csv
/// names a tether the scenario lacks); scenario_error when the echoed scenario is refused;
/// kelp::invalid_argument for a negative `o.elevation_samples`.
/// \param dir the run's directory \param o the source, title and elevation samples
/// \return the JSON text (UTF-8, one line)
KELP_SIM_API std::string replay_data_json(const std::filesystem::path& dir,
                                          const ReplayOptions& o = {});

/// \brief The script that defines the data in the page: `window.KELP_REPLAY_DATA = {...};`, from
/// the data's JSON text (replay_data_json()).
/// Every `<` of the JSON is written `\u003c` (it occurs only inside strings), so that no string
/// can close the script element (`</script>`) or open an HTML comment (`<!--`).
/// \param data_json the data's JSON text \return the script's text
KELP_SIM_API std::string replay_script(const std::string& data_json);

/// \brief The marker of the replay template replaced by replay_script() (alone inside its script
/// element).
inline constexpr const char* replay_data_marker = "/*@KELP_DATA@*/";

/// \brief replay.html's text: `template_text` with its data marker replaced by
/// replay_script(data_json).
/// \param template_text the page's template (with replay_data_marker once)
/// \param data_json the data's JSON text (replay_data_json()) \return the page's HTML text
/// \throws replay_error when the template has not exactly one data marker.
KELP_SIM_API std::string replay_html(const std::string& template_text,
                                     const std::string& data_json);

/// \brief Writes `dir`/replay.html: the template at `template_path` with the run's replay data
/// (replay_data_json()).
/// Written to a temporary file and renamed, so a reader never sees half a page.
/// \param dir the run's directory (replay.html is written there)
/// \param template_path the page's template file \param o as replay_data_json()'s
/// \returns the path of replay.html.
/// \throws replay_error as replay_data_json(), or when the template cannot be read or has no
/// data marker, or replay.html cannot be written; scenario_error as replay_data_json().
KELP_SIM_API std::filesystem::path write_replay(const std::filesystem::path& dir,
                                                const std::string& template_path,
                                                const ReplayOptions& o = {});

}  // namespace sim
}  // namespace kelp
