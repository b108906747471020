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
#include <vector>

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

// Session 20 par4 (docs/notes/tracking.md): the family's seed 10311 in small, 0.98 x 0.98 x 2.41 mm: A (radius 1.4
// mm, 0.6 slice) faded along its middle, one slice-gap above B (3 mm), both along x. Every 8 mm block around A's
// faded part holds both tubes and their walls, so its block background is the pair's (far above the tissue's 33) and
// A cost the most there; in its own slice, 4 mm beside it, lies tissue (the in-plane ring).
constexpr double kSp = 0.98, kSz = 2.41, kY2 = 12, kAz2 = 9.0, kBz2 = 6.5, kRa2 = 1.4, kRb2 = 3.0;

VolumeF32 slicePair(uint64_t seed) {
  Geometry g;
  g.dims = {90, 24, 14};
  g.spacing = Vec3(kSp, kSp, kSz);
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
              const double dy = (py - kY2) * kSp, da = (pz - kAz2) * kSz, db = (pz - kBz2) * kSz;  // mm
              double val = 33;
              if (px >= 3 && px <= 12 && std::abs(dy) <= kRb2 && pz >= kBz2 && pz <= kAz2) val = 200;  // trunk
              if (px >= 3 && px <= 86 && std::hypot(dy, db) <= kRb2) val = 200;
              if (px >= 3 && px <= 86 && std::hypot(dy, da) <= kRa2) val = std::max(val, aValue(px) * 0.85);
              sum += val;
            }
        v(x, y, z) = static_cast<float>(sum / 27 + rng.normal(0, 6));
      }
  return v;
}

TEST(ParallelTubes, AFadedTubeOneSliceBesideAWideOneIsLumenAgainstItsOwnSlice) {
  const VolumeF32 v = slicePair(7);
  const Index3 root{7, 12, 7};
  const AutoCost ac = computeAutoCost(v, root);
  ASSERT_EQ(ac.background.planeRings.size(), 1u);
  EXPECT_EQ(ac.background.planeRings[0].count, 4);  // x, y, xy, x-y: none along the coarse z
  const double lumen = lumenCostThreshold(ac.cost);
  AutoCostOptions noPlane;
  noPlane.planeRingVoxels = 0;
  const AutoCost before = computeAutoCost(v, root, noPlane);
  double faded = 0, fadedBefore = 0;
  for (int64_t x = 36; x <= 68; ++x) {
    faded += costAt(ac, x, 12, 9), fadedBefore += costAt(before, x, 12, 9);
    EXPECT_GT(costAt(ac, x, 4, 9), 0.9) << "tissue beside A, x " << x;
    EXPECT_GT(costAt(ac, x, 12, 12), 0.9) << "tissue above A, x " << x;
  }
  EXPECT_LT(faded, 0.5 * fadedBefore)
      << faded << " against " << fadedBefore << "; "
      << localContrastAt(ac.smoothed, ac.background, ac.estimate, {50, 12, 9}).describe(ac.estimate);
  // In an isotropic volume there is no in-plane ring.
  Geometry iso;
  iso.dims = {8, 8, 8};
  EXPECT_TRUE(planeRingFor(iso, 4, 1.5).empty());
  iso.spacing = Vec3(2.0, 0.8, 0.8);  // x coarse: the plane is y, z (y, z, yz, y-z)
  const std::vector<RingScale> px = planeRingFor(iso, 4, 1.5);
  ASSERT_EQ(px.size(), 1u);
  EXPECT_EQ(px[0].count, 4);
  for (int j = 0; j < px[0].count; ++j) EXPECT_EQ(px[0].offset[static_cast<size_t>(j)][0], 0);
}

}  // namespace
}  // namespace vs
