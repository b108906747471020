// Tests for tracking/region_notes.cpp: the terminal scan's region as the report's note says it.
#include "tracking/region_notes.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace vs {
namespace {

Geometry grid() {
  Geometry g;
  g.dims = {10, 10, 10};
  g.spacing = Vec3(1, 1, 2);  // 2 mm^3 a voxel
  return g;
}

TEST(RegionNotes, SaysSizeAndDepthAndWarnsOnlyWhenTheRegionFillsAFifth) {
  const Geometry g = grid();
  const std::string small = describeRegion(g, 50, {0.5f, 2.5f, 1.0f});
  EXPECT_NE(small.find("50 voxels (0.1 ml)"), std::string::npos) << small;
  EXPECT_NE(small.find("deepest 2.5 mm"), std::string::npos) << small;
  EXPECT_EQ(small.find("warning"), std::string::npos) << small;
  const std::string leaked = describeRegion(g, 250, {1.0f});
  EXPECT_NE(leaked.find("warning: it fills 25 %"), std::string::npos) << leaked;
}

TEST(RegionNotes, NamesContinuationAndSpillOnlyWhenThereWereAny) {
  const Geometry g = grid();
  EXPECT_EQ(describeRegionChanges(g, {}), "");
  RegionChanges asked;
  asked.continuationAsked = true;  // asked for, nothing found: the note says so
  EXPECT_NE(describeRegionChanges(g, asked).find("no dim branch continued"), std::string::npos);
  RegionChanges c;
  c.continuedVoxels = 12;
  c.continuedPieces = 2;
  c.spilledVoxels = 500;
  c.spillAt = {3, 4, 5};
  c.spillMm = 41.6;
  const std::string t = describeRegionChanges(g, c);
  EXPECT_NE(t.find("continued along 2 dim branch piece(s) below the lumen level (12 voxels)"), std::string::npos) << t;
  EXPECT_NE(t.find("500 voxels (1.0 ml) left out"), std::string::npos) << t;
  EXPECT_NE(t.find("at (3,4,5), 42 mm from the root"), std::string::npos) << t;
}

}  // namespace
}  // namespace vs
