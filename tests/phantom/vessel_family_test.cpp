// The vessel family's variants (phantom.h: makeVesselFamilyCase, issue 21): drawn from the seed,
// every tube in the truth and inside the volume, radii and gaps as drawn, a thin case unchanged by
// the variant draw.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "phantom/phantom.h"

using namespace vs;

namespace {

constexpr VesselFamilyVariant kVariants[4] = {VesselFamilyVariant::Thin, VesselFamilyVariant::WideLumen,
                                              VesselFamilyVariant::Kissing, VesselFamilyVariant::Parallel};

// Surface gap (mm) from each point of branch b to branch a.
std::vector<double> surfaceGapsMm(const VesselTruth& t, int a, int b) {
  std::vector<double> out;
  const VesselBranch &A = t.branches[size_t(a)], &B = t.branches[size_t(b)];
  for (size_t j = 0; j < B.points.size(); ++j) {
    double best = 1e300;
    for (size_t i = 0; i < A.points.size(); ++i)
      best = std::min(best, (A.points[i] - B.points[j]).cwiseProduct(t.spacing).norm() - A.radiiMm[i] - B.radiiMm[j]);
    out.push_back(best);
  }
  return out;
}

}  // namespace

TEST(VesselFamilyPhantom, TheSeedDrawsEveryVariant) {
  int count[4] = {0, 0, 0, 0};
  for (uint64_t seed = 1; seed <= 200; ++seed) ++count[static_cast<int>(vesselFamilyVariantOf(seed))];
  for (int v = 0; v < 4; ++v) EXPECT_GE(count[v], 30) << vesselFamilyVariantName(kVariants[v]);
  EXPECT_EQ(makeVesselFamilyCase(7).variant, vesselFamilyVariantOf(7));
}

TEST(VesselFamilyPhantom, AThinSeedIsTheSameCaseWithTheVariantGivenOrDrawn) {
  uint64_t seed = 1;
  while (vesselFamilyVariantOf(seed) != VesselFamilyVariant::Thin) ++seed;
  const VesselFamilyCase a = makeVesselFamilyCase(seed), b = makeVesselFamilyCase(seed, VesselFamilyVariant::Thin);
  EXPECT_EQ(a.volume.voxels(), b.volume.voxels());
  EXPECT_EQ(a.truth.terminalVoxels, b.truth.terminalVoxels);
  EXPECT_EQ(a.truth.dims, (Index3{80, 80, 48}));
}

