// End to end: `runTrace` (auto cost, refined centreline) on a curved tube phantom, then
// measureTree on the traced tree: length and diameters against the exact truth (test seeds of
// docs/notes/quantify.md).
#include <gtest/gtest.h>

#include <cstdio>

#include "quantify/quantify.h"
#include "quantify_cases.h"
#include "tracking/trace_run.h"

namespace vs {
namespace {

TEST(QuantifyTrace, CurvedTubeLengthAndDiameter) {
  for (uint64_t seed : {1601, 1602}) {
    const TubePhantom ph = testq::makeCase({seed, TubeKind::Curved, 3});
    const TubeTruth& t = ph.truth;
    const double r = t.branches[0].radiusMm;
    const std::vector<double> arcs = tubeArcsInside(t, 0, 3 * r + 2, 0.5);
    ASSERT_GT(arcs.size(), 10u);
    const Geometry& g = ph.volume.geometry();
    TraceRequest rq;
    rq.root = roundIndex(g.worldToIndex(t.branches[0].at(arcs.front())));
    rq.targets = {roundIndex(g.worldToIndex(t.branches[0].at(arcs.back())))};
    const TraceResult tr = runTrace(ph.volume, rq);
    ASSERT_TRUE(tr.refined);
    const TreeMeasurement m = measureTree(ph.volume, tr.tree);
    ASSERT_EQ(m.paths.size(), 1u);
    // The truth between the projections of the path's ends onto the true centreline.
    const testq::Nearest a = testq::nearestTruth(t, tr.tree.points[static_cast<size_t>(m.segments[0].nodes.front())]);
    const testq::Nearest b = testq::nearestTruth(t, tr.tree.points[static_cast<size_t>(m.paths[0].tipNode)]);
    const double truth = std::abs(b.s - a.s);
    const testq::DiameterStats st = testq::diameterStats(t, m);
    std::printf(
        "seed %llu traced curved tube: length %.2f mm, truth %.2f mm (%+.2f%%); %d/%d sections measured, "
        "|d err| %.3f vox\n",
        static_cast<unsigned long long>(seed), m.paths[0].lengthMm, truth, 100 * (m.paths[0].lengthMm / truth - 1),
        st.measured, st.total, st.meanAbsErrorVoxels);
    EXPECT_NEAR(m.paths[0].lengthMm, truth, 0.02 * truth) << "seed " << seed;
    EXPECT_LE(st.meanAbsErrorVoxels, 0.3) << "seed " << seed;
    EXPECT_GE(st.measured, st.total / 2);
  }
}

}  // namespace
}  // namespace vs
