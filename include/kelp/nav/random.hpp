/// \file
/// \brief Reproducible random numbers for the simulated sensors: one stream per sensor, derived
/// from a run's seed, with normal deviates computed here rather than by
/// `std::normal_distribution` (whose algorithm the C++ standard leaves to the library, so the
/// same seed gives other numbers under libstdc++, libc++ and MSVC).
///
/// The engine is `std::mt19937_64`, whose output sequence the standard fixes (ISO C++ 2017
/// [rand.eng.mers], the 10000th output of a default-constructed engine is 9981545732273789042).
/// Uniform deviates take its top 53 bits; normal deviates use Marsaglia and Bray's polar method
/// (G. Marsaglia, T. A. Bray, "A convenient method for generating normal variables", SIAM Review
/// 6(3), 1964), which needs only `std::log` and `std::sqrt`: the numbers are identical wherever
/// the C library's `log` rounds alike (the run summary's `math_library` fingerprint says which).
/// A stream's seed is mixed from the run's seed and the stream's number with SplitMix64 (Steele,
/// Lea and Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014), so that adding
/// a sensor does not change the numbers of the others. No heap allocation.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "kelp/core/memory.hpp"

namespace kelp::nav {

/// \brief One SplitMix64 step: advances `x` and returns the next 64-bit output.
/// \param[in,out] x Generator state, advanced by the golden-ratio increment.
/// \return The next output (a bijective mix of the new state).
inline std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// \brief The seed of stream `stream` of a run seeded with `seed` (SplitMix64 of both).
/// \param seed The run's seed.
/// \param stream The stream's number (one per sensor).
/// \return The seed of the stream's mt19937_64 engine.
inline std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t x = seed;
  const std::uint64_t a = splitmix64(x);
  x = a ^ (stream * 0xd1b54a32d192ed03ULL);
  return splitmix64(x);
}

/// \brief A reproducible stream of uniform and standard normal deviates (see the file comment).
class RandomStream {
 public:
  /// \brief Stream `stream` of the run seeded with `seed`.
  /// \param seed The run's seed.
  /// \param stream The stream's number (see stream_seed).
  explicit RandomStream(std::uint64_t seed = 1, std::uint64_t stream = 0)
      : engine_(stream_seed(seed, stream)) {}

  /// \brief A uniform deviate in the open interval (0, 1) (53 random bits).
  /// \return (n + 0.5)/2^53 for the engine's top 53 bits n.
  double uniform() {
    return (static_cast<double>(engine_() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
  }

  /// \brief A standard normal deviate (mean 0, variance 1), Marsaglia's polar method; the
  /// second deviate of each pair is kept for the next call.
  /// \return A deviate of N(0, 1).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    has_spare_ = true;
    return u * m;
  }

  /// \brief True with probability `p` (one uniform deviate).
  /// \param p Probability [-] (≤ 0: never, ≥ 1: always; a NaN: never).
  /// \return The draw.
  bool bernoulli(double p) { return uniform() < p; }
  /// \brief visit_memory(v): the engine's state and the spare deviate (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(engine_, spare_, has_spare_)

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace kelp::nav
