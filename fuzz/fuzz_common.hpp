// Shared by kelp's libFuzzer targets (fuzz/*.cpp) and the seed generator (make_seeds.cpp): a
// little-endian reader over the fuzzer's input, its writer counterpart for the seeds, and the
// oracle's failure report.
//
// Numbers are read as raw IEEE-754 bit patterns, so byte mutations reach NaN, ±Inf, subnormals,
// huge and negative values; when the input runs out, the reader returns the caller's fallback
// (a valid default), so short inputs still reach the step or the solve.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "kelp/core/error.hpp"

namespace kelp_fuzz {

/// Reads the fuzzer's bytes front to back.
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  std::size_t remaining() const { return size_ - pos_; }

  std::uint8_t u8(std::uint8_t fallback = 0) {
    if (remaining() < 1) return fallback;
    return data_[pos_++];
  }
  std::uint32_t u32(std::uint32_t fallback = 0) {
    if (remaining() < 4) return fallback;
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(data_[pos_++]) << (8 * i);
    return v;
  }
  std::int32_t i32(std::int32_t fallback = 0) {
    if (remaining() < 4) return fallback;
    const std::uint32_t u = u32();
    std::int32_t v = 0;
    std::memcpy(&v, &u, sizeof v);
    return v;
  }
  double f64(double fallback = 0.0) {
    if (remaining() < 8) return fallback;
    std::uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u |= static_cast<std::uint64_t>(data_[pos_++]) << (8 * i);
    double v = 0;
    std::memcpy(&v, &u, sizeof v);
    return v;
  }
  /// The rest of the input.
  const std::uint8_t* rest(std::size_t& n) {
    n = remaining();
    const std::uint8_t* p = data_ + pos_;
    pos_ = size_;
    return p;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// The finite-output oracles of the library targets hold on a physical scale: a finite non-zero
/// number outside [1e-12, 1e12] in magnitude (a 1e200 m tether, a 1e-300 m diameter) may make a
/// product overflow to infinity without a bug in the model, so such inputs are only required not
/// to crash, not to trip a sanitizer and to fail with kelp::error if at all. NaN and ±Inf are not
/// "off scale": they must be refused (or be harmless) whatever else the input holds.
inline bool off_scale(double x) {
  const double a = std::abs(x);
  return std::isfinite(x) && a != 0.0 && (a < 1e-12 || a > 1e12);
}
template <class... T>
bool any_off_scale(const T&... x) {
  return (off_scale(x) || ...);
}

/// Writes what Reader reads (for the seed corpora).
class Writer {
 public:
  void u8(std::uint8_t v) { bytes.push_back(v); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void i32(std::int32_t v) {
    std::uint32_t u = 0;
    std::memcpy(&u, &v, sizeof u);
    u32(u);
  }
  void f64(double v) {
    std::uint64_t u = 0;
    std::memcpy(&u, &v, sizeof u);
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
  }
  std::vector<std::uint8_t> bytes;
};

/// An oracle violation: prints it and aborts, which libFuzzer reports as a crash (with the
/// input saved as crash-<sha1>).
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "\n== kelp fuzz oracle violated: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

#define KELP_FUZZ_REQUIRE(cond, what)                                            \
  do {                                                                           \
    if (!(cond))                                                                 \
      ::kelp_fuzz::finding(std::string(what) + " [" #cond "] at " __FILE__ ":" + \
                           std::to_string(__LINE__));                            \
  } while (false)

/// The body of a target whose `run(data, size)` catches every kelp::error its checked calls
/// may throw: one escaping it is a finding. Returns 0 for LLVMFuzzerTestOneInput.
template <typename Run>
int run_catching_stray_errors(Run&& run, const std::uint8_t* data, std::size_t size) {
  try {
    run(data, size);
  } catch (const kelp::error& e) {
    finding(std::string("kelp::error outside the checked calls: ") + e.what());
  }
  return 0;
}

}  // namespace kelp_fuzz
