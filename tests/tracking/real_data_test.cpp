// Airway tracking on real data (thesis 4.3.2, Figure 36): the chest CTA of ../shared/data,
// one root in the trachea, six distal bronchus targets picked by inspection (interior voxels of
// the < -900 HU component connected to the trachea, see docs/notes/tracking.md). Evidence that
// the paths stay inside the airway lumen: every path voxel is air (< -900 HU) and the mean HU on
// the paths is far below the mean of a shell 3-4 voxels around them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "cost/cost3d.h"
#include "io/volume_io.h"
#include "tracking/tracker.h"

namespace vs {
namespace {

TEST(RealAirways, ChestCtaPathsStayInTheLumen) {
  const std::string path = std::string(VS_SHARED_DATA_DIR) + "/chest_cta_totalseg/ct_cropped.nii.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data missing: " << path;
  const VolumeF32 ct = toFloat(readVolume(path));
  Cost3DOptions co;
  co.kind = CostKind3D::Intensity;
  co.polarity = TubePolarity::Dark;
  co.windowLo = -1000;
  co.windowHi = -800;
  const NodeCost3D cost = computeNodeCost3D(ct, co);
  VesselTracker tracker(ct, cost, {46, 59, 150});
  const std::vector<Index3> targets = {{15, 81, 86}, {77, 87, 87},  {12, 86, 79},
                                       {79, 90, 80}, {14, 53, 113}, {86, 67, 109}};
  const auto& g = ct.geometry();
  for (const Index3& t : targets) {
    const TracedPath& p = tracker.addTarget(t);
    ASSERT_TRUE(p.reached) << t[0] << "," << t[1] << "," << t[2];
    EXPECT_GT(p.lengthMm, 80.0);  // trachea to a lobar/segmental bronchus
    double onPath = 0, shell = 0;
    int64_t shellCount = 0;
    for (const Index3& v : p.voxels) {
      const float hu = ct(v[0], v[1], v[2]);
      EXPECT_LT(hu, -900.0f) << "path voxel " << v[0] << "," << v[1] << "," << v[2] << " is not air";
      onPath += hu;
      // Shell: voxels at chessboard distance 3-4 along the axes and diagonals.
      for (int dz = -4; dz <= 4; dz += 4)
        for (int dy = -4; dy <= 4; dy += 4)
          for (int dx = -4; dx <= 4; dx += 4) {
            if (dx == 0 && dy == 0 && dz == 0) continue;
            const int64_t x = v[0] + dx, y = v[1] + dy, z = v[2] + dz;
            if (!g.contains(x, y, z)) continue;
            shell += ct(x, y, z);
            ++shellCount;
          }
    }
    onPath /= static_cast<double>(p.voxels.size());
    shell /= static_cast<double>(std::max<int64_t>(1, shellCount));
    EXPECT_LT(onPath, -950.0);
    EXPECT_GT(shell - onPath, 250.0) << "path mean " << onPath << " HU vs shell " << shell << " HU";
  }
  // Six bronchi off one trachea: the tree of extracted paths branches.
  EXPECT_GE(tracker.branchPoints().size(), 3u);
}

}  // namespace
}  // namespace vs
