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
    const double score = snapScore(features.gradient[i], d2, r2);
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

MeshSnapper::MeshSnapper(const TriMesh& mesh, const VertexFeatures& features, double radiusMm)
    : mesh_(&mesh), features_(&features), radius_(radiusMm) {
  VS_REQUIRE(radiusMm > 0 && std::isfinite(radiusMm), "snap radius must be > 0 mm");
  VS_REQUIRE(!mesh.positions.empty(), "snap: empty mesh");
  VS_REQUIRE(features.gradient.size() == mesh.positions.size(), "snap: one feature per vertex");
  Vec3 lo = mesh.positions[0], hi = lo;
  for (const Vec3& q : mesh.positions) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  origin_ = lo;
  // Cells at least one radius wide (a point's candidates lie in 27 cells at most), wider when a
  // small radius would make far more cells than vertices.
  cellMm_ = radiusMm;
  int64_t total = 0;
  for (;; cellMm_ *= 2) {
    total = 1;
    for (int k = 0; k < 3; ++k) total *= (cells_[size_t(k)] = int64_t((hi[k] - lo[k]) / cellMm_) + 1);
    if (total <= 8 * int64_t(mesh.positions.size()) + 4096) break;
  }
  auto cellOf = [&](const Vec3& q) {
    int64_t c[3];
    for (int k = 0; k < 3; ++k) c[k] = std::clamp<int64_t>(int64_t((q[k] - lo[k]) / cellMm_), 0, cells_[size_t(k)] - 1);
    return size_t(c[0] + cells_[0] * (c[1] + cells_[1] * c[2]));
  };
  cellStart_.assign(size_t(total) + 1, 0);
  for (const Vec3& q : mesh.positions) ++cellStart_[cellOf(q) + 1];
  for (size_t c = 0; c < size_t(total); ++c) cellStart_[c + 1] += cellStart_[c];
  cellVertices_.resize(mesh.positions.size());
  std::vector<uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
  for (size_t i = 0; i < mesh.positions.size(); ++i) cellVertices_[fill[cellOf(mesh.positions[i])]++] = uint32_t(i);
}

int64_t MeshSnapper::vertexNear(const Vec3& p) const {
  // The cells a sphere of the snap radius around p overlaps (cells are >= one radius wide, so at
  // most 3 per axis); a point beyond the mesh's box by more than the radius has none.
  int64_t lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    const double a = (p[k] - radius_ - origin_[k]) / cellMm_, b = (p[k] + radius_ - origin_[k]) / cellMm_;
    if (!(b >= 0) || a >= double(cells_[size_t(k)])) return -1;
    lo[k] = std::max<int64_t>(0, int64_t(std::floor(a)));
    hi[k] = std::min<int64_t>(cells_[size_t(k)] - 1, int64_t(std::floor(b)));
  }
  const double r2 = radius_ * radius_;
  int64_t best = -1;
  double bestScore = -1;
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const size_t c = size_t(x + cells_[0] * (y + cells_[1] * z));
        for (uint32_t k = cellStart_[c]; k < cellStart_[c + 1]; ++k) {
          const uint32_t i = cellVertices_[k];
          const double d2 = (mesh_->positions[i] - p).squaredNorm();
          if (d2 > r2) continue;
          const double score = snapScore(features_->gradient[i], d2, r2);
          if (score > bestScore || (score == bestScore && int64_t(i) < best)) {  // snapToMesh: the first of equals
            bestScore = score;
            best = int64_t(i);
          }
        }
      }
  return best;
}

MeshSnap MeshSnapper::snap(const Vec3& p, const std::string& what) const {
  const int64_t v = vertexNear(p);
  if (v < 0) return snapToMesh(*mesh_, *features_, p, radius_, what);  // throws, saying how far the surface is
  return {v, (mesh_->positions[size_t(v)] - p).norm()};
}

ShortestPathSearch contourSegmentSearch(const CsrGraph& graph, int64_t from, std::span<const uint8_t> allowed) {
  SearchOptions options;
  options.mask = allowed;
  options.useAStar = false;  // (ignored by ShortestPathSearch; said for the reader)
  return ShortestPathSearch(graph, {from}, options);
}

