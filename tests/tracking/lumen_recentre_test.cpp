// A route searched again in its own lumen with the medial term (lumen_recentre.h): a route along a flat lumen's side
// is moved onto the section's centre line, and a thin tube's route beside a wider touching tube stays in its own tube.
#include "tracking/lumen_recentre.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace vs {
namespace {

constexpr float kFloor = 0.001f, kWall = 1.001f;

NodeCost3D emptyCost(const Index3& dims) {
  NodeCost3D c;
  c.geometry.dims = dims;
  c.node.assign(static_cast<size_t>(c.geometry.voxelCount()), kWall);
  return c;
}

// The lumen of a cost as an image: fg on its floor voxels, bg elsewhere.
VolumeF32 imageOf(const NodeCost3D& c, double fg, double bg) {
  VolumeF32 v(c.geometry, static_cast<float>(bg));
  const Index3 d = c.geometry.dims;
  for (int64_t z = 0; z < d[2]; ++z)
    for (int64_t y = 0; y < d[1]; ++y)
      for (int64_t x = 0; x < d[0]; ++x)
        if (c.node[static_cast<size_t>(c.geometry.linear(x, y, z))] <= kFloor) v(x, y, z) = static_cast<float>(fg);
  return v;
}

std::vector<Index3> straightRoute(int64_t x0, int64_t x1, int64_t y, int64_t z) {
  std::vector<Index3> r;
  for (int64_t x = x0; x <= x1; ++x) r.push_back({x, y, z});
  return r;
}

// An elliptic lumen 12 x 4 voxels (half-axes) along x: main's floor cost holds every line along it alike; the route
// along its side (8 voxels off the centre) is moved to the centre line between its ends.
TEST(LumenRecentre, FlatLumensRouteRunsOnItsCentreLine) {
  NodeCost3D c = emptyCost({60, 40, 20});
  for (int64_t z = 0; z < 20; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 60; ++x)
        if (std::pow((y - 20.0) / 12.0, 2) + std::pow((z - 10.0) / 4.0, 2) <= 1)
          c.node[static_cast<size_t>(c.geometry.linear(x, y, z))] = kFloor;
  const std::vector<Index3> route = straightRoute(1, 58, 28, 10);
  const std::vector<Index3> out = recentreInOwnLumen(c, 0.5, route);
  ASSERT_GE(out.size(), 2u);
  EXPECT_EQ(out.front(), route.front());
  EXPECT_EQ(out.back(), route.back());
  int centred = 0, middle = 0;
  for (const Index3& v : out)
    if (v[0] >= 20 && v[0] <= 40) ++middle, centred += std::abs(v[1] - 20) <= 1 && std::abs(v[2] - 10) <= 1;
  EXPECT_GT(middle, 0);
  EXPECT_EQ(centred, middle);
}

// A thin tube (radius 2) touching a wide one (radius 6) over its middle: its route keeps to its own tube.
TEST(LumenRecentre, ThinTubesRouteBesideAWiderOneStaysInItsOwnTube) {
  NodeCost3D c = emptyCost({60, 40, 24});
  for (int64_t z = 0; z < 24; ++z)
    for (int64_t y = 0; y < 40; ++y)
      for (int64_t x = 0; x < 60; ++x) {
        const double thinY = 20 + 6 * std::abs(x - 30.0) / 30.0;  // touches the wide tube's wall at x = 30
        if (std::hypot(y - 12.0, z - 12.0) <= 6 || std::hypot(y - (thinY + 2), z - 12.0) <= 2)
          c.node[static_cast<size_t>(c.geometry.linear(x, y, z))] = kFloor;
      }
  std::vector<Index3> route;
  for (int64_t x = 1; x <= 58; ++x) route.push_back({x, std::llround(20 + 6 * std::abs(x - 30.0) / 30.0 + 2), 12});
  const std::vector<Index3> out = recentreInOwnLumen(c, 0.5, route);
  for (const Index3& v : out) {
    const double thinY = 22 + 6 * std::abs(v[0] - 30.0) / 30.0;
    EXPECT_LE(std::hypot(v[1] - thinY, v[2] - 12.0), 2.5) << v[0] << "," << v[1] << "," << v[2];
  }
}

// Two tubes of radius 3 mm whose axes lie 5 mm apart (slices 2 mm: the coarsest spacing) fuse into one lumen with no
// neck in the mask (the depth at the contact 1.7 mm against the axes' 3), a section almost twice as wide as deep like
// a flat lumen's; the image tells them apart: the own tube's intensity peaks on its axis and falls towards the
// contact, the neighbour's is brighter. The route along the own axis stays there with the image; without it the own
// lumen holds both tubes and the route is moved towards the neighbour.
TEST(LumenRecentre, FusedNeighbourBrighterInTheImageIsNotTheOwnLumen) {
  NodeCost3D c = emptyCost({60, 24, 8});
  c.geometry.spacing = Vec3(1, 1, 2);
  VolumeF32 image(c.geometry, 0.0f);
  for (int64_t z = 0; z < 8; ++z)
    for (int64_t y = 0; y < 24; ++y)
      for (int64_t x = 0; x < 60; ++x) {
        const double own = std::hypot(y - 10.0, 2 * z - 8.0), other = std::hypot(y - 15.0, 2 * z - 8.0);
        if (own > 3 && other > 3) continue;
        c.node[static_cast<size_t>(c.geometry.linear(x, y, z))] = kFloor;
        image(x, y, z) = other <= 3 ? 200.0f : static_cast<float>(60 + 40 * (1 - own * own / 9));
      }
  const std::vector<Index3> route = straightRoute(1, 58, 10, 4);
  const auto farthest = [&](const std::vector<Index3>& out) {
    double off = 0;
    for (const Index3& v : out) off = std::max(off, std::hypot(v[1] - 10.0, 2 * (v[2] - 4.0)));
    return off;
  };
  EXPECT_GE(farthest(recentreInOwnLumen(c, 0.5, route)), 1.5);  // the mask alone: moved towards the neighbour
  const std::vector<Index3> out = recentreInOwnLumen(c, 0.5, route, nullptr, {}, {&image, 1.0, 10.0});
  ASSERT_GE(out.size(), 2u);
  EXPECT_LE(farthest(out), 1.0);
}

// A lumen's voxels (a predicate on x, y, z) as a cost at the floor and an image at 200 on 30.
struct Lumen {
  NodeCost3D cost;
  VolumeF32 image;
};
Lumen lumenOf(const Index3& dims, const std::function<bool(double, double, double)>& inside) {
  Lumen l{emptyCost(dims), {}};
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x)
        if (inside(double(x), double(y), double(z)))
          l.cost.node[static_cast<size_t>(l.cost.geometry.linear(x, y, z))] = kFloor;
  l.image = imageOf(l.cost, 200, 30);
  return l;
}

