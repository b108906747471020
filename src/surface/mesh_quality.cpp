#include "surface/mesh_quality.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "util/error.h"
#include "util/parallel.h"

namespace vs {

MeshTopology analyzeTopology(const TriMesh& mesh, double minArea) {
  mesh.validate();
  MeshTopology t;
  t.faces = static_cast<int64_t>(mesh.triangles.size());
  struct EdgeUse {
    int forward = 0, backward = 0;  // a < b: a -> b is forward
  };
  std::map<std::pair<int32_t, int32_t>, EdgeUse> edges;
  std::set<std::array<int32_t, 3>> seen;
  std::vector<char> used(mesh.positions.size(), 0);
  for (const auto& tri : mesh.triangles) {
    const Vec3 &a = mesh.positions[static_cast<size_t>(tri[0])], &b = mesh.positions[static_cast<size_t>(tri[1])],
               &c = mesh.positions[static_cast<size_t>(tri[2])];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] || (b - a).cross(c - a).norm() / 2 <= minArea)
      ++t.degenerateTriangles;
    std::array<int32_t, 3> key = tri;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) ++t.duplicateTriangles;
    for (int i = 0; i < 3; ++i) {
      used[static_cast<size_t>(tri[i])] = 1;
      const int32_t u = tri[i], v = tri[(i + 1) % 3];
      if (u == v) continue;
      EdgeUse& e = edges[{std::min(u, v), std::max(u, v)}];
      (u < v ? e.forward : e.backward) += 1;
    }
  }
  t.vertices = std::count(used.begin(), used.end(), 1);
  t.edges = static_cast<int64_t>(edges.size());
  std::map<int32_t, std::vector<int32_t>> boundaryNext;
  for (const auto& [k, e] : edges) {
    const int n = e.forward + e.backward;
    if (n == 1) {
      ++t.boundaryEdges;
      boundaryNext[k.first].push_back(k.second);
      boundaryNext[k.second].push_back(k.first);
    }
    if (n >= 3) ++t.nonManifoldEdges;
    if (e.forward > 1 || e.backward > 1) ++t.misorientedEdges;
  }
  // Boundary loops: connected components of the boundary-edge graph.
  std::set<int32_t> visited;
  for (const auto& [v, next] : boundaryNext) {
    if (visited.count(v)) continue;
    ++t.boundaryLoops;
    std::vector<int32_t> stack{v};
    visited.insert(v);
    while (!stack.empty()) {
      const int32_t x = stack.back();
      stack.pop_back();
      for (int32_t y : boundaryNext[x])
        if (visited.insert(y).second) stack.push_back(y);
    }
  }
  // Components: union-find over vertices of triangles.
  std::vector<int32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t x) {
    while (parent[static_cast<size_t>(x)] != x)
      x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  };
  for (const auto& tri : mesh.triangles)
    for (int i = 1; i < 3; ++i) parent[static_cast<size_t>(find(tri[i]))] = find(tri[0]);
  std::set<int32_t> roots;
  for (const auto& tri : mesh.triangles) roots.insert(find(tri[0]));
  t.components = static_cast<int64_t>(roots.size());
  return t;
}

double pointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection 5.1.5: closest point by Voronoi regions.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

MeshDistance::MeshDistance(const TriMesh& mesh) : mesh_(mesh) {
  VS_REQUIRE(!mesh.triangles.empty(), "distance to an empty mesh");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  double edgeSum = 0;
  for (const auto& tri : mesh.triangles)
    for (int i = 0; i < 3; ++i) {
      const Vec3& p = mesh.positions[static_cast<size_t>(tri[i])];
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      edgeSum += (p - mesh.positions[static_cast<size_t>(tri[(i + 1) % 3])]).norm();
    }
  // Cells about twice the mean edge length, at most ~64^3 cells.
  const Vec3 ext = (hi - lo).cwiseMax(Vec3::Constant(1e-9));
  double size = std::max(2.0 * edgeSum / (3.0 * double(mesh.triangles.size())), 1e-9);
  size = std::max(size, ext.maxCoeff() / 64.0);
  lo_ = lo;
  cell_ = Vec3::Constant(size);
  for (int a = 0; a < 3; ++a) n_[a] = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(ext[a] / size)) + 1);
  bins_.resize(static_cast<size_t>(n_[0] * n_[1] * n_[2]));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    Vec3 tlo = Vec3::Constant(std::numeric_limits<double>::infinity()), thi = -tlo;
    for (int i = 0; i < 3; ++i) {
      tlo = tlo.cwiseMin(mesh.positions[static_cast<size_t>(mesh.triangles[t][i])]);
      thi = thi.cwiseMax(mesh.positions[static_cast<size_t>(mesh.triangles[t][i])]);
    }
    std::array<int64_t, 3> a{}, b{};
    for (int k = 0; k < 3; ++k) {
      a[k] = std::clamp<int64_t>(static_cast<int64_t>((tlo[k] - lo_[k]) / size), 0, n_[k] - 1);
      b[k] = std::clamp<int64_t>(static_cast<int64_t>((thi[k] - lo_[k]) / size), 0, n_[k] - 1);
    }
    for (int64_t z = a[2]; z <= b[2]; ++z)
      for (int64_t y = a[1]; y <= b[1]; ++y)
        for (int64_t x = a[0]; x <= b[0]; ++x)
          bins_[static_cast<size_t>(x + n_[0] * (y + n_[1] * z))].push_back(static_cast<int32_t>(t));
  }
}

