// Shared helpers of the quantification tests: tube phantoms with exact truth, a tree along the
// true centreline (with a smooth off-centre error, as a tracker leaves), and the truth of a
// measured cross-section.
#pragma once

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

inline Tree truthTree(const TubeTruth& t, double jitterMm, double hintFactor, double stepMm = 0.5) {
  return tubeTruthTree(t, jitterMm, hintFactor, stepMm);
}

using Nearest = TubeNearest;
inline Nearest nearestTruth(const TubeTruth& t, const Vec3& p) { return nearestTubeCentre(t, p); }

struct DiameterStats {
  int measured = 0, total = 0;
  double meanAbsErrorVoxels = 0, meanErrorVoxels = 0, meanAbsRelError = 0;
};

// Equivalent-diameter error of the measured sections against the truth (phantom/tube_phantom.h
// tubeDiameterErrors), in radius voxels (the largest spacing) and relative.
inline DiameterStats diameterStats(const TubeTruth& t, const TreeMeasurement& m) {
  std::vector<Vec3> centres;
  std::vector<double> diameters;
  for (const auto& cs : m.sections)
    if (cs.measured()) centres.push_back(cs.centreMm), diameters.push_back(cs.equivalentDiameterMm);
  const TubeDiameterErrors e = tubeDiameterErrors(t, centres, diameters);
  return {e.count, static_cast<int>(m.sections.size()), e.meanAbsVoxels, e.meanVoxels, e.meanAbsRelative};
}

}  // namespace vs::testq
