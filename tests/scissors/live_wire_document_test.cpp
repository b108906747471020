// The one home of "a live-wire on a slice of a volume" (scissors/live_wire_document.h): the wire
// of a coronal slice of a 3D volume, and its contour document, field by field against the wire
// and the slice conventions of volume/slice.h.
#include "scissors/live_wire_document.h"

#include <gtest/gtest.h>

#include <cmath>

#include "util/error.h"
#include "volume/slice.h"

namespace vs {
namespace {

// A bright box in a 24 x 20 x 16 int16 volume with anisotropic spacing and an origin.
AnyVolume boxVolume() {
  Geometry g;
  g.dims = {24, 20, 16};
  g.spacing = {0.8, 1.0, 1.5};
  g.origin = {-5, 3, 10};
  VolumeI16 v(g);
  for (int64_t z = 0; z < 16; ++z)
    for (int64_t y = 0; y < 20; ++y)
      for (int64_t x = 0; x < 24; ++x) v(x, y, z) = (x >= 6 && x < 18 && z >= 4 && z < 12) ? 900 : 100;
  return AnyVolume(std::move(v));
}

TEST(LiveWireDocument, CoronalSliceContourInEveryCoordinate) {
  const AnyVolume vol = boxVolume();
  const Geometry& g = geometryOf(vol);
  const int axis = 1;
  const int64_t index = 9;  // coronal y = 9: pixels (u, v) = (x, z)
  LiveWire wire = liveWireOnSlice(vol, axis, index);
  EXPECT_EQ(wire.width(), 24);
  EXPECT_EQ(wire.height(), 16);
  const std::vector<PixelUV> input{{6, 4}, {17, 4}, {17, 11}, {6, 11}};
  wire.setSeed(input[0]);
  for (size_t i = 1; i < input.size(); ++i) wire.commit(input[i]);
  wire.close();
  const ContourDocument doc = contourDocument(wire, g, axis, index, {input, {}, 0}, "box.nii.gz");
  const LiveWireContour c = wire.contour();
  EXPECT_EQ(doc.file, "box.nii.gz");
  EXPECT_EQ(doc.plane, anatomicalPlaneName(sliceFrame(g, axis, index).plane));
  EXPECT_EQ(doc.axis, axis);
  EXPECT_EQ(doc.index, index);
  EXPECT_EQ(doc.width, 24);
  EXPECT_EQ(doc.height, 16);
  EXPECT_DOUBLE_EQ(doc.spacingU, 0.8);
  EXPECT_DOUBLE_EQ(doc.spacingV, 1.5);
  EXPECT_EQ(doc.costKind, "mb");
  ASSERT_TRUE(doc.weights.has_value());
  EXPECT_EQ(doc.connectivity, wire.options().connectivity);
  EXPECT_TRUE(doc.closed);
  EXPECT_EQ(doc.points, c.pixels);
  EXPECT_EQ(doc.clicks, input);  // no snapping: the seeds are the input
  EXPECT_EQ(doc.clicksInput, input);
  ASSERT_EQ(doc.pointsIndex.size(), c.pixels.size());
  ASSERT_EQ(doc.pointsWorld.size(), c.pixels.size());
  ASSERT_EQ(doc.pointsPicture.size(), c.pixels.size());
  const SliceFrame frame = sliceFrame(g, axis, index);
  for (size_t i = 0; i < c.pixels.size(); ++i) {
    const Index3 want{c.pixels[i][0], index, c.pixels[i][1]};
    EXPECT_EQ(doc.pointsIndex[i], want);
    const Vec3 ci = Vec3(double(want[0]), double(want[1]), double(want[2]));
    EXPECT_NEAR((doc.pointsWorld[i] - g.indexToWorld(ci)).norm(), 0, 1e-12);
    EXPECT_EQ(doc.pointsPicture[i], frame.pictureOf(ci));
  }
  EXPECT_DOUBLE_EQ(doc.lengthMm, c.lengthMm);
  EXPECT_DOUBLE_EQ(doc.cost, c.cost);
  ASSERT_EQ(doc.segments.size(), wire.segments().size());
  for (size_t i = 0; i < doc.segments.size(); ++i) {
    EXPECT_EQ(doc.segments[i].from, wire.segments()[i].from);
    EXPECT_EQ(doc.segments[i].pixels, static_cast<int64_t>(wire.segments()[i].pixels.size()));
  }
  // The pixels inside the contour, boundary included: the box's 12 x 8, or its edge ring beside.
  ASSERT_TRUE(doc.areaPixels.has_value());
  int64_t inside = 0;
  for (uint8_t m : fillContour(c.pixels, 24, 16)) inside += m;
  EXPECT_EQ(*doc.areaPixels, inside);
  EXPECT_GE(*doc.areaPixels, 12 * 8);
  EXPECT_LE(*doc.areaPixels, 14 * 10);
  EXPECT_DOUBLE_EQ(*doc.areaMm2, double(inside) * 0.8 * 1.5);
  EXPECT_TRUE(doc.mask.empty());
}

TEST(LiveWireDocument, OpenContourHasNoAreaAndSlicesOutsideAreRefused) {
  const AnyVolume vol = boxVolume();
  LiveWire wire = liveWireOnSlice(vol, 2, 8);
  wire.setSeed({6, 2});
  wire.commit({17, 2}, Progress::none());
  const ContourDocument doc = contourDocument(wire, geometryOf(vol), 2, 8, {{{6, 2}, {17, 2}}, {}, 0});
  EXPECT_FALSE(doc.closed);
  EXPECT_FALSE(doc.areaPixels.has_value());
  EXPECT_FALSE(doc.areaMm2.has_value());
  EXPECT_EQ(doc.plane, "axial");
  EXPECT_THROW(liveWireOnSlice(vol, 2, 16), InvalidArgument);
  EXPECT_THROW(liveWireOnSlice(vol, 3, 0), InvalidArgument);
}

}  // namespace
}  // namespace vs
