// Frangi vesselness (features/vesselness.h): eigenvalues, tube vs. blob vs. plate, polarity,
// anisotropic spacing.
#include "features/vesselness.h"

#include <gtest/gtest.h>

#include <cmath>

#include "volume/crop.h"

namespace vs {
namespace {

TEST(Vesselness, EigenvaluesOfKnownMatrices) {
  double l[3];
  symmetricEigenvalues3(3, -1, 0.5, 0, 0, 0, l);
  EXPECT_NEAR(l[0], 0.5, 1e-12);
  EXPECT_NEAR(l[1], -1, 1e-12);
  EXPECT_NEAR(l[2], 3, 1e-12);
  // [[2,1,0],[1,2,0],[0,0,5]] -> 1, 3, 5
  symmetricEigenvalues3(2, 2, 5, 1, 0, 0, l);
  EXPECT_NEAR(l[0], 1, 1e-9);
  EXPECT_NEAR(l[1], 3, 1e-9);
  EXPECT_NEAR(l[2], 5, 1e-9);
}

// A Gaussian-profile bright tube along x (radius ~2 mm), a blob, and a plate.
VolumeF32 scene(Vec3 spacing, bool tube, bool blob, bool plate) {
  Geometry g;
  g.dims = {40, 40, 40};
  g.spacing = spacing;
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < 40; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 40; ++x) {
        const double X = x * spacing[0], Y = y * spacing[1], Z = z * spacing[2];
        const double cy = 20 * spacing[1], cz = 20 * spacing[2];
        double val = 0;
        if (tube) val += 100 * std::exp(-((Y - cy) * (Y - cy) + (Z - cz) * (Z - cz)) / (2 * 2.0 * 2.0));
        if (blob) val += 100 * std::exp(-((X - cy) * (X - cy) + (Y - cy) * (Y - cy) + (Z - cz) * (Z - cz)) / 8.0);
        if (plate) val += 100 * std::exp(-((Z - cz) * (Z - cz)) / 8.0);
        v(x, y, z) = static_cast<float>(val);
      }
  return v;
}

TEST(Vesselness, TubeBeatsBlobAndPlateAndPolarityMatters) {
  VesselnessOptions o;
  o.scalesMm = {1.5, 2.0, 3.0};
  o.c = 10;  // fixed structureness scale so the three scenes compare on one scale
  const auto tube = computeVesselness(scene(Vec3(1, 1, 1), true, false, false), o);
  const auto blob = computeVesselness(scene(Vec3(1, 1, 1), false, true, false), o);
  const auto plate = computeVesselness(scene(Vec3(1, 1, 1), false, false, true), o);
  Geometry g;
  g.dims = {40, 40, 40};
  const size_t c = static_cast<size_t>(g.linear(20, 20, 20));
  EXPECT_GT(tube[c], 0.5f);
  EXPECT_LT(blob[c], 0.5f * tube[c]);
  EXPECT_LT(plate[c], 0.5f * tube[c]);
  // Off the tube, the response falls.
  EXPECT_LT(tube[static_cast<size_t>(g.linear(20, 30, 20))], 0.1f * tube[c]);
  o.polarity = TubePolarity::Dark;
  const auto dark = computeVesselness(scene(Vec3(1, 1, 1), true, false, false), o);
  EXPECT_EQ(dark[c], 0.0f);
}

TEST(Vesselness, AnisotropicSpacingKeepsTheTube) {
  VesselnessOptions o;
  o.scalesMm = {2.0};
  const auto v = computeVesselness(scene(Vec3(0.8, 0.8, 1.6), true, false, false), o);
  Geometry g;
  g.dims = {40, 40, 40};
  const size_t centre = static_cast<size_t>(g.linear(20, 20, 20));
  EXPECT_GT(v[centre], 0.3f);
  EXPECT_GT(v[centre], 5 * v[static_cast<size_t>(g.linear(20, 20, 27))]);
}

TEST(Vesselness, SmoothingPreservesMeanAndRejectsBadScales) {
  Geometry g;
  g.dims = {10, 10, 10};
  VolumeF32 v(g, 5.0f);
  const VolumeF32 s = gaussianSmooth3D(v, 2.0);
  for (float x : s.voxels()) EXPECT_NEAR(x, 5.0f, 1e-4);
  VesselnessOptions o;
  o.scalesMm = {-1};
  EXPECT_THROW(computeVesselness(v, o), InvalidArgument);
}

// Block by block (the Dask pyramid, issue 25): a block read with vesselnessHaloVoxels of context
// (none beyond the volume's faces) gives the whole volume's floats inside, given the whole volume's
// c per scale, and the maximum of the blocks' own c is the whole volume's.
TEST(Vesselness, BlocksWithTheirHaloEqualTheWholeVolume) {
  VolumeF32 vol = scene(Vec3(0.5, 0.5, 1.5), true, true, false);
  uint32_t state = 12345;  // a fixed speckle, so that no voxel is flat
  for (float& v : vol.voxels()) {
    state = state * 1664525u + 1013904223u;
    v += static_cast<float>(state >> 8) / static_cast<float>(1u << 24) * 20.0f;
  }
  VesselnessOptions o;
  o.scalesMm = {0.5, 1.0, 1.5};
  const std::vector<float> whole = computeVesselness(vol, o);
  const std::vector<double> c = vesselnessStructureScale(vol, o);
  const int halo = vesselnessHaloVoxels(vol.geometry(), o);
  EXPECT_EQ(halo, 10);  // ceil(3 x 1.5 / 0.5) + 1
  const Geometry& g = vol.geometry();
  const int64_t B = 16;
  std::vector<double> cMax(c.size(), 0.0);
  int blocks = 0;
  for (int64_t z = 0; z < g.dims[2]; z += B)
    for (int64_t y = 0; y < g.dims[1]; y += B)
      for (int64_t x = 0; x < g.dims[0]; x += B) {
        const Index3 lo{x, y, z},
            hi{std::min(x + B, g.dims[0]), std::min(y + B, g.dims[1]), std::min(z + B, g.dims[2])};
        VoxelBox read;
        for (int a = 0; a < 3; ++a) {
          read.lo[a] = std::max<int64_t>(0, lo[a] - halo);
          read.hi[a] = std::min<int64_t>(g.dims[a] - 1, hi[a] - 1 + halo);
        }
        const VolumeF32 block = cropVolume(vol, read);
        const Index3 innerLo{lo[0] - read.lo[0], lo[1] - read.lo[1], lo[2] - read.lo[2]};
        const Index3 innerHi{hi[0] - read.lo[0], hi[1] - read.lo[1], hi[2] - read.lo[2]};
        const std::vector<double> cb = vesselnessStructureScale(block, o, innerLo, innerHi);
        for (size_t s = 0; s < c.size(); ++s) cMax[s] = std::max(cMax[s], cb[s]);
        VesselnessOptions given = o;
        given.cPerScale = c;
        const std::vector<float> v = computeVesselness(block, given);
        const Geometry& bg = block.geometry();
        for (int64_t k = lo[2]; k < hi[2]; ++k)
          for (int64_t j = lo[1]; j < hi[1]; ++j)
            for (int64_t i = lo[0]; i < hi[0]; ++i)
              ASSERT_EQ(v[static_cast<size_t>(bg.linear(i - read.lo[0], j - read.lo[1], k - read.lo[2]))],
                        whole[static_cast<size_t>(g.linear(i, j, k))])
                  << "voxel " << i << "," << j << "," << k;
        ++blocks;
      }
  EXPECT_EQ(blocks, 27);
  EXPECT_EQ(cMax, c);
  // One halo voxel less and the block differs from the whole (the halo is not larger than needed).
  VoxelBox read;
  read.lo = {12 - halo + 1, 12 - halo + 1, 12 - halo + 1};
  read.hi = {27 + halo - 1, 27 + halo - 1, 27 + halo - 1};
  VesselnessOptions given = o;
  given.cPerScale = c;
  const std::vector<float> v = computeVesselness(cropVolume(vol, read), given);
  const Geometry bg = cropGeometry(g, read);
  int differ = 0;
  for (int64_t k = 12; k < 28; ++k)
    for (int64_t j = 12; j < 28; ++j)
      for (int64_t i = 12; i < 28; ++i)
        differ += v[static_cast<size_t>(bg.linear(i - read.lo[0], j - read.lo[1], k - read.lo[2]))] !=
                  whole[static_cast<size_t>(g.linear(i, j, k))];
  EXPECT_GT(differ, 0);
}

}  // namespace
}  // namespace vs
