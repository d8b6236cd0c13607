// kelp.run_scenario's C++ part: kelp::sim::run_scenario (what kelp-tethered-pair runs) on a
// scenario file or text, with the program's overrides, its samples collected as columns.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/sim/fleet_run.hpp"
#include "kelp/sim/run.hpp"
#include "kelp/version.hpp"

namespace kelp_python {

namespace {

// The columns of timeseries.csv and one sample's values, appended to `out` in their order: the
// program's own definition (kelp::sim::timeseries_columns, for_each_value), so both stay equal.
const std::vector<std::string>& column_names() { return kelp::sim::timeseries_columns(); }

void append_row(const kelp::sim::LogRow& r, std::vector<double>& out) {
  kelp::sim::for_each_value(r, [&](double v) { out.push_back(v); });
}

// Ctrl-C in Python during a run: Python's own SIGINT handler only sets a flag, which the run
// polls through should_stop (PyErr_CheckSignals, with the GIL, once every 100 steps: a simulated
// second, a few milliseconds). The run then stops cleanly after its step (its files whole,
// summary.json "completed": false) and the pending exception (KeyboardInterrupt) is raised when
// it returns (rethrow()). kelp::sim installs no handler of its own.
class PythonSignals {
 public:
  std::function<bool()> check() {
    return [this] {
      if (raised_) return true;
      if (++calls_ % 100 != 0) return false;
      py::gil_scoped_acquire gil;
      raised_ = PyErr_CheckSignals() != 0;  // the exception stays set until rethrow()
      return raised_;
    };
  }
  // Raises the exception a signal's handler set during the run, if any (with the GIL held).
  void rethrow() const {
    if (raised_) throw py::error_already_set();
  }

 private:
  long calls_ = 0;
  bool raised_ = false;
};

// A fleet scenario (kelp::sim::run_fleet) into `out`, or into a temporary directory removed
// afterwards: (summary.json's text, timeseries.csv's columns or None).
py::tuple run_fleet(const kelp::sim::Scenario& sc, const std::string& file,
                    const std::optional<std::string>& out, bool timeseries) {
  namespace fs = std::filesystem;
  std::string dir;
  if (out) {
    dir = *out;
  } else {
    std::string pattern = (fs::temp_directory_path() / "kelp_fleet_XXXXXX").string();
    KELP_CHECK(::mkdtemp(pattern.data()) != nullptr, "run_scenario: no temporary directory");
    dir = pattern;
  }
  struct Cleanup {
    std::string dir;
    ~Cleanup() {
      std::error_code ec;
      if (!dir.empty()) fs::remove_all(dir, ec);
    }
  } cleanup{out ? std::string() : dir};
  PythonSignals signals;
  {
    py::gil_scoped_release release;
    kelp::sim::run_fleet(sc, file, dir, signals.check());
  }
  signals.rethrow();
  std::ifstream in(fs::path(dir) / "summary.json");
  const std::string summary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!timeseries) return py::make_tuple(summary, py::none());
  std::ifstream csv(fs::path(dir) / "timeseries.csv");
  std::string line, cell;
  std::getline(csv, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  while (std::getline(header, cell, ',')) names.push_back(cell);
  std::vector<std::vector<double>> cols(names.size());
  while (std::getline(csv, line)) {
    std::stringstream row(line);
    for (std::size_t j = 0; j < names.size() && std::getline(row, cell, ','); ++j)
      cols[j].push_back(std::strtod(cell.c_str(), nullptr));
  }
  py::dict columns;
  for (std::size_t j = 0; j < names.size(); ++j)
    columns[py::str(names[j])] = py::array_t<double>(py::ssize_t(cols[j].size()), cols[j].data());
  return py::make_tuple(summary, columns);
}

}  // namespace

void bind_scenario(py::module_& m) {
  m.def(
      "_run_scenario",
      [](const std::optional<std::string>& file, const std::optional<std::string>& text,
         std::optional<double> duration, std::optional<std::int64_t> seed,
         const std::optional<std::string>& kernel, bool deterministic,
         const std::optional<std::string>& out, bool timeseries, double checkpoint_every,
         bool resume) {
        kelp::sim::Scenario sc;
        kelp::sim::RunOptions ro;
        if (file) {
          sc = kelp::sim::load_scenario(*file);
          ro.scenario_file = *file;
        } else if (text) {
          sc = kelp::sim::parse_scenario(*text, "(dict)");
          ro.scenario_file = "(dict)";
        }
        kelp::sim::ScenarioOverrides ov;
        if (duration) {
          KELP_CHECK(std::isfinite(*duration) && *duration > 0,
                     "run_scenario: duration must be a finite number > 0 [s]");
          ov.duration = *duration;
        }
        if (seed) {
          KELP_CHECK(*seed >= 0, "run_scenario: seed must be >= 0");
          ov.seed = *seed;
        }
        if (kernel) ov.kernel = *kernel;
        ov.deterministic = deterministic;
        sc = kelp::sim::apply_overrides(sc, ov);
        KELP_CHECK(!(sc.fleet && (checkpoint_every != 0 || resume)),
                   "run_scenario: a fleet's run cannot be checkpointed yet");
        if (sc.fleet) return run_fleet(sc, ro.scenario_file, out, timeseries);
        if (out) ro.out = *out;
        KELP_CHECK(std::isfinite(checkpoint_every) && checkpoint_every >= 0,
                   "run_scenario: checkpoint_every must be a finite number >= 0 [s]");
        KELP_CHECK(out || (checkpoint_every == 0 && !resume),
                   "run_scenario: checkpoint_every and resume need out (the run's directory)");
        ro.checkpoint_every = checkpoint_every;
        ro.resume = resume;
        ro.version = KELP_VERSION_STRING;
        const std::vector<std::string> names = column_names();
        std::vector<double> rows;
        if (timeseries) {
          rows.reserve(names.size() * static_cast<std::size_t>(sc.duration * sc.log_rate + 2.0));
          ro.on_sample = [&rows](const kelp::sim::LogRow& r) { append_row(r, rows); };
        }
        std::string summary;
        PythonSignals signals;
        ro.should_stop = signals.check();
        {
          py::gil_scoped_release release;
          summary = kelp::sim::summary_json(kelp::sim::run_scenario(sc, ro));
        }
        signals.rethrow();
        if (!timeseries) return py::make_tuple(summary, py::none());
        // One (columns, samples) array; each column a contiguous view into it.
        const std::size_t nc = names.size(), nr = rows.size() / nc;
        py::array_t<double> table({nc, nr});
        auto t = table.mutable_unchecked<2>();
        for (std::size_t i = 0; i < nr; ++i)
          for (std::size_t j = 0; j < nc; ++j)
            t(static_cast<py::ssize_t>(j), static_cast<py::ssize_t>(i)) = rows[i * nc + j];
        py::dict columns;
        for (std::size_t j = 0; j < nc; ++j) columns[py::str(names[j])] = table[py::int_(j)];
        return py::make_tuple(summary, columns);
      },
      py::arg("file"), py::arg("text"), py::arg("duration"), py::arg("seed"), py::arg("kernel"),
      py::arg("deterministic"), py::arg("out"), py::arg("timeseries"), py::arg("checkpoint_every"),
      py::arg("resume"),
      "kelp::sim::run_scenario on a scenario file (`file`), a scenario's JSON text (`text`) or "
      "the embedded default (both None), with kelp-tethered-pair's overrides; a fleet scenario "
      "(\"fleet\") with kelp::sim::run_fleet. Returns (the summary as JSON text, the samples "
      "as a dict of columns or None). Use kelp.run_scenario.");
}

}  // namespace kelp_python
