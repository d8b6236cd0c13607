// Random catenary geometries shared by the fast-path and the Ceres tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>

namespace kelp_test {

struct Geometry {
  double D, dz, L;
};

// The paper's two equations as residuals in long double (independent of the solvers' double
// arithmetic); max(|R1|, |R2|) / L.
inline long double paper_residual_ld(long double a, long double c, long double D, long double dz,
                                     long double L) {
  const long double r1 = a * (std::cosh((D - c) / a) - std::cosh(c / a)) - dz;
  const long double r2 = a * (std::sinh((D - c) / a) + std::sinh(c / a)) - L;
  return std::max(std::fabs(r1), std::fabs(r2)) / L;
}

inline double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(rng));
}

// Family 1: slack ratio L/chord - 1 log-uniform in [1e-9, 999] (L/chord in [1 + 1e-9, 1e3]), then
// D/L log-uniform in [1e-6, chord/L) and the sign of dz at random; L log-uniform in [0.1, 1000] m.
inline Geometry random_by_slack(std::mt19937_64& rng) {
  const double L = log_uniform(rng, 0.1, 1000.0);
  const double ratio = 1.0 + log_uniform(rng, 1e-9, 999.0);
  const double chord = L / ratio;
  const double D = L * std::min(log_uniform(rng, 1e-6, chord / L), chord / L);
  const double dz_mag = std::sqrt(std::max(0.0, chord * chord - D * D));
  const double dz = (rng() & 1) ? dz_mag : -dz_mag;
  return {D, dz, L};
}

// Family 2: uniform in the shape plane: D/L log-uniform in [1e-6, 1), dz/L uniform in (-1, 1),
// redrawn until the chord is shorter than L / (1 + 1e-9).
inline Geometry random_by_shape(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> t(-1.0, 1.0);
  for (;;) {
    const double L = log_uniform(rng, 0.1, 1000.0);
    const double D = L * log_uniform(rng, 1e-6, 1.0);
    const double dz = L * t(rng);
    if (std::hypot(D, dz) * (1.0 + 1e-9) < L) return {D, dz, L};
  }
}

}  // namespace kelp_test
