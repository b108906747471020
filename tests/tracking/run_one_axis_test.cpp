// Session 45 (sinus83): splitForks' fused run (fork_start.cpp's twoDiscRun) is two children side by side, each as thick
// as its own tube; a run up the parent arm whose every section is thinner than the narrower child's diameter by more
// than a voxel is one flat lumen (the head CTA's sinus from 83,41,53), whose ends twoDiscs reads as two discs: no run.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

using centreline_detail::FusedRun;
using centreline_detail::RunInput;

// b at the origin; the parent arm runs down y (1 mm apart, voxel 1 mm), its first five sections two discs along x (the
// widest chord 8 mm, the narrowest `narrowMm`), every other section one round lumen 4 mm across. The two children (own
// radius 2 mm: 4 mm across) part from b up y. Returns twoDiscRun's answer.
bool runWith(double narrowMm) {
  constexpr size_t armPoints = 12, twoDiscSections = 5;
  std::vector<Vec3> q{Vec3(0, 0, 0)};
  std::vector<std::vector<size_t>> arms(3);
  for (size_t j = 1; j <= armPoints; ++j) arms[0].push_back(q.size()), q.emplace_back(0, -static_cast<double>(j), 0);
  for (size_t a = 1; a < 3; ++a)
    for (size_t j = 1; j <= armPoints; ++j) {
      const double side = a == 1 ? 1.0 : -1.0;
      arms[a].push_back(q.size()), q.emplace_back(side * 0.7 * static_cast<double>(j), static_cast<double>(j), 0);
    }
  const centreline_detail::SectionLobes lobes = [&](size_t k, double, Vec3& d, double& plus, double& minus,
                                                    double& narrowest) {
    const bool two = k >= 1 && k <= twoDiscSections;  // the parent arm's first sections
    d = Vec3(1, 0, 0), plus = two ? 4 : 2, minus = two ? 4 : 2, narrowest = two ? narrowMm : 4;
    return true;
  };
  const centreline_detail::FusedAt fusedAt = [](size_t, double) { return false; };
  const std::vector<size_t> zone{0, 2, 2};
  const std::vector<uint8_t> hasLine{1, 1, 1};
  const std::vector<double> ownR{2.5, 2.0, 2.0};
  const RunInput in{arms, zone, hasLine, ownR, q, 1.0, Vec3::Zero(), lobes, fusedAt};
  FusedRun run;
  Vec3 J, G[3];
  return centreline_detail::twoDiscRun(in, 0, run, J, G);
}

// The sinus: the run's sections 2.5 mm thick against the children's 4 mm (more than a voxel short) - one flat lumen
// 8 mm wide, not two 4 mm tubes side by side.
TEST(RunOneAxis, ARunThinnerThanTheChildrenIsOneFlatLumen) { EXPECT_FALSE(runWith(2.5)); }

// Two children fused side by side: the sections as thick as a child (4 mm; 11932's 2.8 against 2.8) or short of it by
// under a voxel (3.2 mm; 12024's arm sections 0.98 x) - the run stands.
TEST(RunOneAxis, ARunAsThickAsTheChildrenIsTheirFusedRun) {
  EXPECT_TRUE(runWith(4.0));
  EXPECT_TRUE(runWith(3.2));
}

}  // namespace
}  // namespace vs
