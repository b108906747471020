// Checks and measures for triangle meshes (issue 15's validity and accuracy tests, the CLI report).
// Topology: each undirected edge is counted by how many triangles use it and in which direction;
// a consistently oriented edge-manifold mesh uses each interior edge exactly twice, once in each
// direction. Distances: exact point-to-triangle distances with a uniform grid of triangles.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/tri_mesh.h"
#include "volume/geometry.h"

namespace vs {

struct MeshTopology {
  int64_t vertices = 0;  // vertices used by at least one triangle
  int64_t edges = 0;     // distinct undirected edges
  int64_t faces = 0;
  int64_t boundaryEdges = 0;        // used by one triangle
  int64_t nonManifoldEdges = 0;     // used by three or more triangles
  int64_t misorientedEdges = 0;     // used twice in the same direction
  int64_t degenerateTriangles = 0;  // repeated index or zero area
  int64_t duplicateTriangles = 0;   // same three vertices as an earlier triangle
  int64_t boundaryLoops = 0;        // connected loops of boundary edges
  int64_t components = 0;           // edge-connected components of triangles
  int64_t eulerCharacteristic() const { return vertices - edges + faces; }
  // Edge-manifold, consistently oriented, no degenerate or duplicate triangle.
  bool valid() const {
    return nonManifoldEdges == 0 && misorientedEdges == 0 && degenerateTriangles == 0 && duplicateTriangles == 0;
  }
  bool watertight() const { return valid() && boundaryEdges == 0; }
};

// `minArea`: triangles with area <= minArea (mm^2) count as degenerate.
MeshTopology analyzeTopology(const TriMesh& mesh, double minArea = 0);

// Nearest-triangle distance queries (mm) against a fixed mesh.
class MeshDistance {
 public:
  explicit MeshDistance(const TriMesh& mesh);
  double distance(const Vec3& p) const;
  // O(points * nearby triangles), parallel over points.
  std::vector<double> distances(const std::vector<Vec3>& points) const;

 private:
  const TriMesh& mesh_;
  Vec3 lo_, cell_;
  std::array<int64_t, 3> n_{1, 1, 1};
  std::vector<std::vector<int32_t>> bins_;
};

double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Points on the mesh: the vertices plus, per triangle, a barycentric lattice with about one point
// per `stepMm` along the longest edge.
std::vector<Vec3> sampleMesh(const TriMesh& mesh, double stepMm);

struct DistanceSummary {
  int64_t count = 0;
  double mean = 0, p95 = 0, max = 0;
};
DistanceSummary summarize(std::vector<double> values);

}  // namespace vs
