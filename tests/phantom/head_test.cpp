#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "phantom/phantom.h"

using namespace vs;

namespace {

HeadPhantomOptions opts(uint64_t seed, Index3 dims = {96, 96, 96}, Vec3 spacing = Vec3(1, 1, 1), double noise = 0) {
  HeadPhantomOptions o;
  o.seed = seed;
  o.dims = dims;
  o.spacing = spacing;
  o.noiseSigma = noise;
  return o;
}

Vec3 mm(const HeadTruth& t, int64_t x, int64_t y, int64_t z) {
  return Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)).cwiseProduct(t.spacing);
}

}  // namespace

TEST(HeadPhantom, SameSeedIdenticalDifferentSeedDifferent) {
  const auto a = makeHeadPhantom(opts(1, {48, 48, 48}, Vec3(1, 1, 1), 10));
  const auto b = makeHeadPhantom(opts(1, {48, 48, 48}, Vec3(1, 1, 1), 10));
  const auto c = makeHeadPhantom(opts(2, {48, 48, 48}, Vec3(1, 1, 1), 10));
  EXPECT_EQ(a.volume.voxels(), b.volume.voxels());
  EXPECT_EQ(toJson(a.truth).dump(), toJson(b.truth).dump());
  EXPECT_NE(a.volume.voxels(), c.volume.voxels());
  EXPECT_NE(toJson(a.truth).dump(), toJson(c.truth).dump());  // proportions jitter with the seed
}

TEST(HeadPhantom, IsoValuesAndLayersNested) {
  const auto ph = makeHeadPhantom(opts(3));
  const HeadTruth& t = ph.truth;
  EXPECT_DOUBLE_EQ(t.isoSkin, -480.0);
  EXPECT_DOUBLE_EQ(t.isoBone, 520.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(t.skin.semiAxesMm[i], t.skullOuter.semiAxesMm[i]);
    EXPECT_GT(t.skullOuter.semiAxesMm[i], t.skullInner.semiAxesMm[i]);
  }
  EXPECT_EQ(t.faceDirection, Vec3(0, -1, 0));
  EXPECT_LT(t.nose.centerMm[1], t.skin.centerMm[1]);  // nose on the face side (small y)
}

namespace {

void expectVoxelsMatchEllipsoids(const HeadPhantom& ph) {
  const HeadTruth& t = ph.truth;
  // Partial volume is confined to half a voxel's extent along the normal (<= half the
  // sum of the spacings) on each side of a surface.
  const double band = 0.5 * t.spacing.sum() + 0.1;
  auto side = [&](const Ellipsoid& e, const Vec3& p) {  // -1 clearly inside, +1 clearly outside, 0 near
    const double q = e.level(p);
    const double margin = band / e.semiAxesMm.minCoeff();
    return q < 1 - margin ? -1 : (q > 1 + margin ? 1 : 0);
  };
  int64_t counts[4] = {0, 0, 0, 0};
  for (int64_t z = 0; z < t.dims[2]; ++z)
    for (int64_t y = 0; y < t.dims[1]; ++y)
      for (int64_t x = 0; x < t.dims[0]; ++x) {
        const Vec3 p = mm(t, x, y, z);
        const int v = ph.volume(x, y, z);
        const int sNose = side(t.nose, p);
        const int sSkin = side(t.skin, p), sOut = side(t.skullOuter, p), sIn = side(t.skullInner, p);
        if (sIn == -1) {
          ++counts[3];
          ASSERT_EQ(v, 30);
        } else if (sIn == 1 && sOut == -1) {
          ++counts[2];
          ASSERT_EQ(v, 1000);
        } else if (sOut == 1 && (sSkin == -1 || sNose == -1)) {
          ++counts[1];
          ASSERT_EQ(v, 40);
        } else if (sSkin == 1 && sNose == 1) {
          ++counts[0];
          ASSERT_EQ(v, -1000);
        }
      }
  for (int64_t c : counts) EXPECT_GT(c, 50);
}

}  // namespace

