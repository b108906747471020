// Cross-sections and tree measures against the exact truth of the tube phantoms, on the test
// seeds fixed in docs/notes/quantify.md (tuning used other seeds: bench/quantify_tune.cpp).
#include "quantify/quantify.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "quantify/report.h"
#include "quantify_cases.h"
#include "util/error.h"

namespace vs {
namespace {

using testq::Case;

TreeMeasurement measureCase(const TubePhantom& ph, double jitterVoxels = 0.3, double hint = 0.7) {
  const Tree tree = testq::truthTree(ph.truth, jitterVoxels * ph.truth.spacing.minCoeff(), hint);
  return measureTree(ph.volume, tree);
}

void expectDiameters(const Case& c) {
  SCOPED_TRACE("seed " + std::to_string(c.seed) + " " + tubeKindName(c.kind) + " r " + std::to_string(c.radiusVoxels));
  const TubePhantom ph = testq::makeCase(c);
  const TreeMeasurement m = measureCase(ph);
  EXPECT_EQ(m.polarity, c.dark ? LumenPolarity::Dark : LumenPolarity::Bright);
  const testq::DiameterStats st = testq::diameterStats(ph.truth, m);
  std::printf("seed %llu %s r %.2f vox spacing %.2f,%.2f,%.2f: %d/%d measured, |err| %.3f vox (signed %+.3f), %.1f%%\n",
              static_cast<unsigned long long>(c.seed), tubeKindName(c.kind).c_str(), c.radiusVoxels,
              ph.truth.spacing[0], ph.truth.spacing[1], ph.truth.spacing[2], st.measured, st.total,
              st.meanAbsErrorVoxels, st.meanErrorVoxels, 100 * st.meanAbsRelError);
  EXPECT_GE(st.measured, st.total / 2);
  if (c.radiusVoxels >= 1.5)
    EXPECT_LE(st.meanAbsErrorVoxels, 0.3);
  else
    EXPECT_LE(st.meanAbsRelError, 0.10);
}

TEST(Quantify, ConstantRadiusTubes) {
  const double radii[] = {1.0, 1.25, 1.5, 2, 3, 5, 7, 10};
  for (uint64_t k = 0; k < 8; ++k) expectDiameters({1001 + k, TubeKind::Straight, radii[k], 1001 + k == 1005});
}

TEST(Quantify, CurvedTubes) {
  expectDiameters({1101, TubeKind::Curved, 2});
  expectDiameters({1102, TubeKind::Curved, 3});
  expectDiameters({1103, TubeKind::Curved, 4, true});
}

TEST(Quantify, TaperAndEllipticSections) {
  expectDiameters({1201, TubeKind::Taper, 4});
  expectDiameters({1202, TubeKind::Taper, 3});
  for (uint64_t seed : {1301, 1302}) {
    const Case c{seed, TubeKind::Elliptic, 4};
    expectDiameters(c);
    const TubePhantom ph = testq::makeCase(c);
    const TreeMeasurement m = measureCase(ph);
    const TubeBranch& b = ph.truth.branches[0];
    double errMin = 0, errMax = 0;
    int n = 0;
    for (const auto& cs : m.sections) {
      if (!cs.measured()) continue;
      errMin += std::abs(cs.minDiameterMm - 2 * b.semiB(0)) / ph.truth.radiusUnitMm;
      errMax += std::abs(cs.maxDiameterMm - 2 * b.semiA(0)) / ph.truth.radiusUnitMm;
      // The minimum diameter runs along the b axis, perpendicular to the a axis.
      EXPECT_LT(std::abs(cs.minDirection.dot(b.aAxis)), 0.3);
      ++n;
    }
    ASSERT_GT(n, 0);
    std::printf("seed %llu elliptic aspect %.2f: min Feret |err| %.3f vox, max Feret |err| %.3f vox\n",
                static_cast<unsigned long long>(seed), b.aspect, errMin / n, errMax / n);
    EXPECT_LE(errMin / n, 0.5);
    EXPECT_LE(errMax / n, 0.5);
  }
}

TEST(Quantify, Stenoses) {
  for (uint64_t seed = 1401; seed <= 1406; ++seed) {
    const Case c{seed, TubeKind::Stenosis, 4};
    const TubePhantom ph = testq::makeCase(c);
    const TreeMeasurement m = measureCase(ph);
    ASSERT_EQ(m.segments.size(), 1u);
    const SegmentMeasure& s = m.segments[0];
    const TubeBranch& b = ph.truth.branches[0];
    std::printf("seed %llu stenosis %.1f%% over %.1f mm: measured %.1f%% (d_min %.2f mm, d_ref %.2f mm)\n",
                static_cast<unsigned long long>(seed), 100 * b.stenosisDegree, b.stenosisLengthMm, 100 * s.stenosis,
                s.minDiameterMm, s.referenceDiameterMm);
    EXPECT_NEAR(s.stenosis, b.stenosisDegree, 0.05) << "seed " << seed;
    ASSERT_EQ(m.paths.size(), 1u);
    EXPECT_NEAR(m.paths[0].stenosis, s.stenosis, 1e-12);
  }
}

TEST(Quantify, BifurcationAnglesAndTopology) {
  for (uint64_t seed = 1501; seed <= 1505; ++seed) {
    const Case c{seed, TubeKind::Bifurcation, 3};
    const TubePhantom ph = testq::makeCase(c);
    const TreeMeasurement m = measureCase(ph);
    ASSERT_EQ(m.segments.size(), 3u);
    ASSERT_EQ(m.branchPoints.size(), 1u);
    ASSERT_EQ(m.paths.size(), 2u);
    const BranchPointMeasure& bp = m.branchPoints[0];
    ASSERT_EQ(bp.pairAnglesDeg.size(), 1u);
    std::printf("seed %llu bifurcation %.1f deg: measured %.1f deg (children %.1f, %.1f; truth %.1f each)\n",
                static_cast<unsigned long long>(seed), ph.truth.bifurcationDeg, bp.pairAnglesDeg[0],
                bp.childAnglesDeg[0], bp.childAnglesDeg[1], 0.5 * ph.truth.bifurcationDeg);
    EXPECT_NEAR(bp.pairAnglesDeg[0], ph.truth.bifurcationDeg, 5.0) << "seed " << seed;
    for (double a : bp.childAnglesDeg) EXPECT_NEAR(a, 0.5 * ph.truth.bifurcationDeg, 5.0) << "seed " << seed;
    EXPECT_EQ(m.segments[0].generation, 0);
    EXPECT_EQ(m.segments[0].strahler, 2);
    for (int s : {1, 2}) {
      EXPECT_EQ(m.segments[static_cast<size_t>(s)].generation, 1);
      EXPECT_EQ(m.segments[static_cast<size_t>(s)].strahler, 1);
      EXPECT_EQ(m.segments[static_cast<size_t>(s)].parent, 0);
    }
    // Sections at the junction are flagged, the others measured.
    int meets = 0;
    for (const auto& cs : m.sections) meets += (cs.flags & kSectionMeetsBranch) != 0;
    EXPECT_GT(meets, 0);
    EXPECT_TRUE(std::isnan(m.sections[static_cast<size_t>(m.segments[0].sections.back())].equivalentDiameterMm));
    const testq::DiameterStats st = testq::diameterStats(ph.truth, m);
    EXPECT_LE(st.meanAbsErrorVoxels, 0.3) << "seed " << seed;
  }
}

TEST(Quantify, MeasuredRadiiForSwc) {
  const TubePhantom ph = testq::makeCase({1004, TubeKind::Straight, 2});
  const Tree tree = testq::truthTree(ph.truth, 0, 2.0);  // radii twice the truth
  const TreeMeasurement m = measureTree(ph.volume, tree);
  const Tree out = treeWithMeasuredRadii(m);
  ASSERT_EQ(out.size(), tree.size());
  double err = 0;
  for (size_t i = 0; i < out.size(); ++i) err += std::abs(out.radii[i] - 0.5 * tree.radii[i]);
  EXPECT_LT(err / static_cast<double>(out.size()) / ph.truth.radiusUnitMm, 0.3);
}

TEST(Quantify, TreeOfAnotherVolumeIsAnError) {
  const TubePhantom ph = testq::makeCase({1004, TubeKind::Straight, 2});
  Tree tree = testq::truthTree(ph.truth, 0, 1.0);
  for (auto& p : tree.points) p += Vec3(500, 0, 0);
  try {
    measureTree(ph.volume, tree);
    FAIL() << "no error";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("does not belong"), std::string::npos) << e.what();
  }
  EXPECT_THROW(measureTree(ph.volume, Tree{}), DataError);
}

TEST(Quantify, SectionsLeavingTheVolumeAreFlagged) {
  // The tree runs to the volume's faces: the sections there leave the volume and carry no numbers.
  const TubePhantom ph = testq::makeCase({1004, TubeKind::Straight, 2});
  const TreeMeasurement m = measureCase(ph);
  int leaving = 0;
  for (const auto& cs : m.sections)
    if (cs.flags & kSectionLeavesVolume) {
      ++leaving;
      EXPECT_TRUE(std::isnan(cs.equivalentDiameterMm));
      EXPECT_TRUE(std::isnan(cs.areaMm2));
    }
  EXPECT_GT(leaving, 0);
  // For colouring by diameter the flagged sections give NaN radii (grey), the rest as for the SWC.
  const Tree plain = treeWithMeasuredRadii(m), flagged = treeWithMeasuredRadii(m, /*flaggedAsNaN=*/true);
  ASSERT_EQ(flagged.radii.size(), plain.radii.size());
  int nan = 0;
  for (size_t i = 0; i < plain.radii.size(); ++i) {
    if (std::isnan(flagged.radii[i]))
      ++nan;
    else
      EXPECT_DOUBLE_EQ(flagged.radii[i], plain.radii[i]) << "node " << i;
    EXPECT_TRUE(std::isfinite(plain.radii[i]));
  }
  EXPECT_GT(nan, 0) << "the nodes at the faces";
  EXPECT_LT(nan, static_cast<int>(plain.radii.size()) / 2);
  EXPECT_EQ(crossSectionFlagsText(kSectionLeavesVolume | kSectionMeetsBranch), "leaves_volume|meets_branch");
}

// Each branch point's neighbour sections: on the parent and on each child, the measured section
// nearest the junction that no other branch meets (the branch-point rule), with the lumen's true
// diameter there.
TEST(Quantify, BranchPointNeighbourSections) {
  for (uint64_t seed = 1501; seed <= 1505; ++seed) {
    const TubePhantom ph = testq::makeCase({seed, TubeKind::Bifurcation, 3});
    const TreeMeasurement m = measureCase(ph);
    ASSERT_EQ(m.branchPoints.size(), 1u);
    const BranchPointMeasure& bp = m.branchPoints[0];
    ASSERT_EQ(bp.childSections.size(), 2u);
    const int sections[3] = {bp.parentSection, bp.childSections[0], bp.childSections[1]};
    const int segments[3] = {bp.parentSegment, bp.childSegments[0], bp.childSegments[1]};
    const double unit = ph.truth.radiusUnitMm;
    for (int k = 0; k < 3; ++k) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " neighbour " + std::to_string(k));
      ASSERT_GE(sections[k], 0);
      const CrossSection& cs = m.sections[static_cast<size_t>(sections[k])];
      const SegmentMeasure& seg = m.segments[static_cast<size_t>(segments[k])];
      ASSERT_TRUE(cs.measured());
      EXPECT_EQ(cs.branchPoint, 0);
      EXPECT_EQ(cs.segment, segments[k]);
      EXPECT_EQ(cs.boundaryMm.size(), static_cast<size_t>(QuantifyOptions{}.rays));
      auto dist = [&](const CrossSection& c) { return k == 0 ? seg.lengthMm - c.arcMm : c.arcMm; };
      // In the segment's profile, nearest the junction of its measured sections, and less than one
      // station beyond the nearest flagged one before it.
      ASSERT_NE(std::find(seg.sections.begin(), seg.sections.end(), sections[k]), seg.sections.end());
      double flaggedBefore = -1;
      for (int i : seg.sections) {
        const CrossSection& o = m.sections[static_cast<size_t>(i)];
        if (o.measured())
          EXPECT_GE(dist(o), dist(cs) - 1e-9);
        else if (dist(o) < dist(cs))
          flaggedBefore = std::max(flaggedBefore, dist(o));
      }
      ASSERT_GE(flaggedBefore, 0) << "no flagged section between the junction and its neighbour";
      const double step = seg.lengthMm / std::round(seg.lengthMm / QuantifyOptions{}.stepMm);  // the stations'
      EXPECT_LE(dist(cs) - flaggedBefore, step + 1e-9);
      // In its own branch's lumen, with that lumen's true diameter.
      const testq::Nearest n = testq::nearestTruth(ph.truth, cs.centreMm);
      if (k == 0)
        EXPECT_EQ(n.branch, 0);
      else
        EXPECT_NE(n.branch, 0);
      const double truth = 2 * ph.truth.branches[static_cast<size_t>(n.branch)].equivalentRadiusMm(n.s);
      std::printf("seed %llu neighbour %d: %.2f mm from the branch point, d %.3f mm (truth %.3f), err %.3f vox\n",
                  static_cast<unsigned long long>(seed), k, dist(cs), cs.equivalentDiameterMm, truth,
                  (cs.equivalentDiameterMm - truth) / unit);
      EXPECT_LE(std::abs(cs.equivalentDiameterMm - truth) / unit, 0.3);
      // No other true branch's lumen crosses its plane within its boundary (the rule on the truth,
      // half a voxel of tolerance for the tree's off-centre error).
      for (size_t b = 0; b < ph.truth.branches.size(); ++b) {
        if (static_cast<int>(b) == n.branch) continue;
        const TubeBranch& br = ph.truth.branches[b];
        for (double s = 0; s <= br.lengthMm; s += 0.05) {
          const Vec3 d = br.at(s) - cs.centreMm;
          const double rb = br.equivalentRadiusMm(s), along = cs.tangent.dot(d);
          if (std::abs(along) > rb) continue;
          EXPECT_GT((d - along * cs.tangent).norm(), cs.outerRadiusMm + rb - 0.5 * unit)
              << "branch " << b << " s " << s;
        }
      }
    }
    // In the report: distances and diameters per branch point, the CSV's branch_point column.
    const nlohmann::json j = measurementToJson(m, QuantifyOptions{});
    ASSERT_EQ(j["branch_points"][0]["child_sections"].size(), 2u);
    EXPECT_GT(j["branch_points"][0]["parent_section"]["distance_mm"].get<double>(), 0);
    const std::string csv = measurementCsv(m);
    EXPECT_NE(csv.find(",flags,branch_point\n"), std::string::npos);
    size_t rows = 0;
    for (size_t p = csv.find(",0\n"); p != std::string::npos; p = csv.find(",0\n", p + 1)) ++rows;
    EXPECT_EQ(rows, 4u) << "the parent's neighbour in both paths, each child's in its own";
  }
}

}  // namespace
}  // namespace vs

