// The paper's story on one cell, printed scan by scan: a road cell seen free, then occupied by an
// object that appears (V), then stays (ζ grows, V → S). Uses only the ROS-free core.
#include <cstdio>
#include <string>

#include "map_aided_fusion/core/fusion.hpp"
#include "map_aided_fusion/core/pignistic.hpp"

using namespace map_aided_fusion::core;

int main()
{
  const FusionParams params;
  const PriorConfidence beta;
  const MassMG road = priorMass(PriorClass::kRoad, beta);
  const MassSG free_scan{ { FrameSG::kF, 0.7 }, { FrameSG::kOmega, 0.3 } };
  const MassSG occupied_scan{ { FrameSG::kO, 0.8 }, { FrameSG::kOmega, 0.2 } };
  std::printf("One road cell (prior m(FSV) = %.2f), 10 Hz scans: free for 1 s, then occupied for 4 s.\n",
              beta.beta_road);
  std::printf("%5s %-9s %6s %6s %6s %6s %6s %6s %8s  %s\n", "scan", "sees", "BetP F", "C", "N", "S", "V", "zeta",
              "conflict", "decision");
  MassMG m;
  double zeta = 0.0;
  for (int t = 0; t < 50; ++t)
  {
    const bool occupied = t >= 10;
    const auto r = fuseCell(m, zeta, occupied ? occupied_scan : free_scan, road, params);
    m = r.mass;
    zeta = r.zeta;
    const auto p = pignistic(m);
    int best = 0;
    for (int e = 1; e < FrameMG::kSize; ++e)
      if (p[e] > p[best]) best = e;
    if (t < 14 || t % 5 == 0)
      std::printf("%5d %-9s %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f %8.3f  %s\n", t, occupied ? "occupied" : "free", p[0],
                  p[1], p[2], p[3], p[4], zeta, r.conflicts.free_occupied + r.conflicts.occupied_free,
                  std::string(FrameMG::kNames[best]).c_str());
  }
  return 0;
}
