// Colouring by diameter (issue 24): the ramp's ends, pieces and range from the radii, the bar drawn.
#include "render/colour_legend.h"

#include <gtest/gtest.h>

#include <limits>

#include "util/error.h"

namespace vs {
namespace {

TEST(ColourLegend, RampEndsAreBlueAndRed) {
  const auto lo = rampColour(0), hi = rampColour(1);
  EXPECT_GT(lo[2], lo[0]);
  EXPECT_GT(hi[0], hi[2]);
  EXPECT_EQ(rampColour(-5), lo);
  EXPECT_EQ(rampColour(7), hi);
}

TEST(ColourLegend, PiecesCarryTheirDiameterColour) {
  Polyline l;
  l.points = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2, 0, 0)};
  l.radii = {1.0, 2.0, 3.0};
  const ColouredPieces c = colourByDiameter({l});
  ASSERT_EQ(c.pieces.size(), 2u);
  EXPECT_DOUBLE_EQ(c.loMm, 2.0);
  EXPECT_DOUBLE_EQ(c.hiMm, 6.0);
  EXPECT_EQ(c.colours[0], rampColour(0.25));  // mean diameter 3 mm of 2..6
  EXPECT_EQ(c.colours[1], rampColour(0.75));
  Polyline bare;
  bare.points = l.points;
  EXPECT_THROW(colourByDiameter({bare}), InvalidArgument);
}

TEST(ColourLegend, UnmeasuredPiecesAreGreyAndOutOfTheRange) {
  Polyline l;
  l.points = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(3, 0, 0)};
  l.radii = {1.0, std::numeric_limits<double>::quiet_NaN(), 3.0, 2.0};  // a flagged section in the middle
  const ColouredPieces c = colourByDiameter({l});
  ASSERT_EQ(c.pieces.size(), 3u);
  EXPECT_EQ(c.colours[0], kUnmeasuredColour);
  EXPECT_EQ(c.colours[1], kUnmeasuredColour);
  EXPECT_EQ(c.colours[2], rampColour(0.75));  // mean diameter 5 mm of 2..6
  EXPECT_DOUBLE_EQ(c.loMm, 2.0);
  EXPECT_DOUBLE_EQ(c.hiMm, 6.0);
}

TEST(ColourLegend, TicksAreTheEndsAndTheMiddle) {
  const auto t = colourLegendTicks(1.5, 19);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].text, "1.5mm");
  EXPECT_DOUBLE_EQ(t[0].fraction, 0);
  EXPECT_DOUBLE_EQ(t[1].valueMm, 10.25);
  EXPECT_EQ(t[1].text, "10mm");
  EXPECT_EQ(t[2].text, "19mm");
  EXPECT_DOUBLE_EQ(t[2].fraction, 1);
}

TEST(ColourLegend, BarIsDrawnAtTheRight) {
  RgbaImage img(200, 200);
  drawColourLegend(img, 1.5, 19);
  int coloured = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) coloured += img.at(x, y)[3] != 0;
  EXPECT_GT(coloured, 500);
  EXPECT_EQ(img.at(10, 100)[3], 0);  // the left of the picture untouched
}

}  // namespace
}  // namespace vs