namespace vs {
namespace {

TEST(Quantify, CoincidentBranchesAreMerged) {
  // Two chains leave node 0 side by side (0.5 mm apart in a lumen of radius 4 mm) for 10 mm,
  // then part: one branch point where they part, not at node 0.
  Tree t;
  auto add = [&](const Vec3& p, int32_t parent) {
    t.points.push_back(p);
    t.parent.push_back(parent);
    t.radii.push_back(4.0);
    return static_cast<int32_t>(t.points.size() - 1);
  };
  int32_t a = add({0, 0, 0}, -1), b = a;
  for (int k = 1; k <= 20; ++k) a = add({0, 0, double(k)}, a);
  for (int k = 1; k <= 16; ++k) b = add({k <= 10 ? 0.5 : 0.5 + (k - 10) * 1.5, 0, double(k)}, b);
  int merged = 0;
  const Tree m = mergeCoincidentBranches(t, &merged);
  EXPECT_EQ(merged, 1);
  m.validate();
  std::vector<int> children(m.size(), 0);
  for (int32_t p : m.parent)
    if (p >= 0) ++children[static_cast<size_t>(p)];
  int branchNode = -1;
  for (size_t i = 0; i < m.size(); ++i)
    if (children[i] >= 2) branchNode = static_cast<int>(i);
  ASSERT_GE(branchNode, 0);
  EXPECT_GT(m.points[static_cast<size_t>(branchNode)][2], 5.0);  // moved down to where they part
  EXPECT_LT(m.size(), t.size());
}

}  // namespace
}  // namespace vs
