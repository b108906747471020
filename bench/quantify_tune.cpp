// Tuning harness of the quantification (issue 24), on tube-phantom seeds below 1000 only: the
// tests' seeds (docs/notes/quantify.md, 1001 and up) are never used while tuning. Prints per seed
// the equivalent-diameter error against the truth and, by kind, the stenosis degree or the
// bifurcation angle. Not a test: it asserts nothing.
//   bench/quantify_tune FIRST LAST KIND RADIUS_VOXELS [dark]
//   e.g. build/quantify_tune 1 20 stenosis 4
// KIND: straight, curved, taper, elliptic, stenosis, bifurcation. The tree is the true centreline
// moved off centre by 0.3 voxel with radius hints 0.7 x the truth, as in tests/quantify.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "phantom/tube_phantom.h"
#include "quantify/quantify.h"

int main(int argc, char** argv) {
  using namespace vs;
  if (argc != 5 && !(argc == 6 && std::string(argv[5]) == "dark")) {
    std::fprintf(stderr, "usage: %s FIRST LAST KIND RADIUS_VOXELS [dark]   (seeds < 1000)\n", argv[0]);
    return 2;
  }
  try {
    const unsigned long long first = std::stoull(argv[1]), last = std::stoull(argv[2]);
    const TubeKind kind = tubeKindFromName(argv[3]);
    const double radius = std::stod(argv[4]);
    if (last >= 1000) {
      std::fprintf(stderr, "tuning seeds must stay below 1000 (the test seeds)\n");
      return 2;
    }
    for (unsigned long long s = first; s <= last; ++s) {
      TubePhantomOptions o;
      o.seed = s;
      o.kind = kind;
      o.radiusVoxels = radius;
      if (argc == 6) std::swap(o.background, o.foreground);
      o.noiseSigma = 0.05 * std::abs(o.foreground - o.background);
      const TubePhantom ph = makeTubePhantom(o);
      const TubeTruth& t = ph.truth;
      const TreeMeasurement m = measureTree(ph.volume, tubeTruthTree(t, 0.3 * t.spacing.minCoeff(), 0.7));
      std::vector<Vec3> centres;
      std::vector<double> diameters;
      for (const auto& cs : m.sections)
        if (cs.measured()) centres.push_back(cs.centreMm), diameters.push_back(cs.equivalentDiameterMm);
      const TubeDiameterErrors e = tubeDiameterErrors(t, centres, diameters);
      std::printf("seed %llu %s r %.2f sp %.2f,%.2f,%.2f: %d/%zu measured, |err| %.3f vox signed %+.3f rel %.1f%%", s,
                  argv[3], radius, t.spacing[0], t.spacing[1], t.spacing[2], e.count, m.sections.size(),
                  e.meanAbsVoxels, e.meanVoxels, 100 * e.meanAbsRelative);
      if (kind == TubeKind::Stenosis && !m.segments.empty())
        std::printf(" stenosis truth %.1f%% over %.1f mm measured %.1f%% (run %.1f mm)",
                    100 * t.branches[0].stenosisDegree, t.branches[0].stenosisLengthMm, 100 * m.segments[0].stenosis,
                    m.segments[0].stenosisLengthMm);
      if (kind != TubeKind::Stenosis)  // a stenosis reported on a tube without one: a false positive
        for (const auto& seg : m.segments)
          if (std::isfinite(seg.stenosis)) std::printf(" FALSE stenosis %.1f%%", 100 * seg.stenosis);
      if (kind == TubeKind::Bifurcation && !m.branchPoints.empty() && !m.branchPoints[0].pairAnglesDeg.empty())
        std::printf(" angle truth %.1f measured %.1f", t.bifurcationDeg, m.branchPoints[0].pairAnglesDeg[0]);
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "quantify_tune: %s\n", e.what());
    return 1;
  }
  return 0;
}
