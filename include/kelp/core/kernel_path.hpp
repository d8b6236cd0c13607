/// \file
/// \brief Which instruction path kelp's run-time dispatched kernels take, and the deterministic
/// mode that pins them to one path available on every CPU.
///
/// kelp compiles for the build's baseline instruction set (x86-64: SSE2, no FMA, unless the user
/// passes -march/-mfma flags). One kernel is also compiled for wider instruction sets and chosen
/// at run time: the wave kinematics kernel (kelp/environment/wave_kernels.hpp), with AVX2 + FMA and
/// AVX-512 builds on x86-64 with GCC or clang. The wider builds contract multiply–adds into fused
/// multiply–adds (one rounding instead of two), so their results differ from the baseline's in the
/// last bits (≲ 1e-15 relative per wave sum); those differences then grow through a
/// chaotic closed loop, and a run on a CPU with AVX2 and FMA does not reproduce the same run on
/// one without (the AVX2 and AVX-512 builds gave the same bits with GCC 12, but nothing obliges a
/// compiler to contract both alike). The tether's force passes (kelp/tether/forces.hpp), the
/// implicit steps' array passes (kelp/tether/stepping.hpp) and the solve with a kept Newton
/// factor (kelp/tether/block_solve.hpp) are dispatched as well, to AVX2 builds without FMA that
/// give the same bits as the baseline's: they give the same bits on every CPU that runs the
/// program, whatever the path.
///
/// `KernelPath::portable` computes what the baseline build computes, never a fused multiply–add:
/// with it, a program gives the same bits on every CPU that runs it (the deterministic mode). It
/// still uses the CPU's vectors: its operations are compiled for SSE2, AVX2 without FMA and (GCC)
/// AVX-512 with contraction off, which give the same bits, and the widest the CPU has runs. It is
/// chosen
///   - for the whole process: `set_kernel_policy(KernelPath::portable)` or the environment variable
///     `KELP_KERNEL=portable` (read once, at the first use);
///   - for one wave field: `WaveField::set_kernel(KernelPath::portable)` (kelp::sim scenarios:
///     `"deterministic": true` or `"kernel": "portable"`), which takes precedence over the process'
///     policy.
///
/// The C library's own math (std::sin, std::exp, … called outside the kernels) is dispatched
/// too: glibc picks FMA builds of them on CPUs with FMA and AVX2 (glibc's
/// sysdeps/x86_64/fpu/multiarch), and SSE2 builds elsewhere; measured with glibc 2.36, about 7 in
/// 10⁴ results of sin, cos, exp and pow differ between the two. `math_library_fingerprint()`
/// tells them apart; see docs/deterministic.md.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "kelp/core/error.hpp"

#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && !defined(__AVX2__) && \
    !defined(__FMA__)
/// Defined when kelp builds its AVX2 and AVX-512 kernels beside the baseline and chooses among them
/// at run time (GCC or clang on x86-64 with a baseline below AVX2 and without FMA). A program
/// compiled with -mfma, -mavx2 or -march=native has one build only (its `portable` path then
/// contracts like the rest of the program, and gives the same bits on every CPU that runs it).
#define KELP_X86_DISPATCH 1
#endif

#if defined(KELP_X86_DISPATCH) && !defined(__clang__)
/// Defined to 1 when the portable path has an AVX-512 build without FMA (GCC: its
/// `optimize("fp-contract=off")` attribute; clang's AVX-512 implies FMA and it has no such
/// attribute, so there the portable path's widest build is AVX2).
#define KELP_PORTABLE_AVX512 1
#else
/// \brief 1 when the portable kernel path has an AVX-512 build without FMA (GCC on x86-64), 0
/// otherwise (this build: no such build; the portable path's widest is AVX2 or the baseline).
#define KELP_PORTABLE_AVX512 0
#endif

