// The neck re-search's section pieces (neck_section.h; issue 21, session 43 kindA6): the own lobe's peak climbed to
// from the path's voxel, and the grid's rim read as the background the section's levels are measured from.
#include "tracking/neck_section.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace vs {
namespace {

constexpr int kM = 20, kN = 2 * kM + 1;

// Two round lobes on a flat background: the own one (peak 100) at (own, m), the other (peak 200) at (other, m).
std::vector<double> twoLobes(int own, int other) {
  std::vector<double> v(static_cast<size_t>(kN * kN));
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x) {
      const double a = std::hypot(x - own, y - kM), b = std::hypot(x - other, y - kM);
      v[static_cast<size_t>(y * kN + x)] = 10 + 90 * std::exp(-a * a / 4) + 190 * std::exp(-b * b / 4);
    }
  return v;
}

}  // namespace

// The own lobe's peak 1 sample off the path's voxel, a brighter neighbour's 4 samples off on the other side, both
// within the reach (5): the climb stays in the own lobe (the highest sample in the reach, main's pick before kindA5,
// is the neighbour's peak).
TEST(NeckSection, ClimbStaysInTheOwnLobe) {
  const std::vector<double> v = twoLobes(kM - 1, kM + 4);
  EXPECT_EQ(climbedPeak(v, kN, kM, 5), kM * kN + kM - 1);
}

// The rim at the level only in the two lobes (tubes wider than the grid) is background; a rim sample at the level in a
// third component where the rim's noise also reaches as far below its median (a lumen wider than the grid, 6606's
// trunk: its lobes are noise) is not.
TEST(NeckSection, RimAtTheLevelOnlyInTheTwoLobes) {
  std::vector<double> v(static_cast<size_t>(kN * kN), 10.0);
  std::vector<int> lab(v.size(), -1);
  const auto set = [&](int x, int y, double value, int label) {
    v[static_cast<size_t>(y * kN + x)] = value, lab[static_cast<size_t>(y * kN + x)] = label;
  };
  set(kM, kM, 100, 0);      // the own lobe
  set(0, kM, 100, 1);       // the other lobe at the rim
  set(kM, 0, 100, 0);       // the own lobe at the rim
  set(3, kN - 1, -40, -1);  // the rim's noise 50 below its median 10
  EXPECT_TRUE(rimIsBackground(v, lab, kN, 10, 50, 0, 1));
  set(kN - 1, 3, 100, 2);  // a third component at the rim
  EXPECT_FALSE(rimIsBackground(v, lab, kN, 10, 50, 0, 1));
  set(kN - 1, 3, 40, -1);  // under the level: background again
  EXPECT_TRUE(rimIsBackground(v, lab, kN, 10, 50, 0, 1));
}

// Session 44 (kindA9): a third tube the grid's edge cuts in a flat background (511's sibling, 12124's turned-round
// trunk beside a thin fork) is no wider lumen: nothing on the rim lies as far below its median as the level lies above
// it, so the rim is background and the two lobes are a neck (kindA6's rim test read it as a wider lumen: no neck).
TEST(NeckSection, ThirdTubeAtTheRimOfAFlatBackgroundIsNoWiderLumen) {
  std::vector<double> v(static_cast<size_t>(kN * kN), 10.0);
  std::vector<int> lab(v.size(), -1);
  const auto set = [&](int x, int y, double value, int label) {
    v[static_cast<size_t>(y * kN + x)] = value, lab[static_cast<size_t>(y * kN + x)] = label;
  };
  set(kM, kM, 100, 0);
  set(0, kM, 100, 1);
  for (int y = 2; y < 8; ++y) set(kN - 1, y, 100, 2);  // the third tube's arc on the rim
  set(3, kN - 1, 5, -1);                               // the background's noise, 5 below its median
  EXPECT_TRUE(rimIsBackground(v, lab, kN, 10, 50, 0, 1));
}

}  // namespace vs