TEST(HeadPhantom, VoxelsMatchTheEllipsoids) { expectVoxelsMatchEllipsoids(makeHeadPhantom(opts(4))); }

TEST(HeadPhantom, AnisotropicVoxelsMatchTheEllipsoidsInMm) {
  // The ellipsoids are defined in mm; the classification follows them on every axis.
  expectVoxelsMatchEllipsoids(makeHeadPhantom(opts(4, {128, 128, 96}, Vec3(0.8, 0.8, 1.2))));
}

TEST(HeadPhantom, LayersOrderedAlongRaysFromTheCentre) {
  const auto ph = makeHeadPhantom(opts(5, {96, 96, 96}, Vec3(1, 1, 1), 10));
  const HeadTruth& t = ph.truth;
  const Vec3 c = t.skin.centerIndex(t.spacing);
  auto layer = [&](double v) {  // 3 brain, 2 bone, 1 soft tissue, 0 air (noise 10 HU)
    if (v < t.isoSkin) return 0;
    if (v > t.isoBone) return 2;
    return -1;  // soft tissue or brain: resolved by position (outside/inside bone)
  };
  for (const Vec3& dir :
       {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)}) {
    // Sequence along the ray: inside bone (brain) -> bone -> soft -> air; record transitions.
    std::vector<int> seq;
    bool passedBone = false;
    for (double s = 0;; s += 0.5) {
      const Index3 v = roundIndex(c + s * dir);
      if (!ph.volume.geometry().contains(v)) break;
      int l = layer(ph.volume(v[0], v[1], v[2]));
      if (l == 2) passedBone = true;
      if (l == -1) l = passedBone ? 1 : 3;
      if (seq.empty() || seq.back() != l) seq.push_back(l);
    }
    EXPECT_EQ(seq, (std::vector<int>{3, 2, 1, 0})) << "ray " << dir.transpose();
  }
}

TEST(HeadPhantom, NoseInsideItsBoxAndProtrudes) {
  const auto ph = makeHeadPhantom(opts(6, {96, 96, 96}, Vec3(1, 1, 1), 0));
  const HeadTruth& t = ph.truth;
  int64_t protruding = 0;
  for (int64_t z = 0; z < t.dims[2]; ++z)
    for (int64_t y = 0; y < t.dims[1]; ++y)
      for (int64_t x = 0; x < t.dims[0]; ++x) {
        if (ph.volume(x, y, z) <= t.isoSkin) continue;
        // Tissue clearly outside the skin ellipsoid can only be the nose.
        if (t.skin.level(mm(t, x, y, z)) < 1 + 2.0 / t.skin.semiAxesMm.minCoeff()) continue;
        ++protruding;
        ASSERT_TRUE(x >= t.noseBoxMin[0] && x <= t.noseBoxMax[0] && y >= t.noseBoxMin[1] && y <= t.noseBoxMax[1] &&
                    z >= t.noseBoxMin[2] && z <= t.noseBoxMax[2])
            << x << "," << y << "," << z;
      }
  EXPECT_GT(protruding, 100);
  // The box lies on the face side: its low-y end is in front of the skin.
  EXPECT_LT(static_cast<double>(t.noseBoxMin[1]), (t.skin.centerMm[1] - t.skin.semiAxesMm[1]) / t.spacing[1]);
  EXPECT_GE(t.noseBoxMin[1], 1);
}

TEST(HeadPhantom, BadOptionsThrow) {
  EXPECT_THROW(makeHeadPhantom(opts(1, {8, 64, 64})), InvalidArgument);
  EXPECT_THROW(makeHeadPhantom(opts(1, {64, 64, 64}, Vec3(1, 1, -1))), InvalidArgument);
  auto o = opts(1);
  o.bone = 0;  // bone below soft tissue
  EXPECT_THROW(makeHeadPhantom(o), InvalidArgument);
}
