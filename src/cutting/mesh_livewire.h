// Intelligent Scissors on a surface mesh (thesis 3.2, eq. 13): the vertex graph of an object's
// surface, vertex gradients sampled from the volume, the 3D snap, and a closed contour through
// the user's points found with the project's one search engine (graph/shortest_path.h).
// Units: positions and lengths in world mm; G in intensity per mm.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "graph/csr_graph.h"
#include "graph/path.h"
#include "graph/shortest_path.h"
#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

// Eq. 13 weights: cost(u,v) = ||p(u)-p(v)|| (w_g f_g + w_n f_n + w_l). The length term w_l is our
// addition: where f_g and f_n both vanish (a flat stretch at full contrast) it keeps the shortest
// route, the property the thesis asks of the length factor, instead of a tie among zero costs.
struct MeshCostOptions {
  double wg = 0.45;                   // gradient magnitude term f_g
  double wn = 0.45;                   // normal change term f_n
  double wl = 0.1;                    // plain length
  double robustMaxPercentile = 99.0;  // max(G) of f_g: this percentile of the vertex G values
};

// Per-vertex image features by trilinear interpolation of the voxel gradients of the cell that
// holds the vertex (thesis Figure 12; reading notes on eq. 13).
struct VertexFeatures {
  std::vector<float> gradient;                // G(u), |interpolated gradient|, intensity / mm
  std::vector<Eigen::Vector3d> unitGradient;  // N(u) in world axes (zero where G = 0)
  float robustMaxGradient = 0;                // the options' percentile of G (> 0)
};
// The voxel gradient at a world point by trilinear interpolation of the central differences of
// the cell that holds it (thesis Figure 12), in world axes, intensity per mm.
Vec3 interpolatedGradient(const VolumeF32& volume, const Vec3& worldPoint);
VertexFeatures sampleVertexFeatures(const VolumeF32& volume, const TriMesh& mesh, double robustMaxPercentile = 99.0);

// The undirected vertex graph of the mesh's edges weighted by eq. 13 (positions = vertices, mm).
CsrGraph buildMeshGraph(const TriMesh& mesh, const VertexFeatures& features, const MeshCostOptions& options = {});

struct MeshSnap {
  int64_t vertex = -1;
  double distanceMm = 0;  // from the user's point to the chosen vertex
};
// The thesis's 3D snap: the nearest vertex must lie within radiusMm of the point (else DataError
// saying how far the surface is); among the vertices within radiusMm of the point the one with the
// largest G * (1 - d^2 / (2 radius^2)) wins (d: distance to the point). `what` names the point in messages.
MeshSnap snapToMesh(const TriMesh& mesh, const VertexFeatures& features, const Vec3& pointMm, double radiusMm,
                    const std::string& what);

struct MeshContour {
  std::vector<int64_t> vertices;  // the closed loop, each vertex once (last joins first)
  std::vector<int64_t> anchors;   // the snapped user points, in loop order
  double lengthMm = 0;
  double cost = 0;
};

// Joins consecutive anchors by minimum-cost paths and closes the loop (anchor n-1 -> anchor 0).
// Each segment avoids the vertices of the segments before it and the other anchors, so the loop
// never touches or crosses itself; where that is impossible the loop is refused (DataError naming
// the points). Needs >= 3 distinct anchors (InvalidArgument).
MeshContour closedContour(const CsrGraph& graph, const std::vector<int64_t>& anchors,
                          Progress& progress = Progress::none());

// The interactive case: one search per fixed point, resumed while the free point moves (a
// cursor update costs only the nodes settled since the last query).
class MeshLiveWire {
 public:
  explicit MeshLiveWire(const CsrGraph& graph);
  void setSeed(int64_t vertex);     // restarts the search (a click)
  Path pathTo(int64_t freeVertex);  // the contour segment to the cursor's vertex
 private:
  const CsrGraph* graph_;
  ShortestPathSearch search_;
};

}  // namespace vs
