// Intelligent Scissors on a surface mesh (thesis 3.2, eq. 13): the vertex graph of an object's
// surface, vertex gradients sampled from the volume, the 3D snap, and a closed contour through
// the user's points found with the project's one search engine (graph/shortest_path.h).
// Units: positions and lengths in world mm; G in intensity per mm.
#pragma once

#include <array>
#include <cstdint>
#include <span>
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
// largest G * (1 - d^2 / (2 radius^2)) wins (d: distance to the point; on equal scores the lowest
// vertex id). `what` names the point in messages.
MeshSnap snapToMesh(const TriMesh& mesh, const VertexFeatures& features, const Vec3& pointMm, double radiusMm,
                    const std::string& what);
// The snap's score of a vertex at squared distance d2 (<= r2) from the point: a vertex at the snap
// radius needs twice the gradient of one at the point to win, so the snap moves only to a clearly
// stronger edge, never along a uniform one. (snapToMesh and MeshSnapper both rank with it.)
inline double snapScore(float gradient, double d2, double r2) { return double(gradient) * (1 - 0.5 * d2 / r2); }

// snapToMesh's answer for many points on one mesh (the viewer's hover): the vertices in a grid of
// cells one snap radius wide (wider for a radius much smaller than the mesh's spacing of
// vertices), so a point costs the vertices of a few cells instead of all of them.
// Same vertex as snapToMesh for every point (same score, same tie rule); same error beyond the radius.
class MeshSnapper {
 public:
  MeshSnapper(const TriMesh& mesh, const VertexFeatures& features, double radiusMm);
  MeshSnap snap(const Vec3& pointMm, const std::string& what) const;
  // The vertex snapToMesh would choose, or -1 when no vertex lies within the radius (no message).
  int64_t vertexNear(const Vec3& pointMm) const;

 private:
  const TriMesh* mesh_;
  const VertexFeatures* features_;
  double radius_, cellMm_ = 0;
  Vec3 origin_;
  std::array<int64_t, 3> cells_{};
  std::vector<uint32_t> cellStart_, cellVertices_;  // vertices of cell c: cellVertices_[cellStart_[c]..cellStart_[c+1])
};

struct MeshContour {
  std::vector<int64_t> vertices;  // the closed loop, each vertex once (last joins first)
  std::vector<int64_t> anchors;   // the snapped user points, in loop order
  double lengthMm = 0;
  double cost = 0;
};

// Joins consecutive anchors by minimum-cost paths and closes the loop (anchor n-1 -> anchor 0).
// The loop never touches or crosses itself: segment i (anchor i -> i+1) avoids every vertex of the
// segments before it and the other anchors, the closing segment every vertex of the others;
// where that is impossible the loop is refused (DataError naming the points). Needs >= 3
// distinct anchors (InvalidArgument; DataError for two equal ones).
// Which of several equally cheap paths (the searches' tie rule), fixed so that the viewer can
// preview the same loop incrementally (CutContourSession, cut_contour_session.h):
// - segment i is first searched (contourSegmentSearch: Dijkstra from anchor i, read at anchor i+1)
//   avoiding only the vertices of segments 0..i-1 (the anchors up to i included); only when that
//   path runs through a later anchor is it searched again (A*) avoiding the later anchors too;
// - the closing segment is searched from anchor 0 towards anchor n-1 (the graph is undirected:
//   the same costs both ways) avoiding segments 0..n-3; only when that path touches segment n-2
//   is it searched again (A*) avoiding it too; then reversed.
// Each first search's path is one of the cheapest under the full avoidance (it avoids what it was
// not told to), so the loop's cost is the same as with every vertex avoided from the start.
MeshContour closedContour(const CsrGraph& graph, const std::vector<int64_t>& anchors,
                          Progress& progress = Progress::none());
// The first search of a contour segment: Dijkstra (no A*, so one search serves every target)
// from `from` over the vertices `allowed` (1) marks. closedContour reads one path from it; the
// viewer's CutContourSession keeps it and reads a path per hovered vertex: the same path.
ShortestPathSearch contourSegmentSearch(const CsrGraph& graph, int64_t from, std::span<const uint8_t> allowed);
// The second search (A*), when the first one's path runs through what it must avoid.
Path contourSegmentRetry(const CsrGraph& graph, int64_t from, int64_t to, std::span<const uint8_t> allowed);
// The message closedContour throws when segment `from` -> `to` (0-based point numbers) cannot be drawn.
std::string contourSegmentError(size_t from, size_t to);
// The message closedContour throws when points `first` < `second` (0-based) snap to one vertex.
std::string contourSameVertexError(size_t first, size_t second);

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
