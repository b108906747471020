// The cutting surface alone (eq. 14-18), on a fixed contour: what the image term does and does not
// do to the surface.
#include "cutting/cutting_surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

using vs::Vec3;

// A block of tissue (100) filling the middle of a 40 mm cube, brighter (160) above a plane tilted
// 0.3 mm per mm in x through (20, ., 20): an internal interface that crosses the contour's plane
// z = 20 along x = 20. Values by voxel centre with a 1 mm linear ramp across the interface.
struct TiltedInterface {
  vs::VolumeF32 v;
  std::vector<Vec3> contour;  // a circle of radius 10 mm in the plane z = 20, world mm
  static double interfaceZ(double x) { return 20 + 0.5 * (x - 20); }
};

TiltedInterface tiltedInterface() {
  vs::Geometry g;
  g.dims = {41, 41, 41};
  g.spacing = Vec3(1, 1, 1);
  TiltedInterface c{vs::VolumeF32(g), {}};
  for (int64_t z = 0; z < 41; ++z)
    for (int64_t y = 0; y < 41; ++y)
      for (int64_t x = 0; x < 41; ++x) {
        const bool inBlock = x >= 3 && x <= 37 && y >= 3 && y <= 37 && z >= 3 && z <= 37;
        // Distance above the interface, along z (the ramp is 1 mm wide there).
        const double above = double(z) - TiltedInterface::interfaceZ(double(x));
        c.v(x, y, z) = inBlock ? float(100 + 60 * std::clamp(0.5 + above, 0.0, 1.0)) : 0.0f;
      }
  for (int i = 0; i < 24; ++i) {
    const double phi = 2 * M_PI * i / 24;
    c.contour.push_back(Vec3(20 + 10 * std::cos(phi), 20 + 10 * std::sin(phi), 20));
  }
  return c;
}

// World z of the surface at each pixel at least `ring` hops inside the contour, and the interface's.
void insideHeights(const vs::CuttingSurface& s, int ring, std::vector<double>& surface, std::vector<double>& edge) {
  for (int64_t y = 0; y < s.height; ++y)
    for (int64_t x = 0; x < s.width; ++x)
      if (s.inDomain(x, y) && s.ring[size_t(y * s.width + x)] >= ring) {
        const Vec3 p = s.point(x, y);
        surface.push_back(p.z());
        edge.push_back(TiltedInterface::interfaceZ(p.x()));
      }
}

// With w_g = 0 the image must not move the surface at all: it is the shape without contrast (here
// the plane of the contour), even where that plane happens to cross the interface. Before issue 26's
// session 9 the ridge step still pulled those pixels onto the edge's ridge with w_g = 0.
TEST(CuttingSurface, ZeroImageWeightLeavesTheImageOut) {
  const TiltedInterface c = tiltedInterface();
  vs::CuttingSurfaceOptions o;
  o.wg = 0;
  const vs::CuttingSurface s = vs::buildCuttingSurface(c.v, 50, c.contour, o);
  std::vector<double> surface, edge;
  insideHeights(s, 1, surface, edge);
  ASSERT_GT(surface.size(), 200u);
  double worst = 0;
  for (double z : surface) worst = std::max(worst, std::abs(z - 20));
  std::printf("w_g 0: %zu pixels, largest height off the contour's plane %.3g mm; image energy %g\n", surface.size(),
              worst, s.energy.image);
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(s.energy.image, 0.0);
  EXPECT_GT(s.energy.edgeWithinReach, 100.0);  // the interface is there, within reach: the weight alone leaves it
}

// With the default w_g the surface leaves the plane and lies on the tilted interface inside the
// contour (its rim is held at the contour), and the image term is the larger share of the energy.
TEST(CuttingSurface, DefaultImageWeightFollowsAnInterfaceAcrossThePlane) {
  const TiltedInterface c = tiltedInterface();
  const vs::CuttingSurface s = vs::buildCuttingSurface(c.v, 50, c.contour, {});
  std::vector<double> surface, edge;
  insideHeights(s, 3, surface, edge);
  ASSERT_GT(surface.size(), 100u);
  std::vector<double> off, plane;
  for (size_t i = 0; i < surface.size(); ++i) {
    off.push_back(std::abs(surface[i] - edge[i]));
    plane.push_back(std::abs(edge[i] - 20));
  }
  std::nth_element(off.begin(), off.begin() + long(off.size() / 2), off.end());
  std::nth_element(plane.begin(), plane.begin() + long(plane.size() / 2), plane.end());
  const double medianOff = off[off.size() / 2], medianPlane = plane[plane.size() / 2];
  std::printf("w_g 1: median |surface - interface| %.3f mm (the plane: %.3f mm); image share %.2f\n", medianOff,
              medianPlane, s.energy.share(s.energy.image));
  EXPECT_LT(medianOff, 0.5);
  EXPECT_GT(medianPlane, 2 * medianOff);  // the case is not one the plane already solves
  EXPECT_GT(s.energy.share(s.energy.image), 0.5);
}

}  // namespace
