/// \file
/// \brief A vehicle model seen by the paper's formulas (`kelp/environment/paper.hpp`): the hull
/// data of a surface vessel as environment::SurfaceHydrostatics, so that the vehicle preset stays
/// the one copy of the hull data. Not included by `kelp/kelp.hpp`.
#pragma once

#include "kelp/core/scalar.hpp"
#include "kelp/environment/paper.hpp"
#include "kelp/vehicle/model.hpp"

namespace kelp::vehicle {

/// \brief The hull data of a surface-vessel model as the environment layer's
/// environment::SurfaceHydrostatics (for the paper's
/// wave_restoring()/surface_following_restoring()), so that the vehicle preset stays the one copy
/// of the hull data.
/// \tparam Scalar the parameters' scalar (the hydrostatics are doubles: value parts).
/// \param p a surface vessel's parameters (waterplane area, displaced volume, metacentric
/// heights, its water's density and gravity).
/// \return the hydrostatics (SI units).
template <typename Scalar>
environment::SurfaceHydrostatics surface_hydrostatics(const VehicleParameters<Scalar>& p) {
  environment::SurfaceHydrostatics h;
  h.rho = value_of(p.density);
  h.gravity = value_of(p.gravity);
  h.waterplane_area = value_of(p.waterplane_area);
  h.displaced_volume = value_of(p.displaced_volume);
  h.gm_transverse = value_of(p.gm_transverse);
  h.gm_longitudinal = value_of(p.gm_longitudinal);
  return h;
}

}  // namespace kelp::vehicle
