#include "mesh/tri_mesh.h"

#include <string>

#include "util/error.h"

namespace vs {

void TriMesh::validate() const {
  const auto n = static_cast<int64_t>(positions.size());
  for (const auto& p : positions)
    if (!p.allFinite()) throw InvalidArgument("mesh has a non-finite vertex position");
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int32_t i : triangles[t])
      if (i < 0 || i >= n)
        throw InvalidArgument("mesh triangle " + std::to_string(t) + " refers to vertex " + std::to_string(i) + " of " +
                              std::to_string(n));
  if (!normals.empty() && normals.size() != positions.size())
    throw InvalidArgument("mesh has " + std::to_string(normals.size()) + " normals for " + std::to_string(n) +
                          " vertices");
}

void Tree::validate() const {
  const size_t n = points.size();
  if (parent.size() != n) throw InvalidArgument("tree: parent list size differs from point count");
  if (!radii.empty() && radii.size() != n) throw InvalidArgument("tree: radius list size differs from point count");
  if (!types.empty() && types.size() != n) throw InvalidArgument("tree: type list size differs from point count");
  for (size_t i = 0; i < n; ++i) {
    if (parent[i] < -1 || parent[i] >= static_cast<int32_t>(n))
      throw InvalidArgument("tree node " + std::to_string(i) + " has invalid parent " + std::to_string(parent[i]));
    if (!points[i].allFinite()) throw InvalidArgument("tree node " + std::to_string(i) + " is not finite");
  }
  // Cycle check: walking up from any node must reach a root within n steps.
  std::vector<char> state(n, 0);  // 0 unknown, 1 on current walk, 2 reaches a root
  for (size_t i = 0; i < n; ++i) {
    std::vector<size_t> walk;
    size_t cur = i;
    while (state[cur] == 0) {
      state[cur] = 1;
      walk.push_back(cur);
      if (parent[cur] < 0) break;
      cur = static_cast<size_t>(parent[cur]);
      if (state[cur] == 1) throw InvalidArgument("tree has a cycle through node " + std::to_string(cur));
    }
    for (size_t w : walk) state[w] = 2;
  }
}

std::vector<Polyline> Tree::toPolylines() const {
  const size_t n = points.size();
  std::vector<std::vector<int32_t>> children(n);
  for (size_t i = 0; i < n; ++i)
    if (parent[i] >= 0) children[static_cast<size_t>(parent[i])].push_back(static_cast<int32_t>(i));
  std::vector<Polyline> out;
  // Start a polyline at every root and every child of a branch point (or of a root).
  std::vector<std::pair<int32_t, int32_t>> starts;  // (start node, node before it or -1)
  for (size_t i = 0; i < n; ++i)
    if (parent[i] < 0) starts.emplace_back(static_cast<int32_t>(i), -1);
  while (!starts.empty()) {
    auto [node, prev] = starts.back();
    starts.pop_back();
    Polyline line;
    auto push = [&](int32_t k) {
      line.points.push_back(points[static_cast<size_t>(k)]);
      if (!radii.empty()) line.radii.push_back(radii[static_cast<size_t>(k)]);
    };
    if (prev >= 0) push(prev);
    int32_t cur = node;
    push(cur);
    while (children[static_cast<size_t>(cur)].size() == 1) {
      cur = children[static_cast<size_t>(cur)][0];
      push(cur);
    }
    for (int32_t c : children[static_cast<size_t>(cur)]) starts.emplace_back(c, cur);
    if (line.points.size() >= 2) out.push_back(std::move(line));
  }
  return out;
}

}  // namespace vs
