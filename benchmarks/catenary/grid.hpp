// The fixed grid of slack geometries shared by the catenary benchmarks.
#pragma once

#include <cmath>
#include <vector>

namespace kelp_bench {

struct Geometry {
  double D, dz, L;
};

// L = 20 m; D/L from 1e-4 to 0.95 (log-spaced, 20 values) x dz/L from -0.9 to 0.9 (19 values),
// keeping the slack ones (L/chord > 1 + 1e-6): 326 geometries, from nearly taut to nearly vertical.
inline std::vector<Geometry> catenary_grid() {
  std::vector<Geometry> g;
  const double L = 20.0;
  for (int i = 0; i < 20; ++i) {
    const double d = 1e-4 * std::pow(0.95 / 1e-4, i / 19.0);
    for (int j = 0; j < 19; ++j) {
      const double t = -0.9 + 0.1 * j;
      if (std::hypot(d, t) * (1 + 1e-6) < 1.0) g.push_back({d * L, t * L, L});
    }
  }
  return g;
}

}  // namespace kelp_bench
