// A custom environment whose five-argument sample_water just misses the signature the tether
// calls (docs/custom-environment.md): the tether refuses it at compile time instead of falling
// back to per-node surface_elevation queries. Compiled by CTest with -DNEAR_MISS=1 (the method
// is not const) or 2 (a float elevation for a double tether), expecting the static_assert's
// message (and only that error); with -DNEAR_MISS=0 (no five-argument query) it compiles.
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "wave_tank.hpp"

struct NearMissTank {
  WaveTank<double> tank;
  double water_density() const { return tank.water_density(); }
  double gravity() const { return tank.gravity(); }
  double seabed_depth() const { return tank.seabed_depth(); }
  double surface_elevation(double x, double y, double t) const {
    return tank.surface_elevation(x, y, t);
  }
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<double>>& points, double t,
                    Eigen::Ref<kelp::Matrix3X<double>> velocity,
                    Eigen::Ref<kelp::Matrix3X<double>> acceleration) const {
    tank.sample_water(points, t, velocity, acceleration);
  }
#if NEAR_MISS == 1
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<double>>& points, double t,
                    Eigen::Ref<kelp::Matrix3X<double>> velocity,
                    Eigen::Ref<kelp::Matrix3X<double>> acceleration,
                    Eigen::Ref<Eigen::VectorXd> elevation) {  // not const
    tank.sample_water(points, t, velocity, acceleration, elevation);
  }
#elif NEAR_MISS == 2
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<double>>& points, double t,
                    Eigen::Ref<kelp::Matrix3X<double>> velocity,
                    Eigen::Ref<kelp::Matrix3X<double>> acceleration,
                    Eigen::Ref<Eigen::VectorXf> elevation) const {  // float, not double
    tank.sample_water(points, t, velocity, acceleration);
    for (Eigen::Index i = 0; i < points.cols(); ++i)
      elevation(i) = static_cast<float>(surface_elevation(points(0, i), points(1, i), t));
  }
#endif
};

int main() {
  namespace kt = kelp::tether;
  const NearMissTank env;
  const kt::TetherModeld tether(kt::TetherParametersd{});
  kt::TetherWorkspaced ws(tether);
  const kelp::Vector3<double> a(0, 0, 0), b(10, 0, 5);
  kt::TetherStated s = kt::catenary_initial_state(tether, env, a, b);
  kt::step(tether, ws, env, s, kt::TetherBoundaryd::fixed(a, b), 0.01, {kt::Integrator::bdf2});
}
