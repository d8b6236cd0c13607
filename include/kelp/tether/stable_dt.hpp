/// \file
/// \brief The largest stable explicit time step of a tether: its highest axial frequency bounded
/// by Gershgorin's theorem, and the stability limit of each explicit scheme.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"

#include "kelp/tether/model.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp::tether {

namespace detail {

/// Number of segment springs on node i of a line of n segments (1 at an end, else 2).
inline int node_springs(int i, int n) { return (i > 0 ? 1 : 0) + (i < n ? 1 : 0); }

/// Water densities from 0 (air, vacuum) to the environment's `limits::max_fluid_density` (1e5
/// kg/m³, seven times mercury's); NaN and Inf refused.
template <typename Scalar>
void check_water_density(const Scalar& rho) {
  check_non_negative(rho, "water_density");
  check_at_most(rho, ::kelp::environment::limits::max_fluid_density, "water_density");
}

/// Axial mass of node i [kg]: structural plus tangential added mass, the node taken as
/// submerged in water of density ρ [kg/m³].
template <typename Scalar>
Scalar axial_node_mass(const TetherModel<Scalar>& model, int i, Scalar water_density) {
  return model.node_mass(i) +
         water_density * model.node_volume(i) * model.parameters().tangential_added_mass;
}

}  // namespace detail

/// \brief Largest angular frequency of the line [rad/s], bounded by Gershgorin's theorem.
/// Axial chain: ω²_a ≤ max_i Σ_j |K_ij| / m_i = max_i 2 k_i / m_i, with k_i the sum of the segment
/// spring constants EA/l on free node i and m_i its axial mass (structural plus tangential added
/// mass, nodes taken as submerged). Bending (EI > 0): the discrete bending stiffness is
/// (EI/l³)·DᵀD with D the second difference (‖DᵀD‖ ≤ 16), so ω²_b ≤ 16 EI/(l³ m_n) with m_n the
/// normal (added-mass) node mass. Returns √(ω²_a + ω²_b).
/// \throws kelp::invalid_argument for a water density ρ outside [0, 1e5] kg/m³ or NaN.
template <typename Scalar>
Scalar highest_axial_frequency(const TetherModel<Scalar>& model, Scalar water_density) {
  using std::sqrt;
  detail::check_water_density(water_density);
  const int n = model.segments();
  const TetherParameters<Scalar>& p = model.parameters();
  const Scalar l = model.segment_length();
  Scalar w2(0);
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const int springs = detail::node_springs(i, n);
    const Scalar rv = water_density * model.node_volume(i);
    const Scalar m = detail::axial_node_mass(model, i, water_density);
    Scalar wi = Scalar(2) * Scalar(springs) * model.axial_spring() / m;
    if (p.bending_stiffness > Scalar(0))
      wi += Scalar(16) * p.bending_stiffness /
            (l * l * l * (model.node_mass(i) + rv * p.normal_added_mass));
    w2 = std::max(w2, wi);
  }
  return sqrt(w2);
}

/// \brief Estimated largest stable explicit time step [s]: `safety` × h_max with
/// h_max ω_max = 2 (symplectic Euler), 1 (RK2, which is only stabilised by damping on the
/// imaginary axis; MoorDyn's CFL rule), 2√2 (RK4), reduced for internal damping by the
/// central-difference factor √(1 + ζ²) − ζ (ζ = c/(2 m ω_max), c = 2·(springs)·BA/l the
/// Gershgorin bound of the node's dashpots; Bathe, Finite Element Procedures, §9.4), which keeps
/// a heavily damped segment inside the negative-real-axis limit. Drag and seabed damping are
/// not included. Implicit schemes: +infinity (unconditionally stable for the linearised line;
/// choose dt for accuracy, e.g. 10 ms).
/// \param[in] water_density ρ [kg/m³] for the added mass (0: in air).
/// \param[in] safety factor in (0, 1] on the stability limit.
/// \throws kelp::invalid_argument for ρ outside [0, 1e5] kg/m³ or NaN, a safety factor outside
/// (0, 1], or an Integrator value outside the enumeration.
template <typename Scalar>
Scalar estimate_stable_dt(const TetherModel<Scalar>& model, Integrator integrator,
                          Scalar water_density = Scalar(kelp::seawater_density),
                          Scalar safety = Scalar(0.8)) {
  using std::sqrt;
  check_positive(safety, "safety");
  check_at_most(safety, 1.0, "safety");
  detail::check_water_density(water_density);
  KELP_CHECK(is_valid(integrator), "integrator is not a kelp::tether::Integrator value");
  if (is_implicit(integrator)) return std::numeric_limits<Scalar>::infinity();
  const Scalar w = highest_axial_frequency(model, water_density);
  if (!(w > Scalar(0))) return std::numeric_limits<Scalar>::infinity();
  Scalar limit(2);
  if (integrator == Integrator::rk2) limit = Scalar(1);
  if (integrator == Integrator::rk4) limit = Scalar(2.8284271247461903);
  // Largest damping ratio over the free nodes.
  Scalar zeta(0);
  const int n = model.segments();
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const int springs = detail::node_springs(i, n);
    const Scalar m = detail::axial_node_mass(model, i, water_density);
    zeta = std::max(zeta, Scalar(2) * Scalar(springs) * model.axial_damper() / (Scalar(2) * m * w));
  }
  return safety * limit / w * (sqrt(Scalar(1) + zeta * zeta) - zeta);
}

}  // namespace kelp::tether
