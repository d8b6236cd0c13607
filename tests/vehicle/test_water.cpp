// One water: a vehicle built for seawater is refused in a freshwater environment; built from the
// environment's water it is accepted.
#include <catch2/catch.hpp>

#include "kelp/environment/environment.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/water.hpp"

namespace kv = kelp::vehicle;
namespace ke = kelp::environment;

TEMPLATE_TEST_CASE("a seawater vehicle in a freshwater environment throws", "[vehicle][water]",
                   double, float) {
  using S = TestType;
  ke::Environment<S> fresh;
  fresh.set_water_density(S(1000));
  const kv::VehicleModel<S> rov_sea(kv::bluerov2_heavy<S>().parameters);  // 1025 kg/m^3
  CHECK_THROWS_AS(kv::check_same_water(rov_sea, fresh), kelp::invalid_argument);
  CHECK_THROWS_WITH(kv::check_same_water(rov_sea, fresh, "BlueROV2 Heavy"),
                    Catch::Contains("BlueROV2 Heavy") && Catch::Contains("1025") &&
                        Catch::Contains("1000") && Catch::Contains("water_density"));
  const kv::VehicleModel<S> boat_sea(kv::blueboat<S>().parameters);
  CHECK_THROWS_AS(kv::check_same_water(boat_sea, fresh), kelp::invalid_argument);
  // Built from the environment's water, the same presets pass.
  const kv::VehicleModel<S> rov_fresh(
      kv::bluerov2_heavy<S>(fresh.water_density(), fresh.gravity()).parameters);
  const kv::VehicleModel<S> boat_fresh(
      kv::blueboat<S>(fresh.water_density(), fresh.gravity()).parameters);
  CHECK_NOTHROW(kv::check_same_water(rov_fresh, fresh));
  CHECK_NOTHROW(kv::check_same_water(boat_fresh, fresh));
  // ... and the freshwater ROV is really heavier in the water (B = rho g V is smaller).
  CHECK(rov_fresh.buoyancy() < rov_sea.buoyancy());
  // Gravity is checked too.
  ke::Environment<S> g981;
  g981.set_gravity(S(9.81));
  CHECK_THROWS_WITH(kv::check_same_water(rov_sea, g981), Catch::Contains("gravity"));
  // The default environment and the default presets agree (both seawater, standard gravity).
  CHECK_NOTHROW(kv::check_same_water(rov_sea, ke::Environment<S>()));
  CHECK_NOTHROW(
      kv::check_same_water(kv::bluerov2_heavy<S>().parameters, ke::Environment<double>()));
}
