// Height-field seabed files (kelp/sim/heightfield_file.hpp).
#include "kelp/sim/heightfield_file.hpp"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "kelp/core/error.hpp"

namespace kelp {
namespace sim {

using kelp::environment::HeightField;

HeightField load_heightfield(const std::string& path) {
  std::ifstream in(path);
  KELP_CHECK(in.good(), "heightfield file '" + path + "': cannot open");
  std::vector<std::string> lines;
  std::vector<int> numbers;
  {
    std::string line;
    int lineno = 0;
    while (std::getline(in, line)) {
      ++lineno;
      const auto first = line.find_first_not_of(" \t\r");
      if (first == std::string::npos || line[first] == '#') continue;
      lines.push_back(line);
      numbers.push_back(lineno);
    }
  }
  const auto fail = [&](std::size_t k, const std::string& what) {
    ::kelp::detail::throw_invalid_argument("heightfield file '" + path + "'" +
                                           (k < numbers.size()
                                                ? ", line " + std::to_string(numbers[k])
                                                : std::string(", at the end")) +
                                           ": " + what);
  };
  const auto read_doubles = [&](std::size_t k, std::size_t count, const char* what) {
    if (k >= lines.size()) fail(k, std::string("missing ") + what);
    std::istringstream ss(lines[k]);
    std::vector<double> v;
    std::string tok;
    while (ss >> tok) {
      char* end = nullptr;
      const double x = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != '\0' || !std::isfinite(x))
        fail(k, std::string("'") + tok + "' is not a finite number (" + what + ")");
      v.push_back(x);
    }
    if (v.size() != count)
      fail(k, std::string(what) + ": expected " + std::to_string(count) + " numbers, found " +
                  std::to_string(v.size()));
    return v;
  };
  const std::vector<double> counts = read_doubles(0, 2, "num_x_points num_y_points");
  for (double c : counts)
    if (!(c >= 2 && c <= 100000 && c == std::floor(c)))
      fail(0, "num_x_points and num_y_points must be whole numbers in [2, 100000]");
  HeightField hf;
  hf.rows = int(counts[0]);
  hf.cols = int(counts[1]);
  if (double(hf.rows) * double(hf.cols) > 1e8) fail(0, "at most 1e8 grid points");
  const std::vector<double> xs = read_doubles(1, std::size_t(hf.rows), "x coordinates");
  const std::vector<double> ys = read_doubles(2, std::size_t(hf.cols), "y coordinates");
  const auto even = [&](const std::vector<double>& c, std::size_t k, const char* axis) {
    const double step = (c.back() - c.front()) / double(c.size() - 1);
    if (!(step > 0)) fail(k, std::string(axis) + " coordinates must increase");
    for (std::size_t i = 1; i < c.size(); ++i)
      if (!(std::abs((c[i] - c[i - 1]) - step) <= 1e-6 * step))
        fail(k, std::string(axis) + " coordinates must be evenly spaced (kelp's grid is regular)");
    return step;
  };
  hf.origin = Eigen::Vector2d(xs.front(), ys.front());
  hf.spacing = Eigen::Vector2d(even(xs, 1, "x"), even(ys, 2, "y"));
  hf.depth.assign(std::size_t(hf.rows) * std::size_t(hf.cols), 0.0);
  std::vector<std::uint8_t> seen(hf.depth.size(), 0);
  const std::size_t expected = hf.depth.size();
  if (lines.size() - 3 != expected)
    fail(lines.size() < 3 + expected ? lines.size() : 3 + expected,
         "expected " + std::to_string(expected) +
             " lines 'x y depth' (one per grid point), found " + std::to_string(lines.size() - 3));
  for (std::size_t k = 3; k < lines.size(); ++k) {
    const std::vector<double> p = read_doubles(k, 3, "x y depth");
    const double fi = (p[0] - hf.origin.x()) / hf.spacing.x();
    const double fj = (p[1] - hf.origin.y()) / hf.spacing.y();
    const double ri = std::round(fi), rj = std::round(fj);
    if (!(std::abs(fi - ri) <= 1e-6 && std::abs(fj - rj) <= 1e-6 && ri >= 0 && rj >= 0 &&
          ri < hf.rows && rj < hf.cols))
      fail(k, "point (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) +
                  ") is not on the grid of lines 2 and 3");
    const std::size_t idx = std::size_t(ri) * std::size_t(hf.cols) + std::size_t(rj);
    if (seen[idx]) fail(k, "grid point given twice");
    if (!(std::abs(p[2]) <= 1e5)) fail(k, "depth must be within 1e5 m");
    seen[idx] = 1;
    hf.depth[idx] = p[2];
  }
  validate(hf);
  return hf;
}

}  // namespace sim
}  // namespace kelp
