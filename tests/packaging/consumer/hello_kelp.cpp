// Smallest program a downstream user writes: include the umbrella header and use it.
// kelp/kelp.hpp first: this file is where the packaging test compiles it on its own.
#include <kelp/kelp.hpp>

#include <cstdio>

int main() {
  const auto R = kelp::rotation_zyx(0.0, 0.0, kelp::pi / 2);
  const kelp::Vector3<double> north = R * kelp::Vector3<double>(1, 0, 0);
  std::printf("body x-axis at 90 deg yaw points to (%.3f, %.3f, %.3f) NED\n", north.x(), north.y(),
              north.z());
  return (north - kelp::Vector3<double>(0, 1, 0)).norm() < 1e-12 ? 0 : 1;
}