// The flat lumen (semi-axes 12 x 4 voxels, along x) and the round trunk (radius 6) the tests below read.
Lumen flatLumen() {
  return lumenOf({60, 40, 20}, [](double, double y, double z) {
    return std::pow((y - 20.0) / 12.0, 2) + std::pow((z - 10.0) / 4.0, 2) <= 1;
  });
}
Lumen roundTrunk() {
  return lumenOf({60, 40, 20}, [](double, double y, double z) { return std::hypot(y - 20, z - 10) <= 6; });
}

// A route re-centred in the flat lumen runs on its centre line (y 20, z 10) over the middle (x 20-40), both ends kept.
void expectCentredOverTheMiddle(const std::vector<Index3>& route, const std::vector<Index3>& out) {
  int centred = 0, middle = 0;
  for (const Index3& v : out)
    if (v[0] >= 20 && v[0] <= 40) ++middle, centred += std::abs(v[1] - 20) <= 1 && std::abs(v[2] - 10) <= 1;
  EXPECT_GT(middle, 0);
  EXPECT_EQ(centred, middle);
  EXPECT_EQ(out.front(), route.front());
  EXPECT_EQ(out.back(), route.back());
}

// A route from a root on the lumen's side, fanned off its axis as main's flat floor leaves it.
std::vector<Index3> fannedRoute(int64_t side) {
  std::vector<Index3> r;
  for (int64_t x = 1; x <= 58; ++x) r.push_back({x, 20 + side * std::min<int64_t>(x - 1, 3), 10});
  return r;
}