double MeshDistance::distance(const Vec3& p) const {
  std::array<int64_t, 3> c{};
  for (int k = 0; k < 3; ++k) {
    const double rel = (p[k] - lo_[k]) / cell_[k];
    c[k] = std::clamp<int64_t>(static_cast<int64_t>(std::floor(rel)), 0, n_[k] - 1);
  }
  double best = std::numeric_limits<double>::infinity();
  const int64_t maxRing = std::max({n_[0], n_[1], n_[2]});
  for (int64_t r = 0; r <= maxRing; ++r) {
    for (int64_t z = c[2] - r; z <= c[2] + r; ++z)
      for (int64_t y = c[1] - r; y <= c[1] + r; ++y)
        for (int64_t x = c[0] - r; x <= c[0] + r; ++x) {
          if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
          if (x < 0 || y < 0 || z < 0 || x >= n_[0] || y >= n_[1] || z >= n_[2]) continue;
          for (int32_t t : bins_[static_cast<size_t>(x + n_[0] * (y + n_[1] * z))]) {
            const auto& tri = mesh_.triangles[static_cast<size_t>(t)];
            best = std::min(best, pointTriangleDistance(p, mesh_.positions[static_cast<size_t>(tri[0])],
                                                        mesh_.positions[static_cast<size_t>(tri[1])],
                                                        mesh_.positions[static_cast<size_t>(tri[2])]));
          }
        }
    // Every triangle not yet seen lies outside the (2r+1)^3 block around c, at least r cells away
    // from p's own cell in some axis; p may sit anywhere in its cell, hence r (not r + 1) cells.
    if (best <= double(r) * cell_.minCoeff()) break;
  }
  return best;
}

std::vector<double> MeshDistance::distances(const std::vector<Vec3>& points) const {
  std::vector<double> out(points.size());
  parallelFor(
      0, static_cast<int64_t>(points.size()),
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) out[static_cast<size_t>(i)] = distance(points[static_cast<size_t>(i)]);
      },
      256);
  return out;
}

std::vector<Vec3> sampleMesh(const TriMesh& mesh, double stepMm) {
  VS_REQUIRE(stepMm > 0, "sample step must be > 0");
  std::vector<Vec3> pts;
  std::vector<char> used(mesh.positions.size(), 0);
  for (const auto& tri : mesh.triangles)
    for (int32_t v : tri) used[static_cast<size_t>(v)] = 1;
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (used[v]) pts.push_back(mesh.positions[v]);
  for (const auto& tri : mesh.triangles) {
    const Vec3 &a = mesh.positions[static_cast<size_t>(tri[0])], &b = mesh.positions[static_cast<size_t>(tri[1])],
               &c = mesh.positions[static_cast<size_t>(tri[2])];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / stepMm)));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const int k = n - i - j;
        if (i == n || j == n || k == n) continue;  // the corners are already in
        pts.push_back((double(i) * a + double(j) * b + double(k) * c) / double(n));
      }
  }
  return pts;
}

DistanceSummary summarize(std::vector<double> v) {
  DistanceSummary s;
  s.count = static_cast<int64_t>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  s.p95 = v[std::min(v.size() - 1, static_cast<size_t>(std::ceil(0.95 * double(v.size()))) - 1)];
  s.max = v.back();
  return s;
}

}  // namespace vs
