// The path support's notes (tracking/path_support.h): a path that crosses tissue where the image shows no lumen is
// said in the trace's notes (where, how long, the contrast there); a path along its vessel, a thin partial-volume
// neck of it included, is not.
#include "tracking/path_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/trace_run.h"
#include "tube_segments.h"

namespace vs {
namespace {

using test_tubes::distanceToSegment;
using test_tubes::drawTubes;
using test_tubes::Segment;

std::vector<std::string> supportNotes(const TraceResult& r) {
  std::vector<std::string> out;
  for (const std::string& n : r.notes)
    if (n.find("without lumen") != std::string::npos) out.push_back(n);
  return out;
}

TraceResult trace(const VolumeF32& v, const Index3& root, const Index3& target) {
  TraceRequest rq;
  rq.root = root;
  rq.targets = {target};
  return runTrace(v, rq);
}

// The stretch a note names: its ends' z and its length.
struct Said {
  long z0 = -1, z1 = -1;
  double mm = 0;
};
Said said(const std::string& note) {
  Said s;
  long x = 0, y = 0;
  const size_t at = note.find("crosses ");
  if (at == std::string::npos) return s;
  std::sscanf(note.c_str() + at, "crosses %lf mm without lumen from (%ld,%ld,%ld) to (%ld,%ld,%ld)", &s.mm, &x, &y,
              &s.z0, &x, &y, &s.z1);
  return s;
}

TEST(PathSupport, AGapOfTissueBetweenTwoTubesIsSaidWithItsEndsLengthAndContrast) {
  // Two collinear tubes (radius 2.5, axes ending at z 22 and 42): 15 voxels of tissue between them (z 24.5..39.5),
  // which the path crosses.
  const VolumeF32 v =
      drawTubes({40, 40, 64}, {{{20, 20, 4}, {20, 20, 22}, 2.5}, {{20, 20, 42}, {20, 20, 58}, 2.5}}, 400, 100, 10, 7);
  const TraceResult r = trace(v, {20, 20, 8}, {20, 20, 54});
  ASSERT_EQ(r.paths.size(), 1u);
  const std::vector<std::string> notes = supportNotes(r);
  ASSERT_EQ(notes.size(), 1u) << testing::PrintToString(r.notes);
  EXPECT_NE(notes[0].find("target #1 (20,20,54)"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("contrast to the local background"), std::string::npos) << notes[0];
  const Said s = said(notes[0]);
  EXPECT_GE(s.z0, 24) << notes[0];  // inside the gap, nearly all of it
  EXPECT_LE(s.z1, 40) << notes[0];
  EXPECT_GE(s.mm, 11.0) << notes[0];
  EXPECT_LE(s.mm, 15.0) << notes[0];
}

TEST(PathSupport, APathAlongItsTubeAndAThinPartialVolumeNeckIsNotSaid) {
  // One tube, radius 2.5, narrowing to a neck of radius 0.6 for 8 voxels (its voxels partial volume, the smoothed
  // values well under the lumen's): the path follows it; nothing to say.
  const VolumeF32 v = drawTubes(
      {40, 40, 64},
      {{{20, 20, 4}, {20, 20, 26}, 2.5}, {{20, 20, 26}, {20, 20, 34}, 0.6}, {{20, 20, 34}, {20, 20, 58}, 2.5}}, 400,
      100, 10, 8);
  const TraceResult r = trace(v, {20, 20, 8}, {20, 20, 54});
  ASSERT_EQ(r.paths.size(), 1u);
  EXPECT_TRUE(supportNotes(r).empty()) << testing::PrintToString(r.notes);
  const TraceResult straight =
      trace(drawTubes({40, 40, 64}, {{{20, 20, 4}, {20, 20, 58}, 2.5}}, 400, 100, 10, 9), {20, 20, 8}, {20, 20, 54});
  EXPECT_TRUE(supportNotes(straight).empty()) << testing::PrintToString(straight.notes);
}

TEST(PathSupport, StretchesAreContiguousUnsupportedRunsAtLeastTheMinimumLong) {
  Geometry g;
  g.dims = {1, 1, 40};
  g.spacing = {1, 1, 0.5};
  std::vector<Index3> voxels;
  std::vector<VoxelSupport> support;
  for (int64_t z = 0; z < 40; ++z) {
    voxels.push_back({0, 0, z});
    VoxelSupport s;
    s.intensity = static_cast<double>(z);
    s.contrast = static_cast<double>(-z);
    s.noise = 2;
    // Unsupported: z 5..12 (3.5 mm: too short) and z 20..31 (5.5 mm).
    s.supported = !((z >= 5 && z <= 12) || (z >= 20 && z <= 31));
    support.push_back(s);
  }
  PathSupportOptions o;
  o.minLengthMm = 5;
  const std::vector<UnsupportedStretch> st = unsupportedStretches(g, voxels, support, o);
  ASSERT_EQ(st.size(), 1u);
  EXPECT_EQ(st[0].first, 20u);
  EXPECT_EQ(st[0].last, 31u);
  EXPECT_DOUBLE_EQ(st[0].lengthMm, 5.5);
  EXPECT_DOUBLE_EQ(st[0].minIntensity, 20);
  EXPECT_DOUBLE_EQ(st[0].maxIntensity, 31);
  EXPECT_DOUBLE_EQ(st[0].maxContrast, -20);
  EXPECT_DOUBLE_EQ(st[0].medianContrast, -25);  // the upper median of 12
  EXPECT_DOUBLE_EQ(st[0].noise, 2);
  o.minLengthMm = 3;
  EXPECT_EQ(unsupportedStretches(g, voxels, support, o).size(), 2u);
}

}  // namespace
}  // namespace vs
