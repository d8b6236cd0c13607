// Kernel paths (kelp/core/kernel_path.hpp): names and parsing, the process' policy and the
// KELP_KERNEL environment variable, a path the CPU lacks refused, and the wave field's kernel
// pinned per field: the portable path gives the same bits whatever the process' policy, an
// unpinned field follows the policy.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include "kelp/core/kernel_path.hpp"
#include "kelp/environment/waves.hpp"

using kelp::simd::KernelPath;
namespace simd = kelp::simd;

namespace {

// A sea with crests above some of the points (the elevation is summed too), in finite depth.
kelp::environment::WaveFieldParameters kp_rough_sea() {
  kelp::environment::WaveFieldParameters p;
  p.spectrum.kind = kelp::environment::SpectrumKind::jonswap;
  p.spectrum.significant_height = 4.0;
  p.spectrum.peak_period = 9.0;
  p.n_components = 100;
  p.spreading = 1.0;
  p.depth = 40.0;
  p.seed = 3;
  return p;
}

// Velocities and accelerations of 45 points (one block and a part) at two times, as one matrix.
Eigen::MatrixXd kp_batch(const kelp::environment::WaveFieldd& w) {
  const int n = 45;
  kelp::Matrix3X<double> pts(3, n), v(3, n), a(3, n);
  for (int i = 0; i < n; ++i) pts.col(i) << 0.7 * i, -0.2 * i, -2.0 + 0.5 * i;
  Eigen::MatrixXd out(6, 2 * n);
  for (int k = 0; k < 2; ++k) {
    w.kinematics(pts, 13.7 + 100.0 * k, v, a);
    out.block(0, k * n, 3, n) = v;
    out.block(3, k * n, 3, n) = a;
  }
  return out;
}

bool kp_same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

// Sets KELP_KERNEL (null: unsets it) and forgets the process' policy, so that the next
// kernel_policy() reads the variable as a fresh process would; restores both at the end.
struct FreshPolicy {
  FreshPolicy() : saved(simd::detail::kernel_policy_slot().load()) {}
  void environment(const char* value) {
    if (value)
      setenv(simd::kernel_environment_variable, value, 1);
    else
      unsetenv(simd::kernel_environment_variable);
    simd::detail::kernel_policy_slot().store(-1);
  }
  ~FreshPolicy() {
    unsetenv(simd::kernel_environment_variable);
    simd::detail::kernel_policy_slot().store(saved);
  }
  int saved;
};

}  // namespace

TEST_CASE("kernel paths: names, parsing and the paths this CPU supports", "[core][kernel]") {
  for (KernelPath p :
       {KernelPath::automatic, KernelPath::portable, KernelPath::avx2, KernelPath::avx512})
    CHECK(simd::parse_kernel_path(simd::kernel_name(p)) == p);
  CHECK_THROWS_AS(simd::parse_kernel_path("sse2"), kelp::invalid_argument);
  CHECK_THROWS_WITH(simd::parse_kernel_path("AVX2"),
                    Catch::Contains("\"AVX2\"") && Catch::Contains("\"portable\""));
  CHECK(simd::kernel_supported(KernelPath::portable));
  CHECK(simd::kernel_supported(KernelPath::automatic));
  const auto paths = simd::supported_kernels();
  REQUIRE(!paths.empty());
  CHECK(paths.front() == KernelPath::portable);
  CHECK(paths.back() == simd::widest_kernel());
  std::string names;
  for (KernelPath p : paths) names += std::string(" ") + simd::kernel_name(p);
  WARN("kernel paths on this CPU:" << names);
  // AVX-512 implies AVX2 here (every AVX-512 CPU has AVX2 and FMA).
  if (simd::kernel_supported(KernelPath::avx512)) CHECK(simd::kernel_supported(KernelPath::avx2));
}

TEST_CASE("a path the CPU lacks is refused with kelp::invalid_argument, never run",
          "[core][kernel]") {
  bool any = false;
  for (KernelPath p : {KernelPath::avx2, KernelPath::avx512}) {
    if (simd::kernel_supported(p)) continue;
    any = true;
    CHECK_THROWS_WITH(simd::set_kernel_policy(p),
                      Catch::Contains(simd::kernel_name(p)) && Catch::Contains("available"));
    kelp::environment::WaveFieldd w(kp_rough_sea());
    CHECK_THROWS_AS(w.set_kernel(p), kelp::invalid_argument);
    CHECK(w.kernel() == KernelPath::automatic);  // unchanged
    FreshPolicy fresh;
    fresh.environment(simd::kernel_name(p));
    CHECK_THROWS_WITH(simd::kernel_policy(), Catch::Contains("KELP_KERNEL="));
  }
  if (!any) WARN("skipped: this CPU supports every kernel path (none to refuse)");
}

