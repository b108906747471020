// Tube phantoms (issue 24): the rendered volume agrees with the analytic geometry, every kind
// builds, bad options are errors.
#include "phantom/tube_phantom.h"

#include <gtest/gtest.h>

#include <cmath>

#include "util/error.h"

namespace vs {
namespace {

TEST(TubePhantom, InsideIsForegroundOutsideIsBackground) {
  TubePhantomOptions o;
  o.seed = 21;
  o.radiusVoxels = 3;
  o.noiseSigma = 0;
  const TubePhantom ph = makeTubePhantom(o);
  const TubeTruth& t = ph.truth;
  const TubeBranch& b = t.branches[0];
  const Geometry& g = ph.volume.geometry();
  int checked = 0;
  for (double s = 0; s <= b.lengthMm; s += 2) {
    const Vec3 c = b.at(s);
    const Index3 v = roundIndex(g.worldToIndex(c));
    if (!g.contains(v)) continue;
    EXPECT_NEAR(ph.volume(v[0], v[1], v[2]), o.foreground, 5) << "centre at s " << s;
    // 2 radii off the axis, perpendicular to it: background.
    const Vec3 off = c + 2.5 * b.radiusMm * b.aAxis;
    const Index3 w = roundIndex(g.worldToIndex(off));
    if (g.contains(w)) {
      EXPECT_NEAR(ph.volume(w[0], w[1], w[2]), o.background, 5);
    }
    ++checked;
  }
  EXPECT_GT(checked, 5);
  EXPECT_DOUBLE_EQ(b.equivalentRadiusMm(0), 3 * t.radiusUnitMm);
}

TEST(TubePhantom, EveryKindBuildsWithItsTruth) {
  for (TubeKind k : {TubeKind::Straight, TubeKind::Curved, TubeKind::Taper, TubeKind::Elliptic, TubeKind::Stenosis,
                     TubeKind::Bifurcation}) {
    TubePhantomOptions o;
    o.seed = 22;
    o.kind = k;
    o.radiusVoxels = 2;
    const TubePhantom ph = makeTubePhantom(o);
    EXPECT_EQ(tubeKindFromName(tubeKindName(k)), k);
    EXPECT_EQ(ph.truth.branches.size(), k == TubeKind::Bifurcation ? 3u : 1u);
    EXPECT_FALSE(tubeArcsInside(ph.truth, 0, 1.0, 0.5).empty()) << tubeKindName(k);
    if (k == TubeKind::Stenosis) {
      const TubeBranch& b = ph.truth.branches[0];
      EXPECT_NEAR(b.profile(b.stenosisCentreMm), 1 - b.stenosisDegree, 1e-12);
    }
    if (k == TubeKind::Bifurcation) {
      const double a = std::acos(ph.truth.branches[1].dir.dot(ph.truth.branches[2].dir)) * 180 / 3.141592653589793;
      EXPECT_NEAR(a, ph.truth.bifurcationDeg, 1e-9);
    }
  }
}

TEST(TubePhantom, BadOptionsAreErrors) {
  TubePhantomOptions o;
  o.radiusVoxels = 0.1;
  EXPECT_THROW(makeTubePhantom(o), InvalidArgument);
  o.radiusVoxels = 3;
  o.kind = TubeKind::Stenosis;
  o.stenosisDegree = 0.95;
  EXPECT_THROW(makeTubePhantom(o), InvalidArgument);
  EXPECT_THROW(tubeKindFromName("spiral"), InvalidArgument);
}

}  // namespace
}  // namespace vs
