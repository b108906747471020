#include "mesh/mesh_repair.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <numeric>

namespace vs {

namespace {

int32_t findRoot(std::vector<int32_t>& parent, int32_t v) {
  while (parent[static_cast<size_t>(v)] != v)
    v = parent[static_cast<size_t>(v)] = parent[static_cast<size_t>(parent[static_cast<size_t>(v)])];
  return v;
}

bool repeated(const std::array<int32_t, 3>& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

}  // namespace

MeshRepair repairDegenerateTriangles(TriMesh& mesh, double minArea) {
  MeshRepair rep;
  const size_t nv = mesh.positions.size();
  std::vector<int32_t> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  auto pos = [&](int32_t v) -> const Eigen::Vector3d& { return mesh.positions[static_cast<size_t>(v)]; };
  // Collapse the shortest edge of each zero-area triangle (after the merges so far), until none is left.
  for (bool again = true; again;) {
    again = false;
    for (const auto& tri : mesh.triangles) {
      std::array<int32_t, 3> t{findRoot(parent, tri[0]), findRoot(parent, tri[1]), findRoot(parent, tri[2])};
      if (repeated(t)) continue;
      if ((pos(t[1]) - pos(t[0])).cross(pos(t[2]) - pos(t[0])).norm() / 2 > minArea) continue;
      int best = 0;
      double shortest = -1;
      for (int i = 0; i < 3; ++i) {
        const double len = (pos(t[(i + 1) % 3]) - pos(t[i])).squaredNorm();
        if (shortest < 0 || len < shortest) shortest = len, best = i;
      }
      const int32_t a = t[best], b = t[(best + 1) % 3];
      parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
      rep.collapsedEdges += 1;
      again = true;
    }
  }
  std::vector<std::array<int32_t, 3>> tris;
  tris.reserve(mesh.triangles.size());
  for (const auto& tri : mesh.triangles) {
    const std::array<int32_t, 3> t{findRoot(parent, tri[0]), findRoot(parent, tri[1]), findRoot(parent, tri[2])};
    if (repeated(t)) {
      rep.removedTriangles += 1;
      continue;
    }
    tris.push_back(t);
  }
  // Two triangles over the same vertices in opposite orders enclose nothing: drop both.
  std::map<std::array<int32_t, 3>, std::array<std::vector<size_t>, 2>> byVertices;
  for (size_t i = 0; i < tris.size(); ++i) {
    const auto& t = tris[i];
    const size_t first = size_t(std::min_element(t.begin(), t.end()) - t.begin());
    const std::array<int32_t, 3> r{t[first], t[(first + 1) % 3], t[(first + 2) % 3]};
    const bool reversed = r[1] > r[2];
    byVertices[reversed ? std::array<int32_t, 3>{r[0], r[2], r[1]} : r][reversed].push_back(i);
  }
  std::vector<bool> drop(tris.size(), false);
  for (const auto& [verts, uses] : byVertices)
    for (size_t k = 0; k < std::min(uses[0].size(), uses[1].size()); ++k) drop[uses[0][k]] = drop[uses[1][k]] = true;
  size_t kept = 0;
  for (size_t i = 0; i < tris.size(); ++i)
    if (!drop[i]) tris[kept++] = tris[i];
  rep.removedTriangles += static_cast<int64_t>(tris.size() - kept);
  tris.resize(kept);
  if (rep.collapsedEdges == 0 && rep.removedTriangles == 0) return rep;

  // Compact the vertices: those no triangle uses any more go (the others keep their order).
  std::vector<char> used(nv, 0);
  for (const auto& t : tris)
    for (int32_t v : t) used[static_cast<size_t>(v)] = 1;
  std::vector<int32_t> compact(nv, -1);
  int32_t next = 0;
  for (size_t v = 0; v < nv; ++v)
    if (used[v]) compact[v] = next++;
  rep.newIndex.assign(nv, -1);
  for (size_t v = 0; v < nv; ++v) {
    const int32_t root = findRoot(parent, static_cast<int32_t>(v));
    rep.newIndex[v] = compact[static_cast<size_t>(root)];
  }
  rep.removedVertices = static_cast<int64_t>(nv) - next;
  std::vector<Eigen::Vector3d> positions(static_cast<size_t>(next)), normals;
  if (!mesh.normals.empty()) normals.resize(static_cast<size_t>(next));
  for (size_t v = 0; v < nv; ++v)
    if (compact[v] >= 0) {
      positions[static_cast<size_t>(compact[v])] = mesh.positions[v];
      if (!normals.empty()) normals[static_cast<size_t>(compact[v])] = mesh.normals[v];
    }
  for (auto& t : tris)
    for (int32_t& v : t) v = compact[static_cast<size_t>(v)];
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
  mesh.triangles = std::move(tris);
  return rep;
}

}  // namespace vs
