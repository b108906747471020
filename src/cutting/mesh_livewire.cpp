#include "cutting/mesh_livewire.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_set>

#include "features/features3d.h"
#include "util/error.h"

namespace vs {

Vec3 interpolatedGradient(const VolumeF32& volume, const Vec3& worldPoint) {
  const Geometry& g = volume.geometry();
  const Index3& d = g.dims;
  const Vec3 c = g.worldToIndex(worldPoint);
  int64_t i0[3];
  double fr[3];
  for (int k = 0; k < 3; ++k) {
    const double ck = std::clamp(c[k], 0.0, double(d[k] - 1));
    i0[k] = std::min<int64_t>(int64_t(ck), std::max<int64_t>(d[k] - 2, 0));
    fr[k] = ck - double(i0[k]);
  }
  Vec3 grad = Vec3::Zero();
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const double w = (dx ? fr[0] : 1 - fr[0]) * (dy ? fr[1] : 1 - fr[1]) * (dz ? fr[2] : 1 - fr[2]);
        if (w == 0) continue;
        grad += w * centralGradient(volume, std::min(i0[0] + dx, d[0] - 1), std::min(i0[1] + dy, d[1] - 1),
                                    std::min(i0[2] + dz, d[2] - 1));
      }
  return g.direction * grad;  // index-axis derivatives (per mm) to world axes
}

VertexFeatures sampleVertexFeatures(const VolumeF32& volume, const TriMesh& mesh, double robustMaxPercentile) {
  VertexFeatures f;
  f.gradient.resize(mesh.positions.size());
  f.unitGradient.resize(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3 grad = interpolatedGradient(volume, mesh.positions[i]);
    const double m = grad.norm();
    f.gradient[i] = float(m);
    f.unitGradient[i] = m > 0 ? Vec3(grad / m) : Vec3::Zero();
  }
  f.robustMaxGradient = std::max(percentileOf(f.gradient, robustMaxPercentile, true), 1e-12f);
  return f;
}

CsrGraph buildMeshGraph(const TriMesh& mesh, const VertexFeatures& features, const MeshCostOptions& o) {
  VS_REQUIRE(o.wg >= 0 && o.wn >= 0 && o.wl > 0, "mesh cost: weights must be >= 0 and the length weight > 0");
  VS_REQUIRE(features.gradient.size() == mesh.positions.size(), "mesh cost: one feature per vertex");
  std::vector<CsrGraph::Edge> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int64_t a = t[size_t(k)], b = t[size_t((k + 1) % 3)];
      edges.push_back({std::min(a, b), std::max(a, b), 0.0f});  // shared edges deduplicated below
    }
  std::sort(edges.begin(), edges.end(),
            [](const auto& x, const auto& y) { return x.from != y.from ? x.from < y.from : x.to < y.to; });
  edges.erase(std::unique(edges.begin(), edges.end(),
                          [](const auto& x, const auto& y) { return x.from == y.from && x.to == y.to; }),
              edges.end());
  const double maxG = features.robustMaxGradient;
  for (auto& e : edges) {
    const size_t u = size_t(e.from), v = size_t(e.to);
    const double len = (mesh.positions[u] - mesh.positions[v]).norm();
    const double fg = std::max(0.0, 1.0 - (double(features.gradient[u]) + features.gradient[v]) / (2 * maxG));
    const double fn = (1.0 - features.unitGradient[u].dot(features.unitGradient[v])) / 2;
    e.weight = float(len * (o.wg * fg + o.wn * fn + o.wl));
  }
  std::vector<std::array<float, 3>> positions(mesh.positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    positions[i] = {float(mesh.positions[i][0]), float(mesh.positions[i][1]), float(mesh.positions[i][2])};
  return CsrGraph::fromEdges(int64_t(mesh.positions.size()), edges, true, std::move(positions));
}

MeshSnap snapToMesh(const TriMesh& mesh, const VertexFeatures& features, const Vec3& p, double radiusMm,
                    const std::string& what) {
  VS_REQUIRE(radiusMm > 0 && std::isfinite(radiusMm), "snap radius must be > 0 mm");
  VS_REQUIRE(!mesh.positions.empty(), "snap: empty mesh");
  double nearest = std::numeric_limits<double>::infinity();
  MeshSnap best;
  double bestScore = -1;
  const double r2 = radiusMm * radiusMm;
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const double d2 = (mesh.positions[i] - p).squaredNorm();
    nearest = std::min(nearest, d2);
    // A vertex at the snap radius needs twice the gradient of one at the point to win, so the
    // snap moves to a clearly stronger edge, never along a uniform one.
    const double score = double(features.gradient[i]) * (1 - 0.5 * d2 / r2);
    if (d2 <= r2 && score > bestScore) {
      bestScore = score;
      best = {int64_t(i), std::sqrt(d2)};
    }
  }
  if (best.vertex < 0) {
    std::ostringstream msg;
    msg.precision(3);
    msg << what << " is " << std::sqrt(nearest) << " mm from the surface, farther than the snap radius " << radiusMm
        << " mm";
    throw DataError(msg.str());
  }
  return best;
}

MeshContour closedContour(const CsrGraph& graph, const std::vector<int64_t>& anchors, Progress& progress) {
  const size_t n = anchors.size();
  VS_REQUIRE(n >= 3, "a closed contour needs at least 3 points, got " + std::to_string(n));
  for (size_t i = 0; i < n; ++i) {
    VS_REQUIRE(anchors[i] >= 0 && anchors[i] < graph.nodeCount(), "contour point is not a mesh vertex");
    for (size_t j = 0; j < i; ++j)
      if (anchors[i] == anchors[j])
        throw DataError("points " + std::to_string(j + 1) + " and " + std::to_string(i + 1) +
                        " snap to the same surface vertex; place them farther apart");
  }
  std::vector<uint8_t> allowed(size_t(graph.nodeCount()), 1);
  for (int64_t a : anchors) allowed[size_t(a)] = 0;
  MeshContour contour;
  contour.anchors = anchors;
  for (size_t i = 0; i < n; ++i) {
    const int64_t from = anchors[i], to = anchors[(i + 1) % n];
    allowed[size_t(from)] = allowed[size_t(to)] = 1;
    SearchOptions options;
    options.mask = allowed;
    Path path = findPath(graph, from, to, options, progress);  // A* (options.useAStar)
    if (path.empty())
      throw DataError("cannot join point " + std::to_string(i + 1) + " to point " + std::to_string((i + 1) % n + 1) +
                      " on the surface without touching the contour already drawn; give the points in their order "
                      "around the loop");
    // The path's vertices (but its end, which the next segment starts from) are now taken.
    for (size_t k = 0; k + 1 < path.nodes.size(); ++k) {
      contour.vertices.push_back(path.nodes[k]);
      allowed[size_t(path.nodes[k])] = 0;
    }
    allowed[size_t(to)] = 0;
    contour.lengthMm += path.lengthMm;
    contour.cost += path.cost;
    progress.report(double(i + 1) / double(n), "contour");
  }
  return contour;
}

MeshLiveWire::MeshLiveWire(const CsrGraph& graph) : graph_(&graph), search_(graph, {0}) {
  VS_REQUIRE(graph.nodeCount() > 0, "live-wire on an empty mesh");
}

void MeshLiveWire::setSeed(int64_t vertex) {
  VS_REQUIRE(vertex >= 0 && vertex < graph_->nodeCount(), "live-wire seed is not a mesh vertex");
  search_.restart({vertex});
}

Path MeshLiveWire::pathTo(int64_t freeVertex) { return search_.pathTo(freeVertex); }

}  // namespace vs
