#include "cutting/cut.h"

#include <algorithm>
#include <chrono>

#include "meshops/isosurface.h"
#include "util/error.h"

namespace vs {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

CutResult cutVolume(const VolumeF32& volume, const CutOptions& o, Progress& progress) {
  VS_REQUIRE(o.pointsIndex.size() >= 3,
             "a cut needs at least 3 points around the part, got " + std::to_string(o.pointsIndex.size()));
  const Geometry& g = volume.geometry();
  CutResult r;
  std::vector<Vec3> pointsMm;
  for (const Vec3& p : o.pointsIndex) pointsMm.push_back(g.indexToWorld(p));

  auto t0 = Clock::now();
  IsoSurfaceOptions iso;
  iso.iso = o.iso;
  iso.largestComponentOnly = false;
  r.mesh = keepComponentNearest(extractIsoSurface(volume, iso, progress), pointsMm);
  r.seconds[0] = since(t0);

  t0 = Clock::now();
  const VertexFeatures features = sampleVertexFeatures(volume, r.mesh, o.cost.robustMaxPercentile);
  const CsrGraph graph = buildMeshGraph(r.mesh, features, o.cost);
  std::vector<int64_t> anchors;
  for (size_t i = 0; i < pointsMm.size(); ++i) {
    const SnapResult s = snapToMesh(r.mesh, features, pointsMm[i], o.snapRadiusMm, "point " + std::to_string(i + 1));
    anchors.push_back(s.vertex);
    r.snapDistanceMm.push_back(s.distanceMm);
  }
  r.contour = closedContour(graph, anchors, progress);
  for (int64_t v : r.contour.vertices) r.contourMm.push_back(r.mesh.positions[size_t(v)]);
  r.seconds[1] = since(t0);

  t0 = Clock::now();
  r.surface = buildCuttingSurface(volume, o.iso, r.contourMm, o.surface, progress);
  r.seconds[2] = since(t0);

  t0 = Clock::now();
  SplitOptions so;
  so.keepSeed = o.keepSeed;
  r.split = splitVolume(volume, o.iso, r.surface, so, progress);
  r.seconds[3] = since(t0);
  return r;
}

}  // namespace vs
