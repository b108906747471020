// Session 44 (kindC7): sectionRun's fused test (fork_sections.cpp) reads the parent's lumen from the parent's own
// sections before the fork, not from its analysed radius. kindC6's form (the analysed diameter + the grid's spacing)
// fired at real forks whose parent's sections read wider than that diameter all along (a non-round, tapering or
// widening lumen: head CTA 83,41,53, 130,77,128, 94,132,8 re-branched, their side-by-side measure 0.010 -> 0.045).
#include "tracking/fork_sections.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace vs {
namespace {

using centreline_detail::FusedAt;
using centreline_detail::RunInput;
using centreline_detail::SectionLobes;

// A fork at b = point 0 (1 mm grid): the parent arm up +z (points 1-24), two children down at 27 degrees either side
// (points 25-34, 35-44). The parent's analysed radius 2 mm (diameter 4, kindC6's round lumen 5 mm), but its own
// sections read `parentMm` wide past the junction's reach (10 mm); `nearMm` gives the widest chords of b, its parent
// and the children's first two points, point 2 (J) reads 4.9 mm, the children's tubes 3 mm further on. Every
// section's narrowest chord 3 mm (the parent's across: 3 + 1 mm at most for a fused fork), b's and its parent's
// `nearAcrossMm`.
struct Fork {
  std::vector<Vec3> q;
  std::vector<std::vector<size_t>> arms{{}, {}, {}};
  std::vector<double> width, narrow;
  double nearAcrossMm_ = 3.0;
  Fork(double parentMm, double nearMm, double nearAcrossMm = 3.0) {
    nearAcrossMm_ = nearAcrossMm;
    q.push_back(Vec3(0, 0, 0));
    width.push_back(nearMm);
    for (int i = 1; i <= 24; ++i) {
      arms[0].push_back(q.size());
      q.push_back(Vec3(0, 0, i));
      width.push_back(i == 1 ? nearMm : i == 2 ? 4.9 : parentMm);
    }
    for (int a = 1; a <= 2; ++a)
      for (int k = 1; k <= 10; ++k) {
        arms[a].push_back(q.size());
        q.push_back(Vec3((a == 1 ? 0.5 : -0.5) * k, 0, -k));
        width.push_back(k <= 2 ? nearMm : 3.0);
      }
  }
  bool run(Vec3& J) {
    narrow.assign(q.size(), 3.0);
    narrow[0] = narrow[1] = nearAcrossMm_;
    const std::vector<size_t> zone{0, 3, 3};
    const std::vector<uint8_t> hasLine{1, 1, 1};
    const std::vector<double> ownR{2.0, 1.5, 1.5};
    const SectionLobes lobes = [this](size_t k, double, Vec3& dir, double& plus, double& minus, double& narrowest) {
      dir = Vec3(1, 0, 0), plus = minus = 0.5 * width[k], narrowest = narrow[k];
      return true;
    };
    const FusedAt fusedAt = [](size_t, double) { return false; };
    const RunInput in{arms, zone, hasLine, ownR, q, 1.0, Vec3(1, 1, 1), lobes, fusedAt};
    Vec3 G[3];
    return centreline_detail::sectionRun(in, 0, J, G);
  }
};

// The parent's own sections 5.2 mm wide, b's and its neighbours' 5.9: a section 0.7 mm wider than the parent's own is
// within the grid's spacing of it - the parent's lumen, not two children side by side. kindC6's test (5.9 > 4 + 1)
// re-branched it.
TEST(ForkSections, SectionWithinTheParentsOwnWidthIsNoFusedRun) {
  Vec3 J;
  EXPECT_FALSE(Fork(5.2, 5.9).run(J));
}

// The same parent, b's and its neighbours' sections 7.4 mm wide (6321's b: two children's tubes side by side): more
// than the parent's own width and a spacing - the fused run, J at point 2 where the section is the parent's again.
TEST(ForkSections, SectionWiderThanTheParentsOwnByASpacingIsAFusedRun) {
  Vec3 J;
  ASSERT_TRUE(Fork(5.2, 7.4).run(J));
  EXPECT_NEAR((J - Vec3(0, 0, 2)).norm(), 0.0, 1e-9);
}

// The same, b's and its parent's sections 7.4 mm wide but 6 mm across too: the parent's own lumen widening both ways
// (a bulb, a sinus, an aneurysm's neck: head 3DRA's fork at 128,130,172, 14.6 x 8.6 mm against the parent's 7.4 x 6.4),
// not two children side by side (each thinner than the parent: 6321's b 7.40 x 4.49 against the parent's 5.1 across).
TEST(ForkSections, SectionWiderAcrossTooIsTheParentsWideningNotAFusedRun) {
  Vec3 J;
  EXPECT_FALSE(Fork(5.2, 7.4, 6.0).run(J));
}

}  // namespace
}  // namespace vs
