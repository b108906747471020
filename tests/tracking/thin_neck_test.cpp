// Two parallel tubes whose gap is thinner than a slice (issue 21, the family's parallel variant at its
// narrowest gap, 2 in-plane voxels; docs/notes/tracking.md session 19 par2): across the gap the slices hold
// two partial-volume voxels side by side, one per tube, and no voxel of tissue. The valley term's line 1 step
// each way from one of them reaches the other (no dip), and its second scale (1.2 mm) was 1 step too along
// the coarse axis: the neck cost epsilon (family seed 10211: a path to B ran along A and stepped across). With at
// least 2 steps each way at the smoothed valley's second scale the neck is a valley.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"
#include "tracking/tracker.h"

namespace vs {
namespace {

// Spacing 0.6 x 0.6 x 1.2 mm. A (radius 1.8 mm) along x at z 4.5; B (1.8 mm) above it at z 8.5 (a gap of
// 1.2 mm, 2 in-plane voxels, from the middle of slice 6 to the middle of slice 7: those are half A, half B, no
// slice is tissue) except over x 24-64, where B bows up by up to 6 mm, away from A (the family's bend out).
constexpr double kY = 8, kAz = 4.5, kBz = 8.5, kR = 1.8;

double bZ(double x) {  // B's axis (slices)
  if (x < 24 || x > 64) return kBz;
  return kBz + 2.5 * (1 - std::cos(2 * M_PI * (x - 24) / 40));
}

VolumeF32 neckTubes(uint64_t seed) {
  Geometry g;
  g.dims = {90, 16, 18};
  g.spacing = Vec3(0.6, 0.6, 1.2);
  VolumeF32 v(g);
  PhantomRng rng(seed);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        double sum = 0;  // partial volume: 3 x 3 x 5 sub-samples
        for (int i = -1; i <= 1; ++i)
          for (int j = -1; j <= 1; ++j)
            for (int k = -2; k <= 2; ++k) {
              const double px = double(x) + i / 3.0, py = double(y) + j / 3.0, pz = double(z) + k / 5.0;
              const double dy = (py - kY) * 0.6, da = (pz - kAz) * 1.2, db = (pz - bZ(px)) * 1.2;  // mm
              bool in = px >= 3 && px <= 12 && std::abs(dy) <= kR && pz >= kAz && pz <= kBz;       // trunk
              in = in || (px >= 3 && px <= 86 && (std::hypot(dy, da) <= kR || std::hypot(dy, db) <= kR));
              sum += in ? 200 : 30;
            }
        v(x, y, z) = static_cast<float>(sum / 45 + rng.normal(0, 6));
      }
  return v;
}

TEST(ThinNeck, TheNeckBetweenTubesUnderASliceApartIsNoLumen) {
  const VolumeF32 v = neckTubes(3);
  const AutoCost ac = computeAutoCost(v, {7, 8, 7});
  const double lumen = lumenCostThreshold(ac.cost);
  // Where the tubes run a slice apart: the neck's two slices (z 6, 7) between A's axis (4.5) and B's (8.5).
  int dear = 0, n = 0;
  for (int64_t x : {16, 18, 20, 70, 74, 78, 82})
    for (int64_t z = 6; z <= 7; ++z, ++n) {
      const double c = ac.cost.node[static_cast<size_t>(ac.cost.geometry.linear(x, 8, z))];
      dear += c > lumen;
    }
  EXPECT_GE(dear, n / 2) << "the neck's voxels: at least one slice of the two is no lumen (0 before)";
  // Along the axes: lumen.
  for (int64_t x = 16; x <= 82; x += 6)
    EXPECT_LE(ac.cost.node[static_cast<size_t>(ac.cost.geometry.linear(x, 8, 4))], lumen) << "A's axis, x " << x;
}

}  // namespace
}  // namespace vs
