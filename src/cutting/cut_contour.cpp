#include "cutting/cut_contour.h"

#include <string>

#include "util/error.h"

namespace vs {

CutContour cutContour(const CutMesh& m, const Geometry& g, const std::vector<Vec3>& pointsIndex, double snapRadiusMm,
                      Progress& progress) {
  VS_REQUIRE(pointsIndex.size() >= 3,
             "a cut needs at least 3 points around the part, got " + std::to_string(pointsIndex.size()));
  std::vector<MeshSnap> snaps;
  for (size_t i = 0; i < pointsIndex.size(); ++i)
    snaps.push_back(
        snapToMesh(m.mesh, m.features, g.indexToWorld(pointsIndex[i]), snapRadiusMm, "point " + std::to_string(i + 1)));
  return cutContourOfSnaps(m, snaps, progress);
}

CutContour cutContourOfSnaps(const CutMesh& m, const std::vector<MeshSnap>& snaps, Progress& progress) {
  CutContour out;
  std::vector<int64_t> anchors;
  for (const MeshSnap& s : snaps) {
    anchors.push_back(s.vertex);
    out.snapDistanceMm.push_back(s.distanceMm);
  }
  out.contour = closedContour(m.graph, anchors, progress);
  for (int64_t v : out.contour.vertices) out.contourMm.push_back(m.mesh.positions[size_t(v)]);
  return out;
}

}  // namespace vs
