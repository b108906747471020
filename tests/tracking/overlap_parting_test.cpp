// Session 44 (wideT): placeOverlaps' walk back from the children's parting stops where their sections read one lumen
// over more than a child's own diameter (two_discs.cpp): the chains are one vessel there, the fork is where they part.
#include <gtest/gtest.h>

#include <functional>

#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

using centreline_detail::OverlapArms;

// Two children (radius 2 mm) whose rounds-centred chains coincide along y over their first 14 points (1 mm apart),
// then part in x. A section holds two discs (its widest chord 8 mm along x, narrowest 4 mm) where `twoAt(j)` says
// so for the arm's j-th point, else it reads one round lumen 6 mm across. Returns the points placeOverlaps moved.
size_t movedWith(const std::function<bool(size_t)>& twoAt) {
  constexpr size_t armPoints = 24, shared = 14;
  std::vector<Vec3> q{Vec3(0, 0, 0)};
  std::vector<std::vector<size_t>> arms(3);
  arms[0] = {0};
  for (int side : {1, -1})
    for (size_t j = 0; j < armPoints; ++j) {
      arms[side > 0 ? 1 : 2].push_back(q.size());
      const double x = j < shared ? 0.0 : side * 3.0 * static_cast<double>(j + 1 - shared);
      q.emplace_back(x, static_cast<double>(j + 1), 0.0);
    }
  const std::vector<size_t> zone{0, 0, 0};
  const std::vector<double> ownR{2.0, 2.0, 2.0}, radius(q.size(), 2.0);
  const centreline_detail::SectionLobes lobes = [&](size_t k, double, Vec3& d, double& plus, double& minus,
                                                    double& narrowest) {
    const bool two = twoAt((k - 1) % armPoints);
    d = Vec3(1, 0, 0), plus = two ? 4 : 3, minus = two ? 4 : 3, narrowest = two ? 4 : 6;
    return true;
  };
  std::vector<Vec3> target = q;
  std::vector<uint8_t> moved(q.size(), 0);
  std::vector<double> lobeR;
  centreline_detail::placeOverlaps(OverlapArms{arms, zone, ownR}, radius, q, 1.0, lobes, target, moved, lobeR);
  size_t n = 0;
  for (uint8_t m : moved) n += m;
  return n;
}

// The head CTA sinus (150,171,139): the chains coincide in one flat lumen from the root's neighbour and only a few
// sections next to the tree's branch point read two discs; the walk back from the parting crossed 11 mm of one lumen
// (over twice the own 4 mm diameter) and put those few points 2 mm off the vessel's axis. One vessel there: none moved.
TEST(OverlapParting, OneLumenLongerThanTheChildIsWideEndsTheWalkBack) {
  EXPECT_EQ(movedWith([](size_t j) { return j < 3; }), 0u);
}

// Two fused tubes whose sections read two discs from the parting back, but for one section (1 mm, a local misreading:
// the family's 7103) - the walk goes on past it, as before.
TEST(OverlapParting, ALocalOneLumenSectionDoesNotEndTheWalkBack) {
  EXPECT_EQ(movedWith([](size_t j) { return j != 8; }), 26u);
  EXPECT_EQ(movedWith([](size_t) { return true; }), 28u);
}

}  // namespace
}  // namespace vs
