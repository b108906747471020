// The surface policy every front end shares (issue 23): the extraction applies it itself
// (SurfaceExtraction, extractSurface, editSide), so `volscissors surface`, Python's
// volscissors.surface and the viewer keep and refuse the same meshes.
//  1. Degenerate triangles (a repeated vertex or zero area) are repaired, not fatal
//     (mesh/mesh_repair.h); the count is in SurfaceResult::repairedTriangles.
//  2. The mesh must then be edge-manifold and consistently oriented, and watertight when closed;
//     otherwise DataError naming the counts.
//  3. An octant that folds back over itself along rays from the centre (fold_check.h) is a
//     DataError naming the octants, unless SurfaceOptions::allowFolds.
#pragma once

#include <string>

#include "surface/surface.h"

namespace vs {

// "+x+y+z (12% of its rays, e.g. at voxel (40,41,39))", comma-separated; "" when none folds.
std::string foldedOctantsText(const SurfaceResult& result);

// Steps 2 and 3 on a result whose mesh was repaired (step 1, done by the extraction).
void checkSurfacePolicy(const SurfaceResult& result, const SurfaceOptions& options);

}  // namespace vs
