// Repair of degenerate triangles in an otherwise valid triangle mesh: one sliver must not fail a
// whole surface (issue 22: a closed sphere at level 5 lost to one zero-area triangle).
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/tri_mesh.h"

namespace vs {

struct MeshRepair {
  int64_t collapsedEdges = 0;     // edges of zero-area triangles collapsed (end points merged)
  int64_t removedTriangles = 0;   // triangles dropped: a repeated vertex, or a pair enclosing nothing
  int64_t removedVertices = 0;    // vertices no triangle uses any more (dropped, indices compacted)
  std::vector<int32_t> newIndex;  // old vertex -> new vertex (-1: removed); empty when nothing changed
  bool changed() const { return collapsedEdges + removedTriangles + removedVertices > 0; }
};

// Makes every triangle non-degenerate: a triangle of area <= minArea (mm^2) has its shortest edge
// collapsed (the end point with the larger index merges into the other, which keeps its position),
// triangles with a repeated vertex are dropped, and so are two triangles over the same three
// vertices in opposite orders (they enclose nothing). Positions and normals are compacted, and
// `newIndex` maps the old vertices for per-vertex data of the caller's. A consistently oriented
// edge-manifold mesh stays one wherever the collapsed edge's ends share only the two neighbours of
// the edge (the usual sliver); analyzeTopology tells the rest.
MeshRepair repairDegenerateTriangles(TriMesh& mesh, double minArea = 0);

}  // namespace vs
