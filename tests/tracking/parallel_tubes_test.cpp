// Two parallel tubes a few voxels apart (issue 21, the family's parallel variant; docs/notes/tracking.md
// session 17 par1): a thin tube A fading to half its contrast along its middle beside a wide bright tube B,
// both from one trunk, in a volume they fill much of. The 8 mm blocks of the local background hold both
// tubes and their partial-volume walls beyond the percentile, so without the cap on a block's value
// (AutoCostOptions::localTailCap) A's faded middle had no contrast against its "surroundings" and the path to
// A's end ran along B and jumped the gap to A near the end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"
#include "tracking/trace_run.h"
#include "tracking/tracker.h"

namespace vs {
namespace {

// In voxels; spacing 0.7 x 0.7 x 1.7 mm (coarse slices, as the family's parallel seeds): A (radius 1 mm) and B
// (2.4 mm) along x, one above the other in z, 6 mm apart (a gap of 2.6 mm, 1.5 slices).
constexpr double kY = 8, kAz = 5, kBz = 8.5, kRa = 1.0, kRb = 2.4;

// A's value along x (voxels): 200 at the trunk, faded to 72 over x 34-70, 200 again from x 76 (its end's target).
double aValue(double x) {
  if (x < 24) return 200;
  if (x < 34) return 200 - 128 * (x - 24) / 10;
  if (x < 70) return 72;
  if (x < 76) return 72 + 128 * (x - 70) / 6;
  return 200;
}

VolumeF32 parallelTubes(uint64_t seed) {
  Geometry g;
  g.dims = {90, 16, 14};
  g.spacing = Vec3(0.7, 0.7, 1.7);
  VolumeF32 v(g);
  PhantomRng rng(seed);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        double sum = 0;  // partial volume: 3 x 3 x 3 sub-samples
        for (int i = -1; i <= 1; ++i)
          for (int j = -1; j <= 1; ++j)
            for (int k = -1; k <= 1; ++k) {
              const double px = double(x) + i / 3.0, py = double(y) + j / 3.0, pz = double(z) + k / 3.0;
              const double dy = (py - kY) * 0.7, da = (pz - kAz) * 1.7, db = (pz - kBz) * 1.7;  // mm
              double val = 30;
              if (px >= 3 && px <= 12 && std::abs(dy) <= kRb && pz >= kAz && pz <= kBz) val = 200;  // trunk
              if (px >= 3 && px <= 86 && std::hypot(dy, db) <= kRb) val = 200;
              if (px >= 3 && px <= 86 && std::hypot(dy, da) <= kRa) val = std::max(val, aValue(px));
              sum += val;
            }
        v(x, y, z) = static_cast<float>(sum / 27 + rng.normal(0, 4));
      }
  return v;
}

double costAt(const AutoCost& ac, int64_t x, int64_t y, int64_t z) {
  return ac.cost.node[static_cast<size_t>(ac.cost.geometry.linear(x, y, z))];
}

TEST(ParallelTubes, AFadedTubeBesideAWideOneIsLumenAgainstTheTissueNotTheirWalls) {
  const VolumeF32 v = parallelTubes(5);
  const Index3 root{7, 8, 7};
  const AutoCost ac = computeAutoCost(v, root);
  const double lumen = lumenCostThreshold(ac.cost);
  AutoCostOptions uncapped;
  uncapped.localTailCap = 0;
  const AutoCost before = computeAutoCost(v, root, uncapped);
  double faded = 0, fadedBefore = 0;
  for (int64_t x = 36; x <= 68; ++x) {
    EXPECT_LE(costAt(ac, x, 8, 5), lumen)
        << "A's faded middle, x " << x << ": "
        << localContrastAt(ac.smoothed, ac.background, ac.estimate, {x, 8, 5}).describe(ac.estimate);
    EXPECT_GT(costAt(ac, x, 8, 6), 0.9) << "the gap between them, x " << x;  // nor is the gap lumen
    faded += costAt(ac, x, 8, 5), fadedBefore += costAt(before, x, 8, 5);
  }
  EXPECT_LT(faded, 1.5) << fadedBefore;  // 33 voxels (0.77; uncapped 10.3)
  EXPECT_GT(fadedBefore, 5.0) << "without the cap the faded middle was expensive";
  const LocalContrast mid = localContrastAt(ac.smoothed, ac.background, ac.estimate, {50, 8, 5});
  EXPECT_LT(mid.background, 60) << mid.describe(ac.estimate);  // the tissue's 30, not the walls'
}

TEST(ParallelTubes, ThePathToTheFadedTubesEndStaysInIt) {
  const VolumeF32 v = parallelTubes(5);
  TraceRequest rq;
  rq.root = {7, 8, 7};
  rq.targets = {Index3{84, 8, 5}};
  const auto offA = [](const TraceResult& r) {
    size_t off = 0;  // path voxels in the middle nearer B's axis than A's
    for (const Index3& p : r.paths.at(0).voxels)
      if (p[0] >= 24 && p[0] <= 74 && std::abs(double(p[2]) - kAz) > std::abs(double(p[2]) - kBz)) ++off;
    return off;
  };
  const TraceResult r = runTrace(v, rq);
  ASSERT_EQ(r.paths.size(), 1u);
  EXPECT_TRUE(r.paths[0].reached);
  EXPECT_EQ(offA(r), 0u);
  for (const Vec3& q : r.points[0]) {
    if (q[0] >= 24 && q[0] <= 74) {
      EXPECT_LT(std::hypot((q[1] - kY) * 0.7, (q[2] - kAz) * 1.7), 0.7) << q.transpose();
    }
  }
  rq.options.autoCost.localTailCap = 0;
  const TraceResult uncapped = runTrace(v, rq);
  EXPECT_GT(offA(uncapped), 10u) << "without the cap the path ran along B";
}

}  // namespace
}  // namespace vs
