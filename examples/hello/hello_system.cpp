// Hello system: the paper's BlueBoat, BlueROV2 Heavy and 10 m tether in its moderate sea, the ROV
// driving away from the boat for 20 s (checked against docs/getting-started.md by CTest).
#include <algorithm>
#include <cstdio>

#include "kelp/system/presets.hpp"

int main() {
  namespace ks = kelp::system;
  // BlueBoat + BlueROV2 Heavy + 10 m ROV tether, moderate sea; ROV 5 m down astern of the boat.
  ks::presets::PaperWorld<double> w(10.0, ks::presets::Sea::moderate);
  ks::SystemInputsd in;
  in.auv.tau << -20, 0, 0, 0, 0, 0;  // body wrench [N, N m]: 20 N astern, away from the boat
  double peak = 0;
  for (int k = 0; k < 2000; ++k) {  // 20 s at 10 ms
    const ks::SystemReportd r = ks::step(w.model, w.workspace, w.state, in, 0.01);
    peak = std::max(peak, r.force_on_auv.norm());
  }
  const auto& s = w.state;
  std::printf(
      "after %.0f s: ROV at (%.2f, %.2f, %.2f) m, boat at (%.2f, %.2f) m, peak pull %.1f N\n",
      s.time, s.auv.position.x(), s.auv.position.y(), s.auv.position.z(), s.asv.position.x(),
      s.asv.position.y(), peak);
  return peak > 0.0 ? 0 : 1;
}