TEST_CASE("KELP_KERNEL sets the process' policy; a bad value is an error naming it",
          "[core][kernel]") {
  FreshPolicy fresh;
  fresh.environment(nullptr);
  CHECK(simd::kernel_policy() == KernelPath::automatic);
  CHECK(simd::active_kernel() == simd::widest_kernel());

  for (KernelPath p : simd::supported_kernels()) {
    fresh.environment(simd::kernel_name(p));
    CHECK(simd::kernel_policy() == p);
    CHECK(simd::active_kernel() == p);
  }
  fresh.environment("auto");
  CHECK(simd::active_kernel() == simd::widest_kernel());
  fresh.environment("");  // empty: as unset
  CHECK(simd::kernel_policy() == KernelPath::automatic);

  for (const char* bad : {"bogus", "AVX2", "portable ", "deterministic"}) {
    fresh.environment(bad);
    INFO("KELP_KERNEL=\"" << bad << "\"");
    CHECK_THROWS_AS(simd::kernel_policy(), kelp::invalid_argument);
    CHECK_THROWS_WITH(simd::active_kernel(),
                      Catch::Contains(std::string("KELP_KERNEL=") + bad + ":"));
    // An unpinned wave field's query reports it too (the step that asks throws).
    const kelp::environment::WaveFieldd w(kp_rough_sea());
    CHECK_THROWS_AS(w.active_kernel(), kelp::invalid_argument);
    // The API overrides the environment.
    simd::set_kernel_policy(KernelPath::portable);
    CHECK(simd::active_kernel() == KernelPath::portable);
    simd::detail::kernel_policy_slot().store(-1);
  }
  // Read once: changing the variable afterwards changes nothing.
  fresh.environment("portable");
  CHECK(simd::kernel_policy() == KernelPath::portable);
  setenv(simd::kernel_environment_variable, "bogus", 1);
  CHECK(simd::kernel_policy() == KernelPath::portable);
}

TEST_CASE("a wave field pinned to the portable path gives the same bits under every policy",
          "[environment][waves][kernel]") {
  FreshPolicy fresh;
  fresh.environment(nullptr);
  kelp::environment::WaveFieldd pinned(kp_rough_sea());
  pinned.set_kernel(KernelPath::portable);
  CHECK(pinned.kernel() == KernelPath::portable);
  const kelp::environment::WaveFieldd copy = pinned;  // copies keep the pin
  CHECK(copy.kernel() == KernelPath::portable);
  simd::set_kernel_policy(KernelPath::portable);
  const Eigen::MatrixXd reference = kp_batch(pinned);
  const kelp::environment::WaveFieldd follower(kp_rough_sea());  // unpinned: follows the policy
  CHECK(kp_same_bits(kp_batch(follower), reference));

  for (KernelPath p : simd::supported_kernels()) {
    INFO("policy " << simd::kernel_name(p));
    simd::set_kernel_policy(p);
    CHECK(pinned.active_kernel() == KernelPath::portable);
    CHECK(kp_same_bits(kp_batch(pinned), reference));
    CHECK(kp_same_bits(kp_batch(copy), reference));
    // The unpinned field takes the policy's path: the same bits as a field pinned to it, and
    // within FMA rounding of the portable path.
    CHECK(follower.active_kernel() == p);
    kelp::environment::WaveFieldd on_p(kp_rough_sea());
    on_p.set_kernel(p);
    const Eigen::MatrixXd r = kp_batch(follower);
    CHECK(kp_same_bits(r, kp_batch(on_p)));
    CHECK((r - reference).norm() <= 1e-12 * reference.norm());
    if (p != KernelPath::portable)
      WARN("the " << simd::kernel_name(p) << " wave kernel "
                  << (kp_same_bits(r, reference)
                          ? "gives the portable path's bits"
                          : "differs from the portable path in the last bits")
                  << " on this CPU (largest difference " << (r - reference).cwiseAbs().maxCoeff()
                  << ")");
  }
  if (simd::supported_kernels().size() == 1)
    WARN("only the portable path on this CPU: nothing else to compare with");
}

TEST_CASE("the portable path's builds (SSE2, AVX2 and AVX-512 without FMA) give the same bits",
          "[environment][waves][kernel]") {
  // The deterministic mode runs the widest build the CPU has; a CPU without AVX2 runs the SSE2
  // one. All must agree bit for bit: batches (points in lanes) and single points (components in
  // lanes, with the gradient and slope), deep and finite depth.
  struct CapAfter {
    ~CapAfter() { simd::detail::portable_build_cap().store(2); }
  } restore;
  for (const double depth : {std::numeric_limits<double>::infinity(), 40.0}) {
    auto p = kp_rough_sea();
    p.depth = depth;
    kelp::environment::WaveFieldd w(p);
    w.set_kernel(KernelPath::portable);
    Eigen::MatrixXd reference;
    Eigen::VectorXd point_reference;
    for (int cap = 0; cap <= 2; ++cap) {
      simd::detail::portable_build_cap().store(cap);
      const int build = simd::detail::portable_build();
      INFO("depth " << depth << ", portable build " << simd::detail::portable_build_name(build));
      if (build < cap) {
        WARN("skipped the portable build " << cap << ": this CPU (or compiler) lacks it");
        continue;
      }
      const Eigen::MatrixXd r = kp_batch(w);
      const auto k = w.kinematics(kelp::Vector3<double>(1.0, 2.0, 3.0), 13.7);
      Eigen::VectorXd pt(17);
      pt << k.velocity, k.acceleration,
          Eigen::Map<const Eigen::VectorXd>(k.velocity_gradient.data(), 9), k.slope;
      if (cap == 0) {
        reference = r;
        point_reference = pt;
        CHECK(pt.norm() > 0.1);  // a point in the water: not trivially zero
        continue;
      }
      CHECK(kp_same_bits(r, reference));
      CHECK(kp_same_bits(pt, point_reference));
    }
  }
}

TEST_CASE("the C library's math fingerprint is stable within a process", "[core][kernel]") {
  const std::string a = simd::math_library_fingerprint();
  CHECK(a.size() == 16);
  CHECK(a.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(simd::math_library_fingerprint() == a);
}
