/// \file
/// \brief Wave loads on a body from plain numbers: the Froude–Krylov force of the undisturbed
/// flow's acceleration on a displaced volume. The one implementation of that term: the vehicles'
/// forward dynamics (vehicle/model.hpp) and the paper-era small-body formula
/// (small_body_wave_force in paper.hpp) both call it. The paper's formulas themselves are in
/// `kelp/environment/paper.hpp`.
///
/// The environment knows no vehicle: callers pass the displaced volume and the acceleration.
/// Frames: any (the force is in the frame of the acceleration given); units SI.
#pragma once

#include <Eigen/Core>

#include "kelp/core/types.hpp"

namespace kelp {
namespace environment {

/// \brief Froude–Krylov force [N] of an accelerating undisturbed flow on a body small against
/// the wavelength: the pressure gradient −∇p = ρ a over the displaced volume,
/// \f$ \mathbf F_{FK} = \rho \nabla \mathbf a \f$ (Faltinsen 1990, ch. 3; DNV-RP-C205 (2010)
/// §6.2: the "1" of Morison's C_M = 1 + C_A). The acceleration is taken uniform over the body and
/// the moment is neglected. Unchecked (called inside a step): the callers validate.
/// \param[in] rho water density [kg/m³] \param[in] displaced_volume the wet volume ∇ [m³] (times
/// the submerged fraction for a body crossing the surface) \param[in] acceleration the water's
/// acceleration a [m/s²], in the frame wanted for the force.
/// \return F_FK [N], in the acceleration's frame.
template <typename Scalar, typename Derived>
Vector3<Scalar> froude_krylov_force(const Scalar& rho, const Scalar& displaced_volume,
                                    const Eigen::MatrixBase<Derived>& acceleration) {
  return (rho * displaced_volume) * Vector3<Scalar>(acceleration);
}

}  // namespace environment
}  // namespace kelp
