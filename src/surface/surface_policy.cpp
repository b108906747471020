#include "surface/surface_policy.h"

#include <cmath>

#include "surface/mesh_quality.h"
#include "util/error.h"
#include "util/text.h"

namespace vs {

std::string foldedOctantsText(const SurfaceResult& r) {
  std::string folded;
  for (const auto& oct : r.octants)
    if (oct.folded) {
      folded += (folded.empty() ? "" : ", ") + octantName(oct.octant) + " (" +
                std::to_string(static_cast<int>(std::lround(100 * oct.foldedRayFraction))) + "% of its rays";
      if (oct.firstFold) folded += ", e.g. at voxel " + indexText(roundIndex(*oct.firstFold));
      folded += ")";
    }
  return folded;
}

void checkSurfacePolicy(const SurfaceResult& r, const SurfaceOptions& o) {
  const MeshTopology& topo = r.topology;
  if (!topo.valid() || (o.closed && !topo.watertight()))
    throw DataError("the mesh failed its validity check (non-manifold edges " + std::to_string(topo.nonManifoldEdges) +
                    ", misoriented " + std::to_string(topo.misorientedEdges) + ", degenerate " +
                    std::to_string(topo.degenerateTriangles) + ", duplicate " +
                    std::to_string(topo.duplicateTriangles) + ", boundary edges " + std::to_string(topo.boundaryEdges) +
                    (o.closed ? ", closed surface" : "") + ")");
  const std::string folded = foldedOctantsText(r);
  if (!folded.empty() && !o.allowFolds)
    throw DataError("the surface folds back over itself along rays from the centre in octant " + folded +
                    ": rays leave the object and meet it again beyond the mesh (an ear or overhang that three "
                    "contours cannot describe); move the planes, or allow folds (SurfaceOptions::allowFolds; "
                    "--allow-folds, allow_folds=True) to keep the mesh");
}

}  // namespace vs
