// Shared helpers of the quantification tests: tube phantoms with exact truth, a tree along the
// true centreline (with a smooth off-centre error, as a tracker leaves), and the truth of a
// measured cross-section.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "phantom/tube_phantom.h"
#include "quantify/quantify.h"

namespace vs::testq {

struct Case {
  uint64_t seed;
  TubeKind kind;
  double radiusVoxels;
  bool dark = false;
};

inline TubePhantom makeCase(const Case& c) {
  TubePhantomOptions o;
  o.seed = c.seed;
  o.kind = c.kind;
  o.radiusVoxels = c.radiusVoxels;
  if (c.dark) std::swap(o.background, o.foreground);
  o.noiseSigma = 0.05 * std::abs(o.foreground - o.background);
  return makeTubePhantom(o);
}

// The true centrelines as a tree (world mm = index * spacing), every stepMm, moved off centre by
// up to jitterMm (smooth, low frequency) and with radii hintFactor x the truth.
inline Tree truthTree(const TubeTruth& t, double jitterMm, double hintFactor, double stepMm = 0.5) {
  Tree tree;
  auto add = [&](const TubeBranch& b, double s, int32_t parent) {
    const Vec3 tan = b.tangent(s);
    const Vec3 a = std::abs(tan[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    const Vec3 u = tan.cross(a).normalized(), v = tan.cross(u).normalized();
    const Vec3 off = jitterMm * (std::sin(s / 4.0 + 0.3) * u + std::cos(s / 6.0 + 1.1) * v);
    tree.points.push_back(b.at(s) + off);
    tree.parent.push_back(parent);
    tree.radii.push_back(hintFactor * b.equivalentRadiusMm(s));
    tree.types.push_back(3);
    return static_cast<int32_t>(tree.points.size() - 1);
  };
  const double margin = 0.5 * t.spacing.maxCoeff();
  std::vector<double> s0 = tubeArcsInside(t, 0, margin, stepMm);
  if (t.kind == TubeKind::Bifurcation) s0.push_back(t.branches[0].lengthMm);
  int32_t prev = -1;
  for (double s : s0) prev = add(t.branches[0], s, prev);
  const int32_t junction = prev;
  for (size_t b = 1; b < t.branches.size(); ++b) {
    int32_t p = junction;
    for (double s : tubeArcsInside(t, static_cast<int>(b), margin, stepMm))
      if (s > 0) p = add(t.branches[b], s, p);
  }
  return tree;
}

struct Nearest {
  int branch = -1;
  double s = 0, distanceMm = std::numeric_limits<double>::infinity();
};

// The nearest point of the true centrelines to a world point (brute force, 0.02 mm).
inline Nearest nearestTruth(const TubeTruth& t, const Vec3& p) {
  Nearest best;
  for (size_t b = 0; b < t.branches.size(); ++b) {
    const TubeBranch& br = t.branches[b];
    double bs = 0, bd = 1e300;
    for (double s = 0; s <= br.lengthMm; s += 0.25) {
      const double d = (br.at(s) - p).norm();
      if (d < bd) bd = d, bs = s;
    }
    for (double s = std::max(0.0, bs - 0.25); s <= std::min(br.lengthMm, bs + 0.25); s += 0.005) {
      const double d = (br.at(s) - p).norm();
      if (d < bd) bd = d, bs = s;
    }
    if (bd < best.distanceMm) best = {static_cast<int>(b), bs, bd};
  }
  return best;
}

struct DiameterStats {
  int measured = 0, total = 0;
  double meanAbsErrorVoxels = 0, meanErrorVoxels = 0, meanAbsRelError = 0;
};

// Equivalent-diameter error of the measured sections against the truth, in radius voxels (the
// largest spacing) and relative.
inline DiameterStats diameterStats(const TubeTruth& t, const TreeMeasurement& m) {
  DiameterStats st;
  st.total = static_cast<int>(m.sections.size());
  for (const auto& cs : m.sections) {
    if (!cs.measured()) continue;
    const Nearest n = nearestTruth(t, cs.centreMm);
    const double truth = 2 * t.branches[static_cast<size_t>(n.branch)].equivalentRadiusMm(n.s);
    const double e = cs.equivalentDiameterMm - truth;
    st.meanAbsErrorVoxels += std::abs(e) / t.radiusUnitMm;
    st.meanErrorVoxels += e / t.radiusUnitMm;
    st.meanAbsRelError += std::abs(e) / truth;
    ++st.measured;
  }
  if (st.measured > 0) {
    st.meanAbsErrorVoxels /= st.measured;
    st.meanErrorVoxels /= st.measured;
    st.meanAbsRelError /= st.measured;
  }
  return st;
}

}  // namespace vs::testq