TEST(VesselFamilyPhantom, EveryTubeInsideTheVolumeWithItsDrawnRadiusAndGap) {
  for (uint64_t seed = 1; seed <= 6; ++seed)
    for (VesselFamilyVariant v : kVariants) {
      if (v == VesselFamilyVariant::Thin && seed > 2) continue;  // the thin tree has its own tests
      const VesselFamilyCase c = makeVesselFamilyCase(seed, v);
      const VesselTruth& t = c.truth;
      SCOPED_TRACE(c.describe());
      ASSERT_EQ(c.variant, v);
      ASSERT_EQ(c.volume.geometry().dims, t.dims);
      const double vox = t.spacing.minCoeff();
      // Inside: every tube's surface at least 2 voxels from every face.
      for (const VesselBranch& b : t.branches)
        for (size_t k = 0; k < b.points.size(); ++k)
          for (int i = 0; i < 3; ++i) {
            const double mm = b.points[k][i] * t.spacing[i];
            EXPECT_GE(mm - b.radiiMm[k], 2 * t.spacing[i]);
            EXPECT_LE(mm + b.radiiMm[k], double(t.dims[i] - 3) * t.spacing[i]);
          }
      // The tree: children start at their parent's end, terminals on their leaf's last point.
      for (size_t i = 0; i < t.branches.size(); ++i) {
        if (t.branches[i].parent < 0) continue;
        EXPECT_LT((t.branches[i].points.front() - t.branches[size_t(t.branches[i].parent)].points.back()).norm(), 1e-9);
      }
      ASSERT_EQ(t.terminalVoxels.size(), t.terminalBranches.size());
      for (size_t i = 0; i < t.terminalVoxels.size(); ++i) {
        const Vec3 e = t.branches[size_t(t.terminalBranches[i])].points.back();
        EXPECT_LT(
            (e - Vec3(double(t.terminalVoxels[i][0]), double(t.terminalVoxels[i][1]), double(t.terminalVoxels[i][2])))
                .norm(),
            1e-9);
      }
      EXPECT_LT(distanceToCenterline(t, Vec3(double(t.rootVoxel[0]), double(t.rootVoxel[1]), double(t.rootVoxel[2])))
                    .distanceMm,
                1e-9);
      // The lumen is the polarity's side of the background (bias <= 20 %, noise <= 15 on 170).
      const double bg = 0.5 * (t.foreground + t.background);
      const Index3 r = t.rootVoxel;
      EXPECT_EQ(c.volume(r[0], r[1], r[2]) < bg, c.dark);
      if (v == VesselFamilyVariant::WideLumen) {
        EXPECT_GE(c.lumenRadiusVoxels, 8.0);
        EXPECT_LE(c.lumenRadiusVoxels, 25.0);
        EXPECT_GE(t.terminalVoxels.size(), 3u);
        EXPECT_LE(t.terminalVoxels.size(), 5u);
        // Trunk pieces (the chain from the root; radius R) and daughters (1.5-4 voxels, 0.75x at the end).
        for (int b = 0;;) {
          for (double rmm : t.branches[size_t(b)].radiiMm) EXPECT_NEAR(rmm, c.lumenRadiusVoxels * vox, 1e-9);
          int next = -1;
          for (int ch : t.branches[size_t(b)].children) {
            if (t.branches[size_t(ch)].children.empty() && t.branches[size_t(ch)].radiiMm.front() < 5 * vox) {
              for (double rmm : t.branches[size_t(ch)].radiiMm) {
                EXPECT_GE(rmm, 0.75 * 1.5 * vox - 1e-9);
                EXPECT_LE(rmm, 4 * vox + 1e-9);
              }
            } else {
              next = ch;
            }
          }
          if (next < 0) break;
          b = next;
        }
        // Flat inside: the voxel values within half the radius of the trunk's axis.
        const VesselBranch& trunk = t.branches[0];
        double lumenSum = 0;
        int lumenN = 0;
        for (const Vec3& p : trunk.points) {
          const Index3 q = roundIndex(p);
          lumenSum += c.volume(q[0], q[1], q[2]);
          ++lumenN;
        }
        EXPECT_EQ(lumenSum / lumenN < bg, c.dark);
      } else if (v != VesselFamilyVariant::Thin) {
        ASSERT_EQ(t.branches.size(), 3u);
        ASSERT_EQ(t.terminalBranches, (std::vector<int>{1, 2}));
        const bool kissing = v == VesselFamilyVariant::Kissing;
        EXPECT_GE(c.gapVoxels, kissing ? 0.0 : 2.0);
        EXPECT_LE(c.gapVoxels, kissing ? 1.0 : 4.0);
        // B leaves A (fused at the junction), bends away to a peak within the first third of its
        // samples, comes back to the gap and leaves again: the smallest gap after that peak (0.5 voxel
        // sampling of A: up to ~0.1 voxel off).
        const std::vector<double> gaps = surfaceGapsMm(t, 1, 2);
        const size_t peak = size_t(std::max_element(gaps.begin(), gaps.begin() + long(gaps.size() / 3)) - gaps.begin());
        EXPECT_LT(gaps.front(), 0.0);
        EXPECT_GT(gaps[peak], c.gapVoxels * vox + 3 * vox);
        const double gap = *std::min_element(gaps.begin() + long(peak), gaps.end()) / vox;
        EXPECT_NEAR(gap, c.gapVoxels, 0.1);
        for (int b = 1; b <= 2; ++b)
          for (double rmm : t.branches[size_t(b)].radiiMm) {
            EXPECT_GE(rmm, 0.8 * 1.5 * vox - 1e-9);
            EXPECT_LE(rmm, std::max(3.5 * vox, 0.5 * t.radiusUnitMm) + 1e-9);
          }
      }
    }
}