// The start of a route in a flat lumen (12 x 4 voxels semi-axes) reads flat; in two round tubes of radius 3.6 touching
// along their length (a kiss: one lumen in the mask) it reads their waist; in a round trunk of radius 6 it reads round.
// Without the image nothing reads flat.
TEST(LumenRecentre, OnlyAFlatLumensStartReadsFlat) {
  const Lumen flat = flatLumen();
  const Lumen kiss = lumenOf({60, 40, 20}, [](double, double y, double z) {
    return std::hypot(y - 16.5, z - 10.0) <= 3.6 || std::hypot(y - 23.5, z - 10.0) <= 3.6;
  });
  const Lumen round = roundTrunk();
  const RecentreImage none{};
  for (const int64_t side : {1, -1}) {
    const std::vector<Index3> r = fannedRoute(side);
    EXPECT_TRUE(routeStartReadsFlat(flat.cost.geometry, r, 4.0, {&flat.image, 1.0, 10.0, 30.0}));
    EXPECT_FALSE(routeStartReadsFlat(flat.cost.geometry, r, 4.0, none));
    EXPECT_FALSE(routeStartReadsFlat(kiss.cost.geometry, r, 4.0, {&kiss.image, 1.0, 10.0, 30.0}));
    EXPECT_FALSE(routeStartReadsFlat(round.cost.geometry, r, 6.0, {&round.image, 1.0, 10.0, 30.0}));
  }
}

// The centring the flat reading gates (flatre's, the mask alone): routes fanned across the flat lumen from its root
// end on the centre line over its middle, both ends kept.
TEST(LumenRecentre, FlatLumensFannedRoutesRunOnItsCentreLine) {
  const Lumen flat = flatLumen();
  for (const int64_t side : {1, -1}) {
    const std::vector<Index3> r = fannedRoute(side);
    const std::vector<Index3> out = recentreInOwnLumen(flat.cost, 0.5, r);
    expectCentredOverTheMiddle(r, out);
  }
}

// A route from the root on the axis that first crosses the flat lumen to its edge (along the major axis, as main's
// flat floor leads a route heading for an ostium at the edge), then runs along the edge: its start cuts the lumen along
// its length, yet the lumen's own sections there read flat (session 50 flatlumen2, 604).
std::vector<Index3> crossingRoute(int64_t side) {
  std::vector<Index3> r;
  for (int64_t k = 0; k <= 10; ++k) r.push_back({2, 20 + side * k, 10});
  for (int64_t x = 3; x <= 58; ++x) r.push_back({x, 20 + side * 10, 10});
  return r;
}

TEST(LumenRecentre, AStartCrossingAFlatLumenReadsFlat) {
  const Lumen flat = flatLumen();
  const Lumen round = roundTrunk();
  for (const int64_t side : {1, -1}) {
    EXPECT_TRUE(routeStartReadsFlat(flat.cost.geometry, crossingRoute(side), 4.0, {&flat.image, 1.0, 10.0, 30.0}));
    std::vector<Index3> r;  // across the round trunk to its wall, then along it
    for (int64_t k = 0; k <= 4; ++k) r.push_back({2, 20 + side * k, 10});
    for (int64_t x = 3; x <= 58; ++x) r.push_back({x, 20 + side * 4, 10});
    EXPECT_FALSE(routeStartReadsFlat(round.cost.geometry, r, 6.0, {&round.image, 1.0, 10.0, 30.0}));
  }
}

// The same route re-centred: the lumen's own sections (not the planes normal to the route, which cut the lumen along
// its length where the route crosses it and centre the route on itself) put it on the centre line over the middle.
TEST(LumenRecentre, ARouteCrossingAFlatLumenIsCentredOnItsCentreLine) {
  const Lumen flat = flatLumen();
  for (const int64_t side : {1, -1}) {
    const std::vector<Index3> r = crossingRoute(side);
    const std::vector<Index3> out = recentreInOwnLumen(flat.cost, 0.5, r);
    expectCentredOverTheMiddle(r, out);
  }
}

}  // namespace
}  // namespace vs
