// The environment with ceres::Jet scalars: every public class instantiates, and the derivatives
// of the wave kinematics and current profile with respect to position match central finite
// differences of the double-precision model.
#include <ceres/jet.h>
#include <catch2/catch.hpp>

#include <limits>

#include "kelp/environment/current.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/paper.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/environment/spectra.hpp"
#include "kelp/environment/wave_loads.hpp"
#include "kelp/environment/waves.hpp"
#include "kelp/environment/wind.hpp"

using Jet = ceres::Jet<double, 3>;
using kelp::Vector3;
using namespace kelp::environment;

template class kelp::environment::WaveField<Jet>;
template class kelp::environment::CurrentModel<Jet>;
template class kelp::environment::WindField<Jet>;
template class kelp::environment::Environment<Jet>;

namespace {
// The Jet kinematics' velocity `kj` at x0, t equals the double field's, and its derivatives equal
// the double field's central differences.
template <typename K>
void check_velocity_derivatives(const WaveField<double>& wd, const K& kj, const Vector3<double>& x0,
                                double t) {
  const double h = 1e-6;
  for (int d = 0; d < 3; ++d) {
    Vector3<double> e = Vector3<double>::Zero();
    e(d) = h;
    const Vector3<double> dv =
        (wd.kinematics(x0 + e, t).velocity - wd.kinematics(x0 - e, t).velocity) / (2 * h);
    for (int r = 0; r < 3; ++r) {
      CHECK(kj.velocity(r).a == Approx(wd.kinematics(x0, t).velocity(r)).margin(1e-12));
      CHECK(kj.velocity(r).v(d) == Approx(dv(r)).margin(1e-7));
    }
  }
}
}  // namespace

TEST_CASE("wave kinematics: Jet derivatives match finite differences", "[environment][jet]") {
  for (const double depth : {std::numeric_limits<double>::infinity(), 18.0}) {
    WaveFieldParameters p;
    p.spectrum.significant_height = 2.0;
    p.spectrum.peak_period = 7.0;
    p.spreading = 1.0;
    p.depth = depth;
    p.n_components = 24;
    const WaveField<Jet> wj(p);
    const WaveField<double> wd(p);
    const Vector3<double> x0(3.0, -2.0, 4.0);
    const double t = 5.0;
    const Vector3<Jet> xj(Jet(x0(0), 0), Jet(x0(1), 1), Jet(x0(2), 2));
    const auto kj = wj.kinematics(xj, t);
    check_velocity_derivatives(wd, kj, x0, t);
    // The generic path's velocity gradient: the Jet derivative of the velocity, and the double
    // (SIMD) path's gradient.
    const auto kd = wd.kinematics(x0, t);
    for (int r = 0; r < 3; ++r)
      for (int d = 0; d < 3; ++d) {
        CHECK(kj.velocity_gradient(r, d).a == Approx(kj.velocity(r).v(d)).margin(1e-12));
        CHECK(kd.velocity_gradient(r, d) == Approx(kj.velocity(r).v(d)).margin(1e-12));
      }
    // Elevation gradient = slope.
    const Jet z = wj.elevation(xj(0), xj(1), t);
    const auto s = wd.slope(x0(0), x0(1), t);
    CHECK(z.v(0) == Approx(s(0)).margin(1e-12));
    CHECK(z.v(1) == Approx(s(1)).margin(1e-12));
  }
}

TEST_CASE(
    "Wheeler-stretched regular and spectral waves: Jet derivatives match finite "
    "differences",
    "[environment][jet][stretching]") {
  for (const double depth : {std::numeric_limits<double>::infinity(), 15.0}) {
    WaveFieldParameters p;
    p.spectrum.significant_height = 1.5;
    p.spectrum.peak_period = 6.0;
    p.n_components = 16;
    p.depth = depth;
    p.stretching = WaveStretching::wheeler;
    RegularWave w;
    w.height = 1.0;
    w.period = 5.0;
    w.direction = 0.3;
    p.regular = {w};
    const WaveField<Jet> wj(p);
    const WaveField<double> wd(p);
    const Vector3<double> x0(2.0, 1.0, 1.5);
    const Vector3<Jet> xj(Jet(x0(0), 0), Jet(x0(1), 1), Jet(x0(2), 2));
    for (const double t : {0.0, 2.7}) {
      const auto kj = wj.kinematics(xj, t);
      check_velocity_derivatives(wd, kj, x0, t);
    }
  }
}

TEST_CASE("environment sample with Jets: current profile derivative", "[environment][jet]") {
  Environment<Jet> env = make_environment<Jet>(presets::moderate());
  CurrentParameters cp;
  cp.speed = 1.0;
  cp.profile.kind = CurrentProfileKind::power_law;
  cp.profile.depth = 20.0;
  env.set_current(CurrentModel<Jet>(cp));
  const Vector3<Jet> p(Jet(1.0), Jet(2.0), Jet(10.0, 2));
  const auto s = env.sample(p, 3.0);
  // d/dz of ((20 − z)/20)^{1/7} at z = 10: −(1/7)(1/20)(0.5)^{−6/7} = −0.0129393.
  CHECK(s.current(0).v(2) == Approx(-(1.0 / 7) / 20 * std::pow(0.5, -6.0 / 7)).epsilon(1e-10));
  CHECK(s.wind.norm().a > 0.0);
  // Batch query with Jets takes the generic path.
  kelp::Matrix3X<Jet> pts(3, 2), vel(3, 2), acc(3, 2);
  pts.col(0) = p;
  pts.col(1) = p;
  env.sample_water(pts, 3.0, vel, acc);
  CHECK((vel.col(0) - s.current - s.wave_velocity).norm().a < 1e-12);
  // Loads compile and differentiate with Jets.
  const Vector3<Jet> f =
      wind_load(ConstantWindCoefficients{0.9, 0.8, 0.1}, WindAreas{0.3, 0.5, 1.2}, Jet(1.225),
                s.wind, Jet(0.1), Jet(1.0, 0), Jet(0.0));
  CHECK(f(0).v(0) != 0.0);
  CHECK(paper_wave_force(Jet(1025), Jet(9.81), Jet(1), Jet(1.2), Jet(0.1), Jet(0.5, 1), Jet(20))
            .v(1) == Approx(1025 * 9.81 * 1.2 * 0.1 * 2 * kelp::pi / 20));
}
