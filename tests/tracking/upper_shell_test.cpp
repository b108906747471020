// upperShell (auto_cost_upper.cpp) against a plain per-voxel reference on random volumes with NaNs, both
// polarities, odd sizes and volumes one voxel thick: the shell is the voxels beside a value beyond the upper edge's far
// end (their 3x3x3 neighbourhood, cut at the volume's faces), not beyond it themselves, whose neighbourhood also holds
// background (beyond the window's far edge). Such a voxel's test value (the neighbourhood's most lumen-beyond value,
// which the edge tested before the shell was a byte) is beyond the far end as a float and as a double, so the upper
// edge's cap is 0 there: the byte says all that value did.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"

namespace vs {
namespace {

struct Reference {
  std::vector<uint8_t> shell;
  std::vector<float> value;  // the shell voxel's test value: its neighbourhood's most lumen-beyond one
};

Reference reference(const VolumeF32& v, const LumenEstimate& e) {
  const Geometry& g = v.geometry();
  const bool bright = e.polarity == TubePolarity::Bright;
  const float hi = static_cast<float>(e.upperHi), bg = static_cast<float>(bright ? e.windowLo : e.windowHi);
  auto beyond = [&](float x) { return bright ? x > hi : x < hi; };
  Reference r;
  r.shell.assign(static_cast<size_t>(g.voxelCount()), 0);
  r.value.assign(r.shell.size(), 0);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const float own = v(x, y, z);
        bool beside = false;
        float most = own, least = own;
        for (int64_t dz = -1; dz <= 1; ++dz)
          for (int64_t dy = -1; dy <= 1; ++dy)
            for (int64_t dx = -1; dx <= 1; ++dx) {
              if (!g.contains({x + dx, y + dy, z + dz})) continue;
              const float w = v(x + dx, y + dy, z + dz);
              beside = beside || beyond(w);
              most = bright ? std::max(most, w) : std::min(most, w);
              least = bright ? std::min(least, w) : std::max(least, w);
            }
        if (beside && !beyond(own) && (bright ? least < bg : least > bg)) {
          r.shell[static_cast<size_t>(g.linear(x, y, z))] = 1;
          r.value[static_cast<size_t>(g.linear(x, y, z))] = most;
        }
      }
  return r;
}

// Tissue 0..100, lumen ~200, a far end from 330 (dark: the mirror image); a far end no float equals: its float
// rounds one way, the tests compare both ways.
LumenEstimate shellEstimate(bool bright) {
  LumenEstimate e;
  e.polarity = bright ? TubePolarity::Bright : TubePolarity::Dark;
  e.lumen = bright ? 200 : 800;
  e.windowLo = bright ? 120 : 700;
  e.windowHi = bright ? 300 : 880;
  e.upperFraction = 1;
  e.upperLo = bright ? 330.1 : 669.9;
  e.upperHi = bright ? 380.3 : 619.7;
  return e;
}

TEST(UpperShell, EqualsAPlainNeighbourhoodReferenceAndTestsBeyondTheFarEnd) {
  const Index3 sizes[] = {{23, 17, 11}, {9, 31, 1}, {1, 5, 7}, {2, 2, 2}, {40, 3, 9}, {1, 1, 6}};
  uint64_t seed = 11;
  int64_t shellVoxels = 0;
  for (const Index3& dims : sizes)
    for (const TubePolarity pol : {TubePolarity::Bright, TubePolarity::Dark}) {
      Geometry g;
      g.dims = dims;
      VolumeF32 v(g);
      PhantomRng rng(seed++);
      const bool bright = pol == TubePolarity::Bright;
      // Tissue 0..100, lumen ~200, bone beyond 400 (dark: the mirror image), in random patches; a few NaNs.
      for (int64_t i = 0; i < g.voxelCount(); ++i) {
        const double u = rng.uniform(0, 1);
        const double val = u < 0.5 ? rng.uniform(0, 100) : u < 0.85 ? rng.uniform(150, 300) : rng.uniform(400, 900);
        v.data()[i] =
            u > 0.98 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(bright ? val : 1000 - val);
      }
      const LumenEstimate e = shellEstimate(bright);
      ASSERT_TRUE(e.hasUpperEdge());
      const std::vector<uint8_t> got = upperShell(v, e);
      const Reference want = reference(v, e);
      ASSERT_EQ(got.size(), want.shell.size());
      for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i], want.shell[i]) << "voxel " << i << " of " << dims[0] << "x" << dims[1] << "x" << dims[2]
                                         << (bright ? " bright" : " dark");
        if (!want.shell[i]) continue;
        ++shellVoxels;
        const float t = want.value[i];
        EXPECT_TRUE(bright ? t > static_cast<float>(e.upperHi) : t < static_cast<float>(e.upperHi));
        EXPECT_TRUE(bright ? t > e.upperHi : t < e.upperHi);
        EXPECT_EQ(e.upperCap(t), 0.0);
      }
    }
  EXPECT_GT(shellVoxels, 100);  // the shell rule was exercised
}

// Session 47 speed2: slices with no value beyond the far end in them or beside them are left 0 unread - the shell
// must still equal the reference where the beyond values lie in a few slices only (first, last, middle, none).
TEST(UpperShell, EqualsTheReferenceWithBeyondValuesInFewSlices) {
  const Index3 sizes[] = {{13, 9, 12}, {7, 5, 1}, {6, 8, 2}, {11, 4, 25}};
  uint64_t seed = 4701;
  int64_t shellVoxels = 0;
  for (const Index3& dims : sizes)
    for (const TubePolarity pol : {TubePolarity::Bright, TubePolarity::Dark})
      for (int pattern = 0; pattern < 4; ++pattern) {
        Geometry g;
        g.dims = dims;
        VolumeF32 v(g);
        PhantomRng rng(seed++);
        const bool bright = pol == TubePolarity::Bright;
        const int64_t nz = dims[2];
        // The slices that may hold bone: pattern 0 none, 1 the first and last, 2 one in the middle, 3 every fifth.
        const auto boneSlice = [&](int64_t z) {
          return pattern == 1 ? (z == 0 || z == nz - 1) : pattern == 2 ? z == nz / 2 : pattern == 3 && z % 5 == 2;
        };
        for (int64_t z = 0; z < nz; ++z)
          for (int64_t i = 0; i < dims[0] * dims[1]; ++i) {
            const double u = rng.uniform(0, 1);
            const double val = u < 0.5                    ? rng.uniform(0, 100)
                               : u < 0.8 || !boneSlice(z) ? rng.uniform(150, 300)
                                                          : rng.uniform(400, 900);
            v.data()[z * dims[0] * dims[1] + i] =
                u > 0.98 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(bright ? val : 1000 - val);
          }
        const LumenEstimate e = shellEstimate(bright);
        const std::vector<uint8_t> got = upperShell(v, e);
        const Reference want = reference(v, e);
        ASSERT_EQ(got.size(), want.shell.size());
        for (size_t i = 0; i < got.size(); ++i) {
          ASSERT_EQ(got[i], want.shell[i]) << "voxel " << i << " pattern " << pattern << (bright ? " bright" : " dark");
          shellVoxels += want.shell[i];
        }
      }
  EXPECT_GT(shellVoxels, 100);
}

}  // namespace
}  // namespace vs
