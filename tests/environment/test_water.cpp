// One water: models of the environment layer that carry a density or gravity are checked against
// the Environment, the single source of truth.
#include <catch2/catch.hpp>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/paper.hpp"
#include "kelp/environment/wave_loads.hpp"
#include "kelp/environment/waves.hpp"

using namespace kelp::environment;

TEST_CASE("check_same_water: hydrostatics, paper wave and wave field against the environment",
          "[environment][water]") {
  Environment<double> fresh;
  fresh.set_water_density(1000.0);
  const Environment<double> sea;  // seawater, 1025 kg/m^3
  SurfaceHydrostatics h;          // defaults: seawater
  CHECK_NOTHROW(check_same_water(h, sea));
  CHECK_THROWS_AS(check_same_water(h, fresh), kelp::invalid_argument);
  CHECK_THROWS_WITH(check_same_water(h, fresh),
                    Catch::Contains("SurfaceHydrostatics") && Catch::Contains("1025") &&
                        Catch::Contains("1000") && Catch::Contains("water_density"));
  h.rho = fresh.water_density();
  h.gravity = fresh.gravity();
  CHECK_NOTHROW(check_same_water(h, fresh));

  PaperWave w;
  w.gravity = 9.81;
  CHECK_THROWS_WITH(check_same_water(w, sea),
                    Catch::Contains("PaperWave") && Catch::Contains("gravity"));
  w.gravity = sea.gravity();
  CHECK_NOTHROW(check_same_water(w, sea));

  WaveFieldParameters wp;
  wp.spectrum.significant_height = 1.0;
  wp.spectrum.peak_period = 6.0;
  wp.gravity = 9.81;
  const WaveField<double> waves(wp);
  CHECK_THROWS_WITH(check_same_water(waves, sea), Catch::Contains("WaveField"));
  CHECK_THROWS_WITH(Environment<double>().set_waves(waves), Catch::Contains("gravity"));
  Environment<double> moon_g;
  moon_g.set_gravity(9.81);
  CHECK_NOTHROW(check_same_water(waves, moon_g));
  // A float copy of the same numbers passes (1e-6 relative).
  Environment<float> seaf;
  CHECK_NOTHROW(check_same_water(SurfaceHydrostatics{}, seaf));
}
