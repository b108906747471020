// The surface policy (surface/surface_policy.h), applied by the extraction itself so every front
// end keeps and refuses the same meshes: degenerate triangles are repaired (issue 22: a closed
// 128^3 sphere at level 5, and --every-voxel at level 4, failed on slivers), folds are refused
// unless allowed.
#include "surface/surface_policy.h"

#include <gtest/gtest.h>

#include "shapes.h"
#include "surface/mesh_quality.h"
#include "surface/surface.h"
#include "util/error.h"

namespace vs {
namespace {

// A plain 128^3 sphere of radius 40 voxels: a binary 0/200 step (no partial volume), where vertex
// refinement puts neighbouring vertices on the same point.
VolumeF32 binarySphere() {
  VolumeF32 v(test::cube(128));
  for (int64_t z = 0; z < 128; ++z)
    for (int64_t y = 0; y < 128; ++y)
      for (int64_t x = 0; x < 128; ++x)
        v(x, y, z) = (Vec3(double(x), double(y), double(z)) - Vec3(64, 64, 64)).norm() < 40 ? 200.0f : 0.0f;
  return v;
}

TEST(SurfacePolicy, BinarySphereLevel5IsRepairedAndWatertight) {
  const VolumeF32 v = binarySphere();
  SurfaceOptions o;
  o.planes = {64, 64, 64};
  o.level = 5;
  o.closed = true;
  const SurfaceResult r = extractSurface(v, o);
  EXPECT_GT(r.repairedTriangles, 0);  // the slivers that failed the whole surface before
  EXPECT_TRUE(r.topology.watertight());
  EXPECT_EQ(r.topology.eulerCharacteristic(), 2);
  EXPECT_EQ(r.topology.components, 1);
  // The result's topology is the mesh's (nothing stale), and every vertex is used.
  const MeshTopology t = analyzeTopology(r.mesh);
  EXPECT_TRUE(t.watertight());
  EXPECT_EQ(t.vertices, static_cast<int64_t>(r.mesh.positions.size()));
  EXPECT_EQ(r.mesh.normals.size(), r.mesh.positions.size());
  EXPECT_EQ(r.vertexVoxels.size(), r.mesh.positions.size());
  // Still a sphere of radius 40 (the binary step is between 39.5 and 40.5 voxels).
  for (const Vec3& p : r.mesh.positions) EXPECT_NEAR((p - Vec3(64, 64, 64)).norm(), 40.0, 1.5);
}

TEST(SurfacePolicy, EveryPathVoxelLevel4IsWatertight) {
  const VolumeF32 v = test::makeStarVolume(test::cube(128), Vec3(64, 64, 64), [](const Vec3&) { return 40.0; });
  SurfaceOptions o;
  o.planes = {64, 64, 64};
  o.level = 4;
  o.closed = true;
  o.everyPathVoxel = true;
  o.iso = 500;
  const SurfaceResult r = extractSurface(v, o);
  EXPECT_GT(r.repairedTriangles, 0);  // slivers that made edges non-manifold before
  EXPECT_TRUE(r.topology.watertight());
  EXPECT_EQ(r.topology.eulerCharacteristic(), 2);
  EXPECT_TRUE(analyzeTopology(r.mesh).watertight());
}

// A ball with a mushroom (an overhang) in octant +x+y+z: refused by default, naming that octant
// alone; kept with allowFolds, the report marking it.
TEST(SurfacePolicy, FoldsAreRefusedUnlessAllowed) {
  const Vec3 c(31, 32, 30);
  const VolumeF32 v = test::makeImplicitVolume(test::cube(64), test::mushroomBall(c, 20, Vec3(1, 1, 1).normalized()));
  SurfaceOptions o;
  o.planes = {31, 32, 30};
  o.iso = 500;
  o.level = 3;
  o.closed = true;
  try {
    extractSurface(v, o);
    ADD_FAILURE() << "a folded octant was accepted";
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("folds back over itself along rays from the centre in octant +x+y+z ("), std::string::npos)
        << what;
    EXPECT_EQ(what.find("-x"), std::string::npos) << what;
  }
  o.allowFolds = true;
  const SurfaceResult r = extractSurface(v, o);
  EXPECT_TRUE(r.topology.watertight());
  EXPECT_EQ(foldedOctantsText(r).rfind("+x+y+z (", 0), 0u) << foldedOctantsText(r);
}

}  // namespace
}  // namespace vs