namespace kelp::simd {

/// \brief An instruction path of kelp's run-time dispatched kernels.
enum class KernelPath {
  automatic,  ///< the process' policy (for a wave field), else the widest path the CPU runs
  portable,   ///< the build's baseline instruction set (x86-64: SSE2, no FMA): same bits on every
              ///< CPU
  avx2,       ///< AVX2 + FMA (x86-64; Intel since 2013, AMD since 2015)
  avx512,     ///< AVX-512 F + DQ (x86-64; Intel Skylake-SP and later, AMD Zen 4 and later)
};

/// \brief The environment variable read (once) for the process' kernel policy: `auto`,
/// `portable`, `avx2` or `avx512`.
inline constexpr const char* kernel_environment_variable = "KELP_KERNEL";

/// \brief The name of a path as the environment variable, scenario files and summaries spell it:
/// "auto", "portable", "avx2", "avx512".
/// \param p the path. \return its name, a string literal ("?" for a value outside the enum).
inline const char* kernel_name(KernelPath p) {
  switch (p) {
    case KernelPath::automatic:
      return "auto";
    case KernelPath::portable:
      return "portable";
    case KernelPath::avx2:
      return "avx2";
    case KernelPath::avx512:
      return "avx512";
  }
  return "?";
}

/// \brief The path named `name` ("auto", "portable", "avx2", "avx512").
/// \param name the name, as kernel_name spells it. \return the path.
/// \throws kelp::invalid_argument naming the value and the allowed ones.
inline KernelPath parse_kernel_path(const std::string& name) {
  for (KernelPath p :
       {KernelPath::automatic, KernelPath::portable, KernelPath::avx2, KernelPath::avx512})
    if (name == kernel_name(p)) return p;
  ::kelp::detail::throw_invalid_argument(
      "kernel path \"" + name + "\" is not one of \"auto\", \"portable\", \"avx2\", \"avx512\"");
}

/// \brief True when this program on this CPU can take path `p` (`automatic` and `portable`
/// always; `avx2` and `avx512` only in a dispatching build, KELP_X86_DISPATCH, on a CPU and OS
/// that support them).
/// \param p the path. \return whether a kernel may take it here; never throws.
inline bool kernel_supported(KernelPath p) {
  if (p == KernelPath::automatic || p == KernelPath::portable) return true;
#ifdef KELP_X86_DISPATCH
  // Checked once. GCC's and clang's __builtin_cpu_supports also check that the OS saves the
  // vector registers (XCR0), so a supported path cannot raise SIGILL.
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  static const bool avx512 =
      avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  return p == KernelPath::avx2 ? avx2 : avx512;
#else
  return false;
#endif
}

/// \brief The concrete paths this program can take on this CPU, narrowest first (always starts
/// with `portable`).
/// \return `portable`, then `avx2` and `avx512` where kernel_supported(); never throws (other
/// than std::bad_alloc).
inline std::vector<KernelPath> supported_kernels() {
  std::vector<KernelPath> v;
  for (KernelPath p : {KernelPath::portable, KernelPath::avx2, KernelPath::avx512})
    if (kernel_supported(p)) v.push_back(p);
  return v;
}

/// \brief The widest path the CPU runs (what `automatic` becomes without a policy).
/// \return `avx512`, `avx2` or `portable`; ignores the process' policy; never throws.
inline KernelPath widest_kernel() {
  return kernel_supported(KernelPath::avx512) ? KernelPath::avx512
         : kernel_supported(KernelPath::avx2) ? KernelPath::avx2
                                              : KernelPath::portable;
}

namespace detail {
/// The process' policy, -1 until set or read from the environment.
inline std::atomic<int>& kernel_policy_slot() {
  static std::atomic<int> slot{-1};
  return slot;
}

/// Throws unless `p` is supported, naming `where` (who asked) and the supported paths.
inline void check_kernel_supported(KernelPath p, const std::string& where) {
  if (kernel_supported(p)) return;
  std::string have;
  for (KernelPath q : supported_kernels())
    have += std::string(have.empty() ? "" : ", ") + kernel_name(q);
#ifdef KELP_X86_DISPATCH
  const char* why = "this CPU does not support it";
#else
  const char* why =
      "this build has no run-time dispatch (not GCC/clang on x86-64, or compiled "
      "with FMA or AVX2 already)";
#endif
  kelp::detail::throw_invalid_argument(where + ": kernel path \"" + kernel_name(p) +
                                       "\" cannot be used: " + why + " (available: " + have + ")");
}
}  // namespace detail

namespace detail {
/// The widest build of the portable path the process may use (tests and benchmarks lower it to
/// compare the builds): 0 baseline (SSE2), 1 AVX2 without FMA, 2 AVX-512 without FMA.
inline std::atomic<int>& portable_build_cap() {
  static std::atomic<int> cap{2};
  return cap;
}

/// The build the portable path takes: the widest this CPU (and compiler) has without FMA, at most
/// `portable_build_cap()`. Every build gives the same bits (see wave_kernels.hpp).
inline int portable_build() {
#ifdef KELP_X86_DISPATCH
  static const int widest = KELP_PORTABLE_AVX512 && __builtin_cpu_supports("avx512f") &&
                                    __builtin_cpu_supports("avx512dq")
                                ? 2
                            : __builtin_cpu_supports("avx2") ? 1
                                                             : 0;
  const int cap = portable_build_cap().load(std::memory_order_relaxed);
  return widest < cap ? widest : cap;
#else
  return 0;
#endif
}

/// The name of a portable build: "sse2" (or "baseline" outside x86-64), "avx2", "avx512".
inline const char* portable_build_name(int build) {
#if defined(__x86_64__)
  return build == 2 ? "avx512" : build == 1 ? "avx2" : "sse2";
#else
  (void)build;
  return "baseline";
#endif
}
}  // namespace detail

/// \brief Sets the process' kernel policy: the path every kernel takes unless its object chooses
/// one (e.g. `WaveField::set_kernel`). `automatic` restores the widest path. Takes effect at the
/// next kernel call in every thread (an atomic store); set it before starting threads that must
/// agree. Overrides the environment variable.
/// \throws kelp::invalid_argument when the CPU (or the build) lacks `p`: a forced path is never
/// taken on a CPU that would fault on it.
/// \param p the path every kernel takes from now on (`automatic`: the widest this CPU runs).
inline void set_kernel_policy(KernelPath p) {
  detail::check_kernel_supported(p, "set_kernel_policy");
  detail::kernel_policy_slot().store(static_cast<int>(p), std::memory_order_relaxed);
}

/// \brief The process' kernel policy as requested (possibly `automatic`): the last
/// `set_kernel_policy`, else the environment variable `KELP_KERNEL` (read at the first call that
/// finds no policy; empty is as unset), else `automatic`.
/// \throws kelp::invalid_argument when KELP_KERNEL holds an unknown name or a path this CPU
/// lacks (the message names the variable and its value; every call throws until it is fixed or
/// `set_kernel_policy` is called).
/// \return the requested path, possibly `automatic`.
inline KernelPath kernel_policy() {
  int v = detail::kernel_policy_slot().load(std::memory_order_relaxed);
  if (v >= 0) return static_cast<KernelPath>(v);
  KernelPath p = KernelPath::automatic;
  if (const char* env = std::getenv(kernel_environment_variable); env && *env) {
    const std::string where = std::string(kernel_environment_variable) + "=" + env;
    try {
      p = parse_kernel_path(env);
    } catch (const invalid_argument& e) {
      kelp::detail::throw_invalid_argument(where + ": " + e.what());
    }
    detail::check_kernel_supported(p, where);
  }
  // A concurrent set_kernel_policy wins over the environment.
  int expected = -1;
  detail::kernel_policy_slot().compare_exchange_strong(expected, static_cast<int>(p),
                                                       std::memory_order_relaxed);
  return static_cast<KernelPath>(detail::kernel_policy_slot().load(std::memory_order_relaxed));
}

/// \brief The concrete path a kernel asked for `requested` takes: `requested` itself unless it
/// is `automatic`, then the process' policy, and if that is `automatic` too the widest path.
/// \throws kelp::invalid_argument when `requested` is a path the CPU lacks, or from
/// `kernel_policy()` (a bad KELP_KERNEL).
/// \param requested a path, or `automatic` for the process' policy.
/// \return a concrete path (never `automatic`) that this CPU runs.
inline KernelPath resolve_kernel(KernelPath requested = KernelPath::automatic) {
  if (requested != KernelPath::automatic) {
    detail::check_kernel_supported(requested, "resolve_kernel");
    return requested;
  }
  const KernelPath p = kernel_policy();
  return p == KernelPath::automatic ? widest_kernel() : p;
}

/// \brief The path kernels without a choice of their own take now: `resolve_kernel()`.
/// \return a concrete path (never `automatic`).
/// \throws kelp::invalid_argument from kernel_policy() (a bad KELP_KERNEL).
inline KernelPath active_kernel() { return resolve_kernel(KernelPath::automatic); }

/// \brief 16 hex digits identifying the C library's math as this process computes it: a hash of
/// the bits of std::sin, cos, exp, log, pow, atan2, tanh and cosh at 256 fixed arguments each,
/// among them 24 at which glibc 2.36's FMA and SSE2 builds differ. Two processes with different
/// fingerprints (another C library version, or glibc's FMA build on one CPU and its SSE2 build on
/// another) may give different results whatever kernel path they take. About 2000 calls, ~50 µs.
/// \return 16 lower-case hex digits (FNV-1a of the result bits); the same in every call of one
/// process.
inline std::string math_library_fingerprint() {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the result bits
  const auto mix = [&h](double r) {
    std::uint64_t b;
    std::memcpy(&b, &r, sizeof b);
    for (int i = 0; i < 8; ++i) {
      h ^= (b >> (8 * i)) & 0xffu;
      h *= 1099511628211ull;
    }
  };
  // Arguments from a fixed 64-bit LCG (Knuth's MMIX constants), spread over [−20, 20]; before
  // them 24 pairs (x, y) at which glibc 2.36's FMA and SSE2 builds of one of the eight functions
  // differ (found by evaluating 4·10⁵ such pairs under GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA
  // and without, on an AMD EPYC).
  std::uint64_t s = 0x9e3779b97f4a7c15ull;
  const auto next = [&s] {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(s >> 11) * 0x1.0p-53 * 40.0 - 20.0;
  };
  static constexpr double known[][2] = {
      {0x1.236ba3c6ac474p+4, -0x1.b28b3d183ac93p+3},
      {-0x1.463b8da348bb4p+3, -0x1.b7f4ef07603ep+1},
      {0x1.3441ec8abaafcp+3, 0x1.f87e27c618e1cp+3},
      {-0x1.0ac342883dfdap+3, -0x1.cebb45f15992bp+3},
      {-0x1.5b3790fc61ee4p+3, -0x1.2987659a9b0a6p+4},
      {-0x1.2d4d326c88128p+1, 0x1.69d46015fd3ap+3},
      {-0x1.40c15dc2748fp+0, -0x1.1e74f021e072p-1},
      {-0x1.c1a9ee39cf1b8p+1, 0x1.739220ffb132p+2},
      {0x1.95ef5fb949c3cp+3, -0x1.20512b0a36d4cp+2},
      {0x1.b1103b533cd6p+1, 0x1.6d4c18846cb2cp+2},
      {-0x1.1ff9e9ae88446p+3, -0x1.57304e1019e5cp+2},
      {-0x1.9d3c9e7ed8958p+3, -0x1.e3961176b8348p+3},
      {0x1.12766db2aef08p+3, -0x1.0305dea77b3fep+3},
      {-0x1.2bab11916ed97p+4, 0x1.68c9fa6432cf4p+3},
      {0x1.001c3d2b9b00ep+3, 0x1.1899edb6f9dap+0},
      {-0x1.68b30ac411648p+1, 0x1.0a3cac94c5bfap+4},
      {0x1.1d82d4bbe8828p+4, 0x1.48f08b731213p+3},
      {0x1.3962feff92498p+1, 0x1.57817a15c7ap-3},
      {-0x1.67227338bc2fp+0, 0x1.1a6b04ba7ebf8p+3},
      {0x1.d5b411056a5cp-1, -0x1.c2c5b3c22829p+0},
      {-0x1.5c44851f33cbp+2, -0x1.466ad3af68f7cp+2},
      {-0x1.b94710a1ba99cp+3, 0x1.579363e7cebap-1},
      {-0x1.b1aa5d119cbdap+3, -0x1.690056e3b4812p+2},
      {-0x1.5dd8c612eed5cp+2, -0x1.472ed2fe8698p-3},
  };
  const auto all = [&mix](double x, double y) {
    mix(std::sin(x));
    mix(std::cos(x));
    mix(std::exp(x));
    mix(std::log(std::fabs(x) + 1e-3));
    mix(std::pow(std::fabs(x) + 1e-3, 0.1 * y));
    mix(std::atan2(x, y));
    mix(std::tanh(0.1 * x));
    mix(std::cosh(x));
  };
  for (const auto& xy : known) all(xy[0], xy[1]);
  for (int i = 0; i < 256; ++i) {
    const double x = next(), y = next();
    all(x, y);
  }
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

}  // namespace kelp::simd
