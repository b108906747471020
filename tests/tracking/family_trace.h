// One case of the vessel family traced with defaults and every terminal given, and the point figures on it
// (issue 21): shared by the tests that pin one tuning seed's bounds (vessel_family_test.cpp's sweeps report more).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "phantom/phantom.h"
#include "tracking/centreline.h"
#include "tracking/trace_run.h"

namespace vs {

struct FamilyTrace {
  VesselFamilyCase c;
  TraceResult r;
};

// The case of `seed` traced from its root to every terminal; every terminal must be reached.
inline FamilyTrace traceEveryTerminal(uint64_t seed, VesselFamilyVariant variant) {
  FamilyTrace f{makeVesselFamilyCase(seed, variant), {}};
  TraceRequest rq;
  rq.root = f.c.truth.rootVoxel;
  rq.targets = f.c.truth.terminalVoxels;
  f.r = runTrace(f.c.volume, rq);
  EXPECT_EQ(f.r.paths.size(), rq.targets.size());
  for (size_t i = 0; i < f.r.paths.size(); ++i) EXPECT_TRUE(f.r.paths[i].reached) << "terminal " << i;
  return f;
}

// The refined points' distance to the nearest true centreline in voxels (the smallest spacing): their count, mean
// and share within one voxel.
struct PointFigures {
  size_t n = 0;
  double meanVox = 0, within1 = 0;
};

inline PointFigures pointFigures(const VesselTruth& t, const TraceResult& r) {
  const double vox = t.spacing.minCoeff();
  PointFigures f;
  size_t within = 0;
  for (const auto& points : r.points)
    for (const Vec3& q : points) {
      const double d = distanceToCenterline(t, q).distanceMm;
      f.meanVox += d / vox, within += d <= vox, ++f.n;
    }
  if (f.n > 0) f.meanVox /= double(f.n), f.within1 = double(within) / double(f.n);
  return f;
}

// The same figures against each path's own tubes only (its terminal's branch and those up to the root), as the family
// sweep measures them (vessel_family_test.cpp): a point centred on a neighbouring tube's axis counts as off.
inline PointFigures ownPathFigures(const VesselTruth& t, const TraceResult& r) {
  const double vox = t.spacing.minCoeff();
  PointFigures f;
  size_t within = 0;
  for (size_t i = 0; i < r.points.size() && i < t.terminalBranches.size(); ++i) {
    VesselTruth own = t;
    own.branches.clear();
    for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[size_t(b)].parent)
      own.branches.push_back(t.branches[size_t(b)]);
    for (const Vec3& q : r.points[i]) {
      const double d = distanceToCenterline(own, q).distanceMm;
      f.meanVox += d / vox, within += d <= vox, ++f.n;
    }
  }
  if (f.n > 0) f.meanVox /= double(f.n), f.within1 = double(within) / double(f.n);
  return f;
}

// The share of path i's own true centreline points (its terminal's branch and those up to the root) that lie within
// their tube's radius of one of the path's refined points: whether the path covers its own route.
inline double ownRouteCovered(const VesselTruth& t, const TraceResult& r, size_t i) {
  size_t covered = 0, total = 0;
  for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[size_t(b)].parent) {
    const VesselBranch& br = t.branches[size_t(b)];
    for (size_t j = 0; j < br.points.size(); ++j) {
      double d = 1e9;
      for (const Vec3& q : r.points[i]) d = std::min(d, (q - br.points[j]).cwiseProduct(t.spacing).norm());
      covered += d <= br.radiiMm[j], ++total;
    }
  }
  return total > 0 ? double(covered) / double(total) : 0.0;
}

// The case of `seed` traced (traceEveryTerminal) and its figures printed as "[label seed] ...": against every true
// centreline, or (ownPath) against each path's own tubes only.
inline PointFigures tracedFigures(const char* label, uint64_t seed, VesselFamilyVariant variant, bool ownPath = false) {
  const FamilyTrace f = traceEveryTerminal(seed, variant);
  const PointFigures p = ownPath ? ownPathFigures(f.c.truth, f.r) : pointFigures(f.c.truth, f.r);
  std::printf("[%s %llu] %zu points: mean %.3f vox, within 1 vox %.1f%%\n", label,
              static_cast<unsigned long long>(seed), p.n, p.meanVox, 100 * p.within1);
  return p;
}

}  // namespace vs