Path contourSegmentRetry(const CsrGraph& graph, int64_t from, int64_t to, std::span<const uint8_t> allowed) {
  SearchOptions options;
  options.mask = allowed;
  return findPath(graph, from, to, options);  // A*
}

std::string contourSegmentError(size_t from, size_t to) {
  return "cannot join point " + std::to_string(from + 1) + " to point " + std::to_string(to + 1) +
         " on the surface without touching the contour already drawn; give the points in their order around the loop";
}

std::string contourSameVertexError(size_t first, size_t second) {
  return "points " + std::to_string(first + 1) + " and " + std::to_string(second + 1) +
         " snap to the same surface vertex; place them farther apart";
}

MeshContour closedContour(const CsrGraph& graph, const std::vector<int64_t>& anchors, Progress& progress) {
  const size_t n = anchors.size();
  VS_REQUIRE(n >= 3, "a closed contour needs at least 3 points, got " + std::to_string(n));
  for (size_t i = 0; i < n; ++i) {
    VS_REQUIRE(anchors[i] >= 0 && anchors[i] < graph.nodeCount(), "contour point is not a mesh vertex");
    for (size_t j = 0; j < i; ++j)
      if (anchors[i] == anchors[j]) throw DataError(contourSameVertexError(j, i));
  }
  const size_t N = size_t(graph.nodeCount());
  std::vector<uint8_t> onLoop(N, 0);  // every vertex of the segments drawn so far, their ends included
  std::vector<uint8_t> allowed(N);
  auto allowAllBut = [&](const std::vector<uint8_t>& taken, int64_t from, int64_t to) {
    for (size_t v = 0; v < N; ++v) allowed[v] = uint8_t(!taken[v]);
    allowed[size_t(from)] = allowed[size_t(to)] = 1;
  };
  std::vector<Path> segments;
  for (size_t i = 0; i + 1 < n; ++i) {
    const int64_t from = anchors[i], to = anchors[i + 1];
    allowAllBut(onLoop, from, to);
    Path path = contourSegmentSearch(graph, from, allowed).pathTo(to);
    bool later = false;  // does it run through a later anchor?
    for (size_t j = i + 2; j < n && !path.empty(); ++j)
      later |= std::find(path.nodes.begin(), path.nodes.end(), anchors[j]) != path.nodes.end();
    if (later) {
      for (size_t j = i + 2; j < n; ++j) allowed[size_t(anchors[j])] = 0;
      path = contourSegmentRetry(graph, from, to, allowed);
    }
    if (path.empty()) throw DataError(contourSegmentError(i, i + 1));
    if (i + 2 < n)  // the last open segment is marked after the closing segment's first search
      for (int64_t v : path.nodes) onLoop[size_t(v)] = 1;
    segments.push_back(std::move(path));
    progress.report(double(i + 1) / double(n), "contour");
  }
  // The closing segment, searched from anchor 0 towards anchor n-1, then reversed.
  allowAllBut(onLoop, anchors[0], anchors[n - 1]);
  Path closing = contourSegmentSearch(graph, anchors[0], allowed).pathTo(anchors[n - 1]);
  const Path& last = segments.back();
  bool touches = false;
  for (int64_t v : last.nodes) onLoop[size_t(v)] = 1;
  for (size_t k = 1; k + 1 < closing.nodes.size(); ++k) touches |= onLoop[size_t(closing.nodes[k])] != 0;
  if (touches) {
    allowAllBut(onLoop, anchors[0], anchors[n - 1]);
    closing = contourSegmentRetry(graph, anchors[0], anchors[n - 1], allowed);
  }
  if (closing.empty()) throw DataError(contourSegmentError(n - 1, 0));
  std::reverse(closing.nodes.begin(), closing.nodes.end());
  segments.push_back(std::move(closing));
  MeshContour contour;
  contour.anchors = anchors;
  for (const Path& path : segments) {  // each segment but its end, which the next one starts from
    contour.vertices.insert(contour.vertices.end(), path.nodes.begin(), path.nodes.end() - 1);
    contour.lengthMm += path.lengthMm;
    contour.cost += path.cost;
  }
  progress.report(1.0, "contour");
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
