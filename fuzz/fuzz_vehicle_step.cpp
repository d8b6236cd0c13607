// libFuzzer target: vehicle parameter validation followed by one step of each integrator
// (include/kelp/vehicle/model.hpp, integrators.hpp, presets.hpp).
//
// Input (raw little-endian doubles; missing bytes take the preset's values): flags (preset
// BlueROV2 Heavy or BlueBoat, hydrostatics), the 107 numbers of VehicleParameters (mass, inertia,
// r_g, r_b, displaced volume, density, gravity, added mass, linear and quadratic damping,
// waterplane area, metacentric heights, hull height, wind areas and coefficients), the state
// (position, attitude quaternion, ν), τ, τ_ext, the current, the environment's water density and
// gravity, dt and the time.
// Oracle: VehicleModel and the environment setters either throw a kelp::error or succeed; each
// step (RK4, semi-implicit Euler, RK4 in an Environment) either throws a kelp::error or leaves a
// finite state with a unit quaternion; kelp::numerical_error leaves the state unchanged (as
// documented). Any other exception, crash or sanitizer report is a finding.
#include <cstring>
#include <optional>

#include "fuzz_common.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/presets.hpp"

namespace kv = kelp::vehicle;

namespace {

template <class M>
void read_matrix(kelp_fuzz::Reader& in, M& m) {
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) m(i, j) = in.f64(m(i, j));
}

bool same_bits(const kv::VehicleStated& a, const kv::VehicleStated& b) {
  return std::memcmp(a.position.data(), b.position.data(), sizeof(double) * 3) == 0 &&
         std::memcmp(a.attitude.coeffs().data(), b.attitude.coeffs().data(), sizeof(double) * 4) ==
             0 &&
         std::memcmp(a.nu.data(), b.nu.data(), sizeof(double) * 6) == 0 &&
         std::memcmp(&a.time, &b.time, sizeof(double)) == 0;
}

void run(const std::uint8_t* data, std::size_t size) {
  kelp_fuzz::Reader in(data, size);
  const std::uint8_t flags = in.u8(0);
  kv::VehicleParametersd p =
      (flags & 1) ? kv::blueboat<double>().parameters : kv::bluerov2_heavy<double>().parameters;
  if (flags & 2) p.hydrostatics = static_cast<kv::Hydrostatics>((flags >> 2) % 3);
  p.mass = in.f64(p.mass);
  read_matrix(in, p.inertia);
  read_matrix(in, p.r_g);
  read_matrix(in, p.r_b);
  p.displaced_volume = in.f64(p.displaced_volume);
  p.density = in.f64(p.density);
  p.gravity = in.f64(p.gravity);
  read_matrix(in, p.added_mass);
  read_matrix(in, p.damping.linear);
  read_matrix(in, p.damping.quadratic);
  p.waterplane_area = in.f64(p.waterplane_area);
  p.gm_transverse = in.f64(p.gm_transverse);
  p.gm_longitudinal = in.f64(p.gm_longitudinal);
  p.hull_height = in.f64(p.hull_height);
  p.wind_areas.frontal_area = in.f64(p.wind_areas.frontal_area);
  p.wind_areas.lateral_area = in.f64(p.wind_areas.lateral_area);
  p.wind_areas.length_overall = in.f64(p.wind_areas.length_overall);
  p.wind_coefficients.cx = in.f64(p.wind_coefficients.cx);
  p.wind_coefficients.cy = in.f64(p.wind_coefficients.cy);
  p.wind_coefficients.cn = in.f64(p.wind_coefficients.cn);

  kv::VehicleStated x0;
  read_matrix(in, x0.position);
  x0.attitude.w() = in.f64(1.0);
  x0.attitude.x() = in.f64(0.0);
  x0.attitude.y() = in.f64(0.0);
  x0.attitude.z() = in.f64(0.0);
  read_matrix(in, x0.nu);
  kelp::Vector6<double> tau = kelp::Vector6<double>::Zero(), tau_ext = tau;
  read_matrix(in, tau);
  read_matrix(in, tau_ext);
  kelp::Vector3<double> current(0, 0, 0);
  read_matrix(in, current);
  const double rho = in.f64(p.density), g = in.f64(p.gravity);
  const double dt = in.f64(1e-3);
  x0.time = in.f64(0.0);  // the clock the environment is sampled at

  std::optional<kv::VehicleModeld> model;
  kelp::environment::Environmentd env;
  try {
    model.emplace(p);
    env.set_water_density(rho).set_gravity(g).set_current(current);
  } catch (const kelp::error&) {
    return;
  }
  kv::VehicleWorkspaced ws;
  for (int integrator = 0; integrator < 3; ++integrator) {
    kv::VehicleStated x = x0;
    const char* names[] = {"step_rk4", "step_symplectic_euler", "step_rk4 (environment)"};
    const std::string what = std::string("vehicle ") + names[integrator];
    try {
      if (integrator == 0)
        kv::step_rk4(*model, ws, x, {tau, tau_ext}, dt, current);
      else if (integrator == 1)
        kv::step_symplectic_euler(*model, ws, x, {tau, tau_ext}, dt, current);
      else
        kv::step_rk4(*model, ws, env, x, {tau, tau_ext}, dt);
    } catch (const kelp::numerical_error&) {
      KELP_FUZZ_REQUIRE(same_bits(x, x0), what + ": numerical_error changed the state");
      continue;
    } catch (const kelp::error&) {
      continue;
    }
    KELP_FUZZ_REQUIRE(x.position.allFinite() && x.nu.allFinite() && x.attitude.coeffs().allFinite(),
                      what + ": non-finite state after a successful step");
    KELP_FUZZ_REQUIRE(std::abs(x.attitude.squaredNorm() - 1.0) < 1e-6,
                      what + ": attitude not a unit quaternion after a step");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return kelp_fuzz::run_catching_stray_errors(run, data, size);
}
