// The closed contour a cut uses (thesis 3.2, eq. 13), from the user's points on a prepared mesh:
// each point snapped onto the mesh (snapToMesh, the 3D snap) and the anchors joined by
// closedContour (self-avoiding segments and the closing segment). cutOnMesh calls it, and the
// viewer's cut preview calls it with the same mesh, so what is previewed is what is cut.
#pragma once

#include <vector>

#include "cutting/cut.h"

namespace vs {

struct CutContour {
  MeshContour contour;                 // mesh vertices of the closed loop (last joins first)
  std::vector<Vec3> contourMm;         // their positions, world mm
  std::vector<double> snapDistanceMm;  // each point's distance to its snapped vertex
};

// Points: continuous voxel indices of `geometry` in loop order (>= 3). Throws as cutVolume does:
// InvalidArgument (< 3 points), DataError (a point farther than snapRadiusMm from the mesh, two
// points on one vertex, a loop that must touch itself).
CutContour cutContour(const CutMesh& mesh, const Geometry& geometry, const std::vector<Vec3>& pointsIndex,
                      double snapRadiusMm, Progress& progress = Progress::none());
// The same after the snap: the points' snapToMesh answers in loop order (the viewer's session
// snaps with a MeshSnapper, which answers as snapToMesh).
CutContour cutContourOfSnaps(const CutMesh& mesh, const std::vector<MeshSnap>& snaps,
                             Progress& progress = Progress::none());

}  // namespace vs
