// upperTestValues (auto_cost_upper.cpp) against a plain per-voxel reference on random volumes, both polarities, odd
// sizes and a volume one voxel thick: a voxel beside a value beyond the upper edge's far end (its 3x3x3
// neighbourhood, cut at the volume's faces), itself not beyond it, whose neighbourhood also holds background (beyond
// the window's far edge) tests the neighbourhood's most lumen-beyond value; every other voxel its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"

namespace vs {
namespace {

VolumeF32 reference(const VolumeF32& v, const LumenEstimate& e) {
  const Geometry& g = v.geometry();
  const bool bright = e.polarity == TubePolarity::Bright;
  const float hi = static_cast<float>(e.upperHi), bg = static_cast<float>(bright ? e.windowLo : e.windowHi);
  auto beyond = [&](float x) { return bright ? x > hi : x < hi; };
  VolumeF32 out = v;
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
        if (beside && !beyond(own) && (bright ? least < bg : least > bg)) out(x, y, z) = most;
      }
  return out;
}

TEST(UpperTestValues, EqualAPlainNeighbourhoodReference) {
  const Index3 sizes[] = {{23, 17, 11}, {9, 31, 1}, {1, 5, 7}, {2, 2, 2}};
  uint64_t seed = 11;
  for (const Index3& dims : sizes)
    for (const TubePolarity pol : {TubePolarity::Bright, TubePolarity::Dark}) {
      Geometry g;
      g.dims = dims;
      VolumeF32 v(g);
      PhantomRng rng(seed++);
      const bool bright = pol == TubePolarity::Bright;
      // Tissue 0..100, lumen ~200, bone beyond 400 (dark: the mirror image), in random patches.
      for (int64_t i = 0; i < g.voxelCount(); ++i) {
        const double u = rng.uniform(0, 1);
        const double val = u < 0.5 ? rng.uniform(0, 100) : u < 0.85 ? rng.uniform(150, 300) : rng.uniform(400, 900);
        v.data()[i] = static_cast<float>(bright ? val : 1000 - val);
      }
      LumenEstimate e;
      e.polarity = pol;
      e.lumen = bright ? 200 : 800;
      e.windowLo = bright ? 120 : 700;
      e.windowHi = bright ? 300 : 880;
      e.upperFraction = 1;
      e.upperLo = bright ? 330 : 670;
      e.upperHi = bright ? 380 : 620;
      ASSERT_TRUE(e.hasUpperEdge());
      const VolumeF32 got = upperTestValues(v, e), want = reference(v, e);
      int64_t changed = 0;
      for (int64_t i = 0; i < g.voxelCount(); ++i) {
        ASSERT_EQ(got.data()[i], want.data()[i])
            << "voxel " << i << " of " << dims[0] << "x" << dims[1] << "x" << dims[2] << (bright ? " bright" : " dark");
        changed += want.data()[i] != v.data()[i];
      }
      if (g.voxelCount() > 100) {
        EXPECT_GT(changed, 0);  // the shell rule was exercised
      }
    }
}

}  // namespace
}  // namespace vs
