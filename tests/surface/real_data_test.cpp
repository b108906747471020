// Accuracy on real heads (issue 15): one octant's skin at level 4 against vtkFlyingEdges3D of the
// same iso-value (meshops), both ways, in voxels of the finest spacing; and against the
// geometry-only baseline (the same three contours without the image). Skips without ../shared/data.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/volume_io.h"
#include "meshops/isosurface.h"
#include "surface/mesh_quality.h"
#include "surface/surface.h"

namespace vs {
namespace {

struct Case {
  const char* file;
  double iso;
  Index3 planes;
  const char* octant;
};

class SurfaceRealData : public ::testing::TestWithParam<Case> {};

TEST_P(SurfaceRealData, Level4WithinHalfAVoxelAndFiveTimesBetterThanGeometry) {
  const Case c = GetParam();
  const std::string path = std::string(VS_SHARED_DATA_DIR) + "/" + c.file;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing (../shared/data not available)";
  const VolumeF32 v = toFloat(readVolume(path));
  const double h = v.geometry().spacing.minCoeff();
  IsoSurfaceOptions io;
  io.iso = c.iso;
  io.largestComponentOnly = false;
  const TriMesh ref = extractIsoSurface(v, io);
  const OctantSigns oct = parseOctant(c.octant);
  const Vec3 center(double(c.planes[0]), double(c.planes[1]), double(c.planes[2]));
  const std::vector<Vec3> refPts = outermostInOctant(ref, v, c.iso, center, oct);
  ASSERT_GT(refPts.size(), 1000u);
  const MeshDistance toRef(ref);
  double mean[2] = {0, 0};
  for (int base = 0; base < 2; ++base) {
    SurfaceOptions o;
    o.planes = c.planes;
    o.iso = c.iso;
    o.level = 4;
    o.octant = oct;
    o.geometryOnly = base == 1;
    const SurfaceResult r = extractSurface(v, o);
    const MeshTopology t = analyzeTopology(r.mesh, 1e-9);
    EXPECT_TRUE(t.valid());
    EXPECT_EQ(t.eulerCharacteristic(), 1);
    EXPECT_EQ(t.faces, 256);
    std::vector<double> a = toRef.distances(sampleMesh(r.mesh, h / 2)), b = MeshDistance(r.mesh).distances(refPts);
    for (double& x : a) x /= h;
    for (double& x : b) x /= h;
    const DistanceSummary da = summarize(a), db = summarize(b);
    mean[base] = da.mean + db.mean;
    if (base == 0) {
      EXPECT_LE(da.mean, 0.5);
      EXPECT_LE(da.p95, 1.0);
      EXPECT_LE(db.mean, 0.5);
      EXPECT_LE(db.p95, 1.0);
      EXPECT_FALSE(r.octants[0].folded);
    }
  }
  EXPECT_GE(mean[1], 5 * mean[0]) << "image-driven " << mean[0] << ", geometry only " << mean[1];
}

// The head CT's octant -x-y+z: rays that leave the back of the head cross air and meet the head
// holder (a separate shell near y = 0): counted as another object, not a fold of the skin.
TEST(SurfaceRealDataFold, HeadHolderIsNotAFold) {
  const std::string path = std::string(VS_SHARED_DATA_DIR) + "/head_ct_cranium_invesalius/cranium.nhdr";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing (../shared/data not available)";
  const VolumeF32 v = toFloat(readVolume(path));
  SurfaceOptions o;
  o.planes = {128, 128, 54};
  o.iso = -403.28;
  o.level = 4;
  o.octant = parseOctant("-x-y+z");
  const SurfaceResult r = extractSurface(v, o);
  const OctantReport& rep = r.octants[0];
  EXPECT_FALSE(rep.folded);
  EXPECT_EQ(rep.foldedRays, 0);
  EXPECT_GT(rep.otherObjectRays, rep.foldCheckRays / 20) << rep.otherObjectRays << " of " << rep.foldCheckRays;
}

INSTANTIATE_TEST_SUITE_P(
    Heads, SurfaceRealData,
    ::testing::Values(Case{"head_ct_cranium_invesalius/cranium.nhdr", -403.28, {128, 128, 54}, "+x+y+z"},
                      Case{"head_mr_t1_face/chris_t1.nii.gz", 55.66, {94, 128, 95}, "+x+y+z"}));

}  // namespace
}  // namespace vs
