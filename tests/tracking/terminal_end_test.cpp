// Tests for tracking/terminal_end.cpp (issue 21): an automatic terminal's end on its vessel's lumen, not on a voxel
// of a masked volume's zero background that the smoothed cost took into the lumen region beside a vessel's end.
#include "tracking/terminal_end.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tracking/trace_run.h"

using namespace vs;

namespace {

// A vessel-only (masked) volume, 1 mm voxels: 150 within radius 1.5 of the segment y = z = 10, x = 4..x1, else 0.
VolumeF32 maskedTube(int64_t x1) {
  Geometry g;
  g.dims = {32, 21, 21};
  g.spacing = Vec3(1, 1, 1);
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < 21; ++z)
    for (int64_t y = 0; y < 21; ++y)
      for (int64_t x = 4; x <= x1; ++x)
        if (std::hypot(static_cast<double>(y - 10), static_cast<double>(z - 10)) <= 1.5) v(x, y, z) = 150.0f;
  return v;
}

// The chain from x = from back to x = 4 along the tube's axis.
std::vector<Index3> chainFrom(int64_t from) {
  std::vector<Index3> c;
  for (int64_t x = from; x >= 4; --x) c.push_back({x, 10, 10});
  return c;
}

}  // namespace

TEST(TerminalEnd, AnEndOnTheBackgroundPastTheVesselsEndMovesBackOntoIt) {
  const VolumeF32 v = maskedTube(20);
  EXPECT_EQ(endOnLumen(v, chainFrom(22), 1.5), 2u);  // x = 22, 21 are 0: the end at x = 20
  EXPECT_EQ(endOnLumen(v, chainFrom(20), 1.5), 0u);  // on the lumen: kept
}

TEST(TerminalEnd, AStubJoinedThroughABackgroundVoxelIsNoEnd) {
  VolumeF32 v = maskedTube(20);
  v(22, 10, 10) = 150.0f;  // a stub beyond a zero voxel at x = 21
  EXPECT_EQ(endOnLumen(v, chainFrom(22), 1.5), 2u);
}

TEST(TerminalEnd, ATaperingEndRoundTheHalfMaximumIsKept) {
  VolumeF32 v = maskedTube(20);
  v(21, 10, 10) = 60.0f, v(22, 10, 10) = 50.0f;  // a third of the contrast: a faint tip, not background
  EXPECT_EQ(endOnLumen(v, chainFrom(22), 1.5), 0u);
}

// End to end: a masked tree traced with defaults; every automatic terminal lies on a vessel voxel.
TEST(TerminalEnd, AutomaticTerminalsOfAMaskedTreeLieOnItsVessels) {
  Geometry g;
  g.dims = {64, 64, 40};
  g.spacing = Vec3(0.55, 0.55, 1.0);
  VolumeF32 v(g, 0.0f);
  const Vec3 a(32, 8, 20), b(32, 36, 20), c1(12, 58, 14), c2(54, 56, 27);
  auto seg = [](const Vec3& p, const Vec3& s0, const Vec3& s1) {
    const Vec3 d = s1 - s0;
    const double t = std::clamp((p - s0).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (p - (s0 + t * d)).cwiseProduct(Vec3(0.55, 0.55, 1.0)).norm();
  };
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 p(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z));
        const double d = std::min({seg(p, a, b) - 1.6, seg(p, b, c1) - 0.9, seg(p, b, c2) - 0.9});
        if (d <= 0) v(x, y, z) = static_cast<float>(150 - 30 * std::max(0.0, p[1] - 40) / 20);
      }
  TraceRequest rq;
  rq.root = {32, 10, 20};
  rq.autoTerminals = 2;
  const TraceResult r = runTrace(v, rq);
  ASSERT_EQ(r.paths.size(), 2u);
  for (const TracedPath& p : r.paths)
    EXPECT_GT(v(p.target[0], p.target[1], p.target[2]), 0.0f)
        << p.target[0] << "," << p.target[1] << "," << p.target[2];
}