// The flat variant (a dural sinus's form): never drawn from a seed; its trunk's section an ellipse of aspect 2-3,
// 5-25 voxels across (semi-axis), read in the volume along rays from the trunk's axis: the farthest lumen reach is
// the semi-axis across and the nearest the one deep (within 1.5 voxels: partial volume, bias and noise), and the
// truth's radius is the equivalent radius (the circle of the section's area); daughters at most as wide as it is deep.
TEST(VesselFamilyPhantom, FlatVariantHasAnEllipticTrunkWithItsEquivalentRadiusInTheTruth) {
  for (uint64_t seed = 1; seed <= 200; ++seed) ASSERT_NE(vesselFamilyVariantOf(seed), VesselFamilyVariant::Flat);
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    const VesselFamilyCase c = makeVesselFamilyCase(seed, VesselFamilyVariant::Flat);
    const VesselTruth& t = c.truth;
    SCOPED_TRACE(c.describe());
    ASSERT_EQ(c.variant, VesselFamilyVariant::Flat);
    EXPECT_EQ(vesselFamilyVariantName(c.variant), "flat");
    EXPECT_GE(c.flatAspect, 2.0);
    EXPECT_LE(c.flatAspect, 3.0);
    EXPECT_GE(c.lumenRadiusVoxels, 5.0);
    EXPECT_LE(c.lumenRadiusVoxels, 25.0);
    const double vox = t.spacing.minCoeff(), A = c.lumenRadiusVoxels, B = A / c.flatAspect;
    EXPECT_NEAR(t.branches[0].radiiMm[0], std::sqrt(A * B) * vox, 1e-9);
    for (const VesselBranch& b : t.branches)
      if (b.children.empty() && b.radiiMm.front() < t.branches[0].radiiMm[0]) {
        EXPECT_LE(b.radiiMm.front(), B * vox + 1e-9);
      }
    // Rays across the first trunk piece's middle, in mm.
    const VesselBranch& trunk = t.branches[0];
    const Vec3 a = trunk.points.front().cwiseProduct(t.spacing), e = trunk.points.back().cwiseProduct(t.spacing);
    const Vec3 axis = (e - a).normalized(), centre = 0.5 * (a + e);
    Vec3 u = axis.cross(Vec3(1, 0, 0));
    if (u.norm() < 0.5) u = axis.cross(Vec3(0, 1, 0));
    u.normalize();
    const Vec3 w = axis.cross(u);
    const double iso = 0.5 * (t.foreground + t.background);
    double nearest = 1e300, farthest = 0;
    for (int k = 0; k < 72; ++k) {
      const Vec3 dir = std::cos(M_PI * k / 36) * u + std::sin(M_PI * k / 36) * w;
      double reach = 0;
      int outside = 0;
      for (double d = 0; outside < 3; d += 0.25 * vox) {
        const Vec3 p = (centre + d * dir).cwiseQuotient(t.spacing);
        const Index3 q = roundIndex(p);
        bool out = true;
        if (q[0] >= 0 && q[1] >= 0 && q[2] >= 0 && q[0] < t.dims[0] && q[1] < t.dims[1] && q[2] < t.dims[2])
          out = (c.volume(q[0], q[1], q[2]) < iso) != c.dark;
        outside = out ? outside + 1 : 0;
        if (!out) reach = d;
      }
      nearest = std::min(nearest, reach / vox), farthest = std::max(farthest, reach / vox);
    }
    EXPECT_NEAR(farthest, A, 1.5 * t.spacing.maxCoeff() / vox);
    EXPECT_NEAR(nearest, B, 1.5 * t.spacing.maxCoeff() / vox);
    EXPECT_GT(farthest / nearest, 1.6);
    std::printf("[flat section %llu] reach %.1f .. %.1f vox, semi-axes %.1f x %.1f\n",
                static_cast<unsigned long long>(seed), nearest, farthest, A, B);
  }
}
