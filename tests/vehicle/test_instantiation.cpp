// Explicit instantiation of every public vehicle class template for double and float: every
// member must compile for both scalars (the ceres::Jet instantiation is
// test_jet_instantiation.cpp).
#include <catch2/catch.hpp>

#include "kelp/vehicle/damping.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/kinematics.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp::vehicle {
template struct VehicleState<double>;
template struct VehicleState<float>;
template struct DampingParameters<double>;
template struct DampingParameters<float>;
template struct VehicleParameters<double>;
template struct VehicleParameters<float>;
template class VehicleModel<double>;
template class VehicleModel<float>;
template struct VehicleWorkspace<double>;
template struct VehicleWorkspace<float>;
template struct PoseRate<double>;
template struct PoseRate<float>;
template struct StateDerivative<double>;
template struct StateDerivative<float>;
template class ThrusterAllocation<double>;
template class ThrusterAllocation<float>;
template class ThrusterChain<double>;
template class ThrusterChain<float>;
template struct PwmMapping<double>;
template struct PwmMapping<float>;
template struct VehiclePreset<double>;
template struct VehiclePreset<float>;
}  // namespace kelp::vehicle

TEST_CASE("double and float models give the same dynamics", "[vehicle][instantiation]") {
  namespace kv = kelp::vehicle;
  const kv::VehicleModeld md(kv::bluerov2_heavy<double>().parameters);
  const kv::VehicleModelf mf(kv::bluerov2_heavy<double>().parameters.cast<float>());
  kv::VehicleWorkspaced wd;
  kv::VehicleWorkspacef wf;
  kv::VehicleStated xd;
  xd.nu << 0.3, -0.1, 0.2, 0.1, -0.2, 0.3;
  xd.attitude = kelp::quaternion_from_euler(0.1, 0.2, 0.3);
  kv::VehicleStatef xf;
  xf.nu = xd.nu.cast<float>();
  xf.attitude = xd.attitude.cast<float>();
  kelp::Vector6<double> tau;
  tau << 5, -3, 2, 0.1, -0.2, 0.3;
  const kelp::Vector6<double> ad =
      kv::forward_dynamics(md, wd, xd, tau, kelp::Vector6<double>::Zero());
  const kelp::Vector6<float> af =
      kv::forward_dynamics(mf, wf, xf, tau.cast<float>(), kelp::Vector6<float>::Zero());
  CHECK((ad - af.cast<double>()).norm() < 1e-5 * ad.norm());
}
