// Session 34 (cross34): a child entered mid-way through a contact with its sibling (issue 21). The root fork's
// child 1 loops back and touches / crosses its sibling 2 past the fork; every path to child 1's subtree ran up 2 and
// cut through the contact into 1 (both routes at the cost floor, the shortcut the shorter), so child 1's first part
// was never traced. The looped-contact re-search (contact_retrace.h) follows the tube entered back from the contact
// to the fork and searches the stretch again from there with the sibling's stretch blocked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/centreline.h"
#include "tracking/trace_run.h"

namespace vs {
namespace {

// The share of branch b's truth points that some path's refined polyline passes within its radius (at least a
// voxel) of.
double branchCovered(const VesselTruth& t, const TraceResult& r, size_t b) {
  const double vox = t.spacing.minCoeff();
  const VesselBranch& br = t.branches[b];
  size_t covered = 0;
  for (size_t j = 0; j < br.points.size(); ++j) {
    const Vec3 x = br.points[j].cwiseProduct(t.spacing);
    const double reach = std::max(br.radiiMm[j], vox);
    bool near = false;
    for (size_t i = 0; i < r.points.size() && !near; ++i)
      for (size_t k = 0; k < r.points[i].size() && !near; ++k) {
        const Vec3 a = r.points[i][k].cwiseProduct(t.spacing);
        const Vec3 ab = (k + 1 < r.points[i].size() ? r.points[i][k + 1].cwiseProduct(t.spacing) : a) - a;
        const double s = ab.squaredNorm() > 0 ? std::clamp((x - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
        near = (a + s * ab - x).norm() <= reach;
      }
    covered += near;
  }
  return br.points.empty() ? 1 : double(covered) / double(br.points.size());
}

// Tuning-grade seed 11622 (thin forced, 0.89 x 0.89 x 2.03 mm): branch 1 loops back over the fork and crosses
// branch 2 at 77 degrees; on main the paths to branch 1's subtree went fork -> 2 -> through the crossing (branch 1's
// first 28 voxels never traced, 97.8 % within 1 voxel).
TEST(LoopedContact, ChildEnteredThroughItsSiblingsContactTracedFromTheFork) {
  const VesselFamilyCase c = makeVesselFamilyCase(11622, VesselFamilyVariant::Thin);
  const VesselTruth& t = c.truth;
  TraceRequest rq;
  rq.root = t.rootVoxel;
  rq.targets = t.terminalVoxels;
  const TraceResult r = runTrace(c.volume, rq);
  ASSERT_EQ(r.paths.size(), t.terminalVoxels.size());
  const double vox = t.spacing.minCoeff();
  double sum = 0;
  size_t n = 0, within1 = 0;
  for (size_t i = 0; i < r.paths.size(); ++i) {
    EXPECT_TRUE(r.paths[i].reached) << "terminal " << i;
    for (const Vec3& q : r.points[i]) {
      const CenterlineDistance d = distanceToCenterline(t, q);
      sum += d.distanceMm / vox, within1 += d.distanceMm <= vox, ++n;
    }
  }
  ASSERT_GT(n, 0u);
  const double covered = branchCovered(t, r, 1);
  std::printf("[looped contact 11622] %zu points: mean %.3f vox, within 1 vox %.1f%%, branch 1 covered %.1f%%\n", n,
              sum / double(n), 100.0 * double(within1) / double(n), 100 * covered);
  EXPECT_GE(double(within1) / double(n), 0.98);
  EXPECT_LE(sum / double(n), 0.35);
  EXPECT_GE(covered, 0.95);  // main: the first 28 voxels of branch 1 on no path
}

}  // namespace
}  // namespace vs
