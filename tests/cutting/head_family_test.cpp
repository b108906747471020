// Cuts on the randomised head family (issue 26) with the test seeds fixed in docs/notes/cutting.md
// before they were first run (101, 102, 103; small heads so that CI stays fast): the nose comes
// off (not the face under it down to the skull), and a loop on the forehead cuts along the skull.
#include "phantom/head_family.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cutting/cut.h"

namespace {

using vs::Vec3;

vs::HeadFamilyPhantom smallHead(uint64_t seed) {
  vs::HeadFamilyOptions o;
  o.seed = seed;
  o.sizeScale = 0.6;
  return vs::makeHeadFamilyPhantom(o);
}

vs::CutOptions cutAlong(const vs::HeadFamilyPhantom& ph, const std::vector<Vec3>& loopMm) {
  vs::CutOptions o;
  o.iso = ph.truth.iso;
  for (const Vec3& p : loopMm) o.pointsIndex.push_back(ph.volume.geometry().worldToIndex(p));
  return o;
}

class HeadFamily : public ::testing::TestWithParam<uint64_t> {};

TEST_P(HeadFamily, NoseComesOffWholeWithoutTheFaceBelow) {
  const vs::HeadFamilyPhantom ph = smallHead(GetParam());
  const std::vector<Vec3> loop = ph.truth.noseLoopMm(12);
  ASSERT_EQ(loop.size(), 12u);
  const vs::VolumeF32 v = vs::toFloat(vs::AnyVolume(ph.volume));
  const vs::CutResult r = vs::cutVolume(v, cutAlong(ph, loop));
  const vs::PartCutScore s = vs::scorePartCut(ph, vs::kHeadNose, r.split.labels);
  const vs::CuttingSurfaceEnergy& e = r.surface.energy;
  std::printf(
      "seed %llu: nose %lld voxels, removed %.3f, taken from the rest %.3f; energy image %.1f (%.0f%%) "
      "continuity %.1f (%.0f%%) part %.1f (%.0f%%)\n",
      (unsigned long long)GetParam(), (long long)s.partVoxels, s.removed, s.takenRest, e.image, 100 * e.share(e.image),
      e.continuity, 100 * e.share(e.continuity), e.part, 100 * e.share(e.part));
  // Small heads (1/6 of an adult nose's volume, where a voxel layer over the nose's footprint is
  // ~9% of it): on the tuning seeds 1-6 at this size removed 0.948-1.000, taken 0.003-0.044 (the
  // face's tissue and partial-volume voxels; scorePartCut). Bounds set from those before this test
  // was re-run; the target is reported on adult heads (docs/notes/cutting.md).
  EXPECT_GE(s.removed, 0.93);
  EXPECT_LE(s.takenRest, 0.08);
}

// A loop on the skin of a plain patch of the face: the cut takes the soft tissue down to the skull.
// Returns the cutting surface's mean distance to the skull's outer surface under the region (the
// surface's pixels at least 4 mm, in its plane, inside the contour).
double patchDistanceToSkull(const vs::HeadFamilyPhantom& ph, const std::vector<Vec3>& loop, const char* name) {
  EXPECT_EQ(loop.size(), 12u);
  const vs::VolumeF32 v = vs::toFloat(vs::AnyVolume(ph.volume));
  const vs::CutResult r = vs::cutVolume(v, cutAlong(ph, loop));
  const vs::CuttingSurface& cs = r.surface;
  std::vector<Vec3> under;
  for (int64_t y = 0; y < cs.height; ++y)
    for (int64_t x = 0; x < cs.width; ++x)
      if (cs.inDomain(x, y) && double(cs.ring[size_t(y * cs.width + x)]) * cs.pixelMm >= 4)
        under.push_back(cs.point(x, y));
  EXPECT_GT(under.size(), 20u);
  if (under.empty()) return 1e9;
  const double d = vs::meanDistanceToBoneMm(ph.truth, under);
  std::printf(
      "seed %llu: %s cut, mean distance to the skull's outer surface %.2f mm over %zu pixels "
      "(soft tissue %.1f mm); image share %.0f%%\n",
      (unsigned long long)ph.truth.seed, name, d, under.size(), ph.truth.skinMm + ph.truth.fatMm + ph.truth.muscleMm,
      100 * cs.energy.share(cs.energy.image));
  return d;
}

TEST_P(HeadFamily, ForeheadPatchIsCutAlongTheSkull) {
  const vs::HeadFamilyPhantom ph = smallHead(GetParam());
  EXPECT_LE(patchDistanceToSkull(ph, ph.truth.foreheadLoopMm(12, 12), "forehead"), 1.0);
}

TEST_P(HeadFamily, CheekPatchIsCutAlongTheSkull) {
  const vs::HeadFamilyPhantom ph = smallHead(GetParam());
  EXPECT_LE(patchDistanceToSkull(ph, ph.truth.cheekLoopMm(12, 12), "cheek"), 1.0);
}

INSTANTIATE_TEST_SUITE_P(Cut, HeadFamily, ::testing::Values(101u, 102u, 103u),
                         [](const ::testing::TestParamInfo<uint64_t>& seed) {
                           return "Seed" + std::to_string(seed.param);
                         });

}  // namespace
