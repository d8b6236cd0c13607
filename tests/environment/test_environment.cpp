// The environment facade: the calm default is still water, a constant current is returned
// everywhere, the batch query agrees with the point query and allocates nothing, and bad input is
// rejected naming the field.
#include <catch2/catch.hpp>
#include <limits>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"

// Every public class, for every supported floating scalar (Jets: test_environment_jet.cpp).
template class kelp::environment::Environment<double>;
template class kelp::environment::Environment<float>;
template class kelp::environment::WaveField<double>;
template class kelp::environment::WaveField<float>;
template class kelp::environment::CurrentModel<double>;
template class kelp::environment::CurrentModel<float>;
template class kelp::environment::WindField<double>;
template class kelp::environment::WindField<float>;

using kelp::Matrix3X;
using kelp::Vector3;
using kelp::environment::Environment;

TEMPLATE_TEST_CASE("a default environment is still seawater with standard gravity", "[environment]",
                   double, float) {
  using S = TestType;
  const Environment<S> env = Environment<S>::calm();
  CHECK(env.water_density() == S(1025));
  CHECK(env.air_density() == S(1.225));
  CHECK(env.gravity() == S(kelp::standard_gravity));
  CHECK(env.seabed_depth() == std::numeric_limits<S>::infinity());
  for (const S z : {S(-1), S(0), S(3), S(50)}) {
    const auto s = env.sample(Vector3<S>(S(2), S(-4), z), S(12.5));
    CHECK(s.current.norm() == S(0));
    CHECK(s.wave_velocity.norm() == S(0));
    CHECK(s.wave_acceleration.norm() == S(0));
    CHECK(s.surface_elevation == S(0));
    CHECK(s.wind.norm() == S(0));
  }
  CHECK(env.surface_elevation(S(1), S(2), S(3)) == S(0));
  CHECK(env.is_still_water());
}

TEMPLATE_TEST_CASE("is_still_water is false as soon as there is a current or a wave",
                   "[environment]", double, float) {
  using S = TestType;
  Environment<S> with_current, with_waves;
  with_current.set_current(Vector3<S>(S(0), S(0.1), S(0)));
  CHECK_FALSE(with_current.is_still_water());
  kelp::environment::WaveFieldParameters wp;
  wp.spectrum.significant_height = 1.0;
  wp.n_components = 8;
  with_waves.set_waves(kelp::environment::WaveField<S>(wp));
  CHECK_FALSE(with_waves.is_still_water());
  // Wind alone leaves the water still.
  CHECK(
      kelp::environment::make_environment<S>(kelp::environment::presets::calm()).is_still_water());
}

TEMPLATE_TEST_CASE("a constant current is seen at every point, alone and in the batch query",
                   "[environment]", double, float) {
  using S = TestType;
  Environment<S> env;
  env.set_current(Vector3<S>(S(0.5), S(-0.2), S(0.01)));
  Matrix3X<S> pts(3, 5), vel(3, 5), acc(3, 5);
  pts << 0, 1, 2, 3, 4,  //
      0, 0, 1, 1, 2,     //
      0.5, 2, 4, 8, 16;
  vel.setConstant(S(99));
  acc.setConstant(S(99));
  Eigen::internal::set_is_malloc_allowed(false);
  env.sample_water(pts, S(3), vel, acc);
  Eigen::internal::set_is_malloc_allowed(true);
  for (Eigen::Index i = 0; i < pts.cols(); ++i) {
    const Vector3<S> p = pts.col(i);
    const auto s = env.sample(p, S(3));
    CHECK((s.current - Vector3<S>(S(0.5), S(-0.2), S(0.01))).norm() <= S(1e-6));
    CHECK((vel.col(i) - s.current - s.wave_velocity).norm() == S(0));
    CHECK(acc.col(i).norm() == S(0));
  }
}

TEST_CASE("bad environment input throws kelp::invalid_argument naming the field", "[environment]") {
  Environment<double> env;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(env.set_water_density(-1.0), kelp::invalid_argument);
  CHECK_THROWS_WITH(env.set_water_density(0.0), Catch::Contains("water_density"));
  CHECK_THROWS_WITH(env.set_air_density(nan), Catch::Contains("air_density"));
  CHECK_THROWS_WITH(env.set_gravity(-9.8), Catch::Contains("gravity"));
  CHECK_THROWS_WITH(env.set_seabed_depth(-5.0), Catch::Contains("seabed_depth"));
  CHECK_THROWS_WITH(env.set_seabed_depth(nan), Catch::Contains("seabed_depth"));
  CHECK_THROWS_WITH(env.set_current(Vector3<double>(nan, 0, 0)), Catch::Contains("current"));
  CHECK_NOTHROW(env.set_seabed_depth(std::numeric_limits<double>::infinity()));
  // Waves built with another gravity than the environment's are refused, in either order.
  kelp::environment::WaveFieldParameters wp;
  wp.spectrum.significant_height = 1.0;
  wp.gravity = 9.81;
  CHECK_THROWS_WITH(env.set_waves(kelp::environment::WaveField<double>(wp)),
                    Catch::Contains("waves.gravity"));
  env.set_gravity(9.81);
  CHECK_NOTHROW(env.set_waves(kelp::environment::WaveField<double>(wp)));
  CHECK_THROWS_WITH(env.set_gravity(9.80665), Catch::Contains("waves.gravity"));
  env.set_seabed_depth(30.0);
  CHECK(env.seabed_depth() == 30.0);
}

TEMPLATE_TEST_CASE("a calm sea writes the current (uniform or profiled) and zero acceleration",
                   "[environment]", double, float) {
  // The calm path skips the wave pass; it must still overwrite both outputs.
  using S = TestType;
  kelp::environment::CurrentParameters cp;
  cp.speed = 0.7;
  cp.direction = 1.1;
  cp.profile.kind = kelp::environment::CurrentProfileKind::linear;
  cp.profile.depth = 20.0;
  cp.profile.bottom_ratio = 0.25;
  Environment<S> still, profiled;
  profiled.set_current(kelp::environment::CurrentModel<S>(cp));
  Matrix3X<S> pts(3, 6), vel(3, 6), acc(3, 6);
  pts << 0, 1, 2, 3, 4, 5,  //
      0, 0, 1, 1, 2, 2,     //
      -1, 0, 5, 10, 20, 30;
  for (const Environment<S>* env : {&still, &profiled}) {
    vel.setConstant(S(99));
    acc.setConstant(S(99));
    Eigen::internal::set_is_malloc_allowed(false);
    env->sample_water(pts, S(2), vel, acc);
    Eigen::internal::set_is_malloc_allowed(true);
    for (Eigen::Index i = 0; i < pts.cols(); ++i) {
      const auto s = env->sample(Vector3<S>(pts.col(i)), S(2));
      CHECK((vel.col(i) - s.current).norm() <= S(1e-6));
      CHECK(acc.col(i).norm() == S(0));
    }
  }
  CHECK(vel(0, 0) != S(0));  // the profiled current is not zero at the surface
}
