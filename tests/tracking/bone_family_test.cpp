// The vessel family's bone variant (phantom.h: makeVesselFamilyBoneCase; the lumen model's upper edge,
// docs/notes/tracking.md session 15 bone1). CI: the bone blocks change no other draw of the case. The sweep
// (VS_FAMILY_BONE=FIRST-LAST, none in CI): `trace` with defaults, every terminal given, then automatic
// terminals as many as the true ones; refined points inside a bone block, points in a vessel, terminals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "family_seeds.h"
#include "phantom/phantom.h"
#include "tracking/trace_run.h"

namespace vs {
namespace {

// The bone case of a seed drawn bright is the plain case wherever no block reaches (noise, bias, tubes
// all drawn as before), and bone inside its blocks away from the vessels.
TEST(VesselFamilyBone, BoneBlocksChangeNothingElse) {
  uint64_t seed = 1;
  while (makeVesselFamilyCase(seed).dark) ++seed;  // a seed drawn bright: the bone case is bright too
  const VesselFamilyCase plain = makeVesselFamilyCase(seed), bone = makeVesselFamilyBoneCase(seed);
  ASSERT_EQ(plain.volume.geometry().dims, bone.volume.geometry().dims);
  ASSERT_GE(bone.bones.size(), 1u);
  const Geometry& g = bone.volume.geometry();
  const double far = g.spacing.norm();
  size_t same = 0, outside = 0, inside = 0, bright = 0;
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 p = g.spacing.cwiseProduct(Vec3(double(x), double(y), double(z)));
        double sd = 1e300, value = 0;
        for (const BoneBlock& b : bone.bones)
          if (const double d = b.signedDistanceMm(p); d < sd) sd = d, value = b.value;
        if (sd > far) {
          ++outside;
          same += plain.volume(x, y, z) == bone.volume(x, y, z);
        } else if (sd < -far && distanceToCenterline(bone.truth, p.cwiseQuotient(g.spacing)).distanceMm > 3 * far) {
          ++inside;  // well inside a block, away from every vessel: bone (bias at most +-20 %, noise)
          bright += bone.volume(x, y, z) > 0.75 * value;
        }
      }
  EXPECT_EQ(same, outside);
  EXPECT_GT(inside, 0u);
  EXPECT_EQ(bright, inside);
}

struct BoneFigures {
  size_t terminals = 0, reached = 0, points = 0, within1 = 0, inBone = 0;
  double sum = 0;
  size_t autoPaths = 0, autoMatched = 0, autoPoints = 0, autoInside = 0, autoInBone = 0;
  std::string error;
};

// VS_BONE_UPPER=F sets the upper edge (0: none, the model before it) for before/after figures.
void setUpper(TraceRequest& rq) {
  if (const char* u = std::getenv("VS_BONE_UPPER")) rq.options.autoCost.upperFraction = std::strtod(u, nullptr);
}

bool inBone(const VesselFamilyCase& c, const Vec3& q) {
  const Vec3 p = q.cwiseProduct(c.truth.spacing);
  for (const BoneBlock& b : c.bones)
    if (const double sd = b.signedDistanceMm(p); sd < 0) {
      if (std::getenv("VS_BONE_DEBUG")) {
        const CenterlineDistance d = distanceToCenterline(c.truth, q);
        std::printf(
            "  in bone %.0f: point %.1f,%.1f,%.1f value %.0f, %.2f mm deep, %.2f mm from a centreline (r %.2f)\n",
            b.value, q[0], q[1], q[2], c.volume(std::lround(q[0]), std::lround(q[1]), std::lround(q[2])), -sd,
            d.distanceMm, d.radiusMm);
      }
      return true;
    }
  return false;
}

void measureGiven(const VesselFamilyCase& c, BoneFigures& f) {
  const VesselTruth& t = c.truth;
  const double vox = t.spacing.minCoeff();
  TraceRequest rq;
  rq.root = t.rootVoxel;
  rq.targets = t.terminalVoxels;
  setUpper(rq);
  f.terminals = t.terminalVoxels.size();
  try {
    const TraceResult r = runTrace(c.volume, rq);
    for (size_t i = 0; i < r.paths.size(); ++i) {
      f.reached += r.paths[i].reached;
      for (const Vec3& q : r.points[i]) {
        const double d = distanceToCenterline(t, q).distanceMm;
        f.sum += d / vox;
        f.within1 += d <= vox;
        f.inBone += inBone(c, q);
        ++f.points;
      }
    }
  } catch (const std::exception& e) {
    f.error = e.what();
  }
}

void measureAuto(const VesselFamilyCase& c, BoneFigures& f) {
  const VesselTruth& t = c.truth;
  const double vox = t.spacing.minCoeff();
  TraceRequest rq;
  rq.root = t.rootVoxel;
  rq.autoTerminals = static_cast<int>(t.terminalVoxels.size());
  setUpper(rq);
  try {
    const TraceResult r = runTrace(c.volume, rq);
    std::vector<bool> used(t.terminalVoxels.size(), false);
    f.autoPaths = r.paths.size();
    for (size_t i = 0; i < r.paths.size(); ++i) {
      const Vec3 e(double(r.paths[i].target[0]), double(r.paths[i].target[1]), double(r.paths[i].target[2]));
      for (size_t k = 0; k < used.size(); ++k) {
        const Vec3 tv(double(t.terminalVoxels[k][0]), double(t.terminalVoxels[k][1]), double(t.terminalVoxels[k][2]));
        if (!used[k] && (e - tv).cwiseProduct(t.spacing).norm() <= 4 * vox) {
          used[k] = true, ++f.autoMatched;
          break;
        }
      }
      for (const Vec3& q : r.points[i]) {
        const CenterlineDistance d = distanceToCenterline(t, q);
        f.autoInside += d.distanceMm <= d.radiusMm + vox;
        f.autoInBone += inBone(c, q);
        ++f.autoPoints;
      }
    }
  } catch (const std::exception& e) {
    if (f.error.empty()) f.error = std::string("auto terminals: ") + e.what();
  }
}

class VesselFamilyBoneSweep : public ::testing::TestWithParam<uint64_t> {};

// No refined point inside bone, given targets or automatic ones; every given terminal reached.
TEST_P(VesselFamilyBoneSweep, PathsStayOutOfTheBone) {
  const VesselFamilyCase c = makeVesselFamilyBoneCase(GetParam());
  BoneFigures f;
  measureGiven(c, f);
  measureAuto(c, f);
  std::printf(
      "[bone %s] given: %zu/%zu reached, %zu points, mean %.3f vox, within 1 vox %.1f%%, in bone %zu; auto: %zu paths, "
      "%zu matched of %zu, in the vessel %.1f%%, in bone %zu\n",
      c.describe().c_str(), f.reached, f.terminals, f.points, f.points ? f.sum / double(f.points) : 0.0,
      f.points ? 100.0 * double(f.within1) / double(f.points) : 0.0, f.inBone, f.autoPaths, f.autoMatched, f.terminals,
      f.autoPoints ? 100.0 * double(f.autoInside) / double(f.autoPoints) : 0.0, f.autoInBone);
  if (!f.error.empty()) std::printf("  error: %s\n", f.error.c_str());
  EXPECT_TRUE(f.error.empty()) << f.error;
  EXPECT_EQ(f.reached, f.terminals);
  EXPECT_EQ(f.inBone, 0u);
  EXPECT_EQ(f.autoInBone, 0u);
}
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(VesselFamilyBoneSweep);
INSTANTIATE_TEST_SUITE_P(Sweep, VesselFamilyBoneSweep, ::testing::ValuesIn(familySeedsFromEnv("VS_FAMILY_BONE")),
                         [](const auto& p) { return "seed" + std::to_string(p.param); });

}  // namespace
}  // namespace vs
