// libFuzzer target: the analytic catenary solver (include/kelp/tether/catenary.hpp):
// solve_catenary<double>, solve_catenary<float> and the 3-D helper catenary_between.
//
// Input (little-endian, raw IEEE-754 doubles; missing bytes take the defaults):
//   D, dz, L, w, start(3), end(3), EA, tolerance, vertical_tolerance, seabed_depth [f64],
//   max_iterations [i32].
// Oracle: the solver never throws (it is documented not to); the status is one of the enum's;
// the documented invalid inputs (NaN/Inf, L <= 0, D < 0, a negative vertical tolerance) give
// invalid_input (it may refuse more: kelp::tether::limits); every other status comes with finite
// values (the solver's contract since the tether limits): taut: a = +inf and a finite taut
// tension; vertical: a = c = 0; converged and max_iterations: finite a > 0 and c, converged also
// a finite residual. The 3-D helper: invalid_input for non-finite input; on the physical scale
// (fuzz_common.hpp: the end coordinates are not limited by the solver) its points, lowest point,
// end forces, tensions and H are finite for every status but invalid_input.
#include <limits>

#include "fuzz_common.hpp"
#include "kelp/tether/catenary.hpp"

namespace kt = kelp::tether;

namespace {

struct Input {
  double D = 5, dz = 2, L = 10, w = 1;
  kelp::Vector3<double> start{0, 0, 0}, end{5, 0, 2};
  double EA = 0, tolerance = 1e-14, vertical_tolerance = 1e-12;
  double seabed = std::numeric_limits<double>::infinity();
  int max_iterations = 30;
  bool off_scale = false;  // a geometry number off the physical scale (see fuzz_common.hpp)
};

Input read(const std::uint8_t* data, std::size_t size) {
  kelp_fuzz::Reader in(data, size);
  Input x;
  x.D = in.f64(x.D);
  x.dz = in.f64(x.dz);
  x.L = in.f64(x.L);
  x.w = in.f64(x.w);
  for (int i = 0; i < 3; ++i) x.start(i) = in.f64(x.start(i));
  for (int i = 0; i < 3; ++i) x.end(i) = in.f64(x.end(i));
  x.EA = in.f64(x.EA);
  x.tolerance = in.f64(x.tolerance);
  x.vertical_tolerance = in.f64(x.vertical_tolerance);
  x.seabed = in.f64(x.seabed);
  // Bounded so that a tolerance that is never met costs at most ~64k iterations per solve.
  x.max_iterations = static_cast<int>(in.i32(x.max_iterations) % 65536);
  x.off_scale = kelp_fuzz::any_off_scale(x.D, x.dz, x.L, x.w, x.start.x(), x.start.y(), x.start.z(),
                                         x.end.x(), x.end.y(), x.end.z(), x.EA);
  return x;
}

bool known(kt::CatenaryStatus s) {
  switch (s) {
    case kt::CatenaryStatus::converged:
    case kt::CatenaryStatus::taut:
    case kt::CatenaryStatus::vertical:
    case kt::CatenaryStatus::invalid_input:
    case kt::CatenaryStatus::max_iterations:
      return true;
  }
  return false;
}

template <typename S>
void check_solve(const Input& x) {
  kt::CatenaryOptions<S> o;
  o.EA = static_cast<S>(x.EA);
  o.tolerance = x.tolerance;
  o.vertical_tolerance = x.vertical_tolerance;
  o.max_iterations = x.max_iterations;
  const S D = static_cast<S>(x.D), dz = static_cast<S>(x.dz), L = static_cast<S>(x.L);
  const kt::CatenaryResult<S> r = kt::solve_catenary(D, dz, L, o);
  char values[160];
  std::snprintf(values, sizeof values, " (a %.17g, c %.17g, residual %.17g, iterations %d)",
                double(r.a), double(r.c), double(r.residual), r.iterations);
  const std::string what = std::string("solve_catenary<") + (sizeof(S) == 8 ? "double" : "float") +
                           "> status " + kt::to_string(r.status) + values;
  KELP_FUZZ_REQUIRE(known(r.status), what);
  const bool invalid =
      !(std::isfinite(double(D)) && std::isfinite(double(dz)) && std::isfinite(double(L))) ||
      !(L > S(0)) || D < S(0) || !(x.vertical_tolerance >= 0.0);
  // The solver may refuse more (absurd magnitudes, unusable options: kelp::tether::limits), but
  // never less.
  KELP_FUZZ_REQUIRE(!invalid || r.status == kt::CatenaryStatus::invalid_input,
                    what + ": invalid input not refused");
  switch (r.status) {
    case kt::CatenaryStatus::invalid_input:
      return;
    case kt::CatenaryStatus::taut:
      KELP_FUZZ_REQUIRE(std::isinf(double(r.a)) && r.a > S(0), what + ": a = +inf");
      KELP_FUZZ_REQUIRE(std::isfinite(double(r.taut_tension)), what + ": taut tension finite");
      return;
    case kt::CatenaryStatus::vertical:
      KELP_FUZZ_REQUIRE(r.a == S(0) && r.c == S(0), what + ": a = c = 0");
      return;
    case kt::CatenaryStatus::converged:
    case kt::CatenaryStatus::max_iterations:
      KELP_FUZZ_REQUIRE(r.a > S(0), what + ": a > 0");
      KELP_FUZZ_REQUIRE(std::isfinite(double(r.a)), what + ": a finite");
      KELP_FUZZ_REQUIRE(std::isfinite(double(r.c)), what + ": c finite");
      if (r.status == kt::CatenaryStatus::converged)
        KELP_FUZZ_REQUIRE(std::isfinite(double(r.residual)), what + ": residual finite");
      return;
  }
}

void check_shape(const Input& x) {
  kt::CatenaryOptionsd o;
  o.EA = x.EA;
  o.tolerance = x.tolerance;
  o.vertical_tolerance = x.vertical_tolerance;
  o.max_iterations = x.max_iterations;
  o.seabed_depth = x.seabed;
  const kt::CatenaryShaped shape = kt::catenary_between(x.start, x.end, x.L, x.w, o);
  const std::string what = std::string("catenary_between status ") + kt::to_string(shape.status());
  KELP_FUZZ_REQUIRE(known(shape.status()), what);
  const bool finite_input = x.start.allFinite() && x.end.allFinite() && std::isfinite(x.w);
  if (!finite_input)
    KELP_FUZZ_REQUIRE(shape.status() == kt::CatenaryStatus::invalid_input,
                      what + ": non-finite input must be invalid_input");
  if (shape.status() == kt::CatenaryStatus::invalid_input) return;
  if (x.off_scale || kelp_fuzz::off_scale(x.seabed)) return;  // coordinates are not limited
  for (int k = 0; k <= 4; ++k) {
    const double s = x.L * k / 4.0;
    KELP_FUZZ_REQUIRE(shape.point_at(s).allFinite(), what + ": point_at finite");
    KELP_FUZZ_REQUIRE(std::isfinite(shape.tension_at(s)), what + ": tension_at finite");
  }
  KELP_FUZZ_REQUIRE(shape.lowest_point().allFinite(), what + ": lowest_point finite");
  KELP_FUZZ_REQUIRE(shape.force_on_start().allFinite() && shape.force_on_end().allFinite(),
                    what + ": end forces finite");
  KELP_FUZZ_REQUIRE(std::isfinite(shape.horizontal_tension()), what + ": H finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Input x = read(data, size);
  try {
    check_solve<double>(x);
    check_solve<float>(x);
    check_shape(x);
  } catch (const std::exception& e) {
    kelp_fuzz::finding(std::string("the catenary solver threw (documented not to): ") + e.what());
  }
  return 0;
}
