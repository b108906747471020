// Repair of degenerate triangles (mesh/mesh_repair.h): a sliver with coincident vertices in a
// closed octahedron is collapsed, its neighbour pair dropped, and the rest stays a closed,
// consistently oriented mesh; a mesh without a degenerate triangle is left exactly as it was.
#include "mesh/mesh_repair.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>

namespace vs {
namespace {

// An octahedron (closed, outward counter-clockwise triangles).
TriMesh octahedron() {
  TriMesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& p : m.positions) m.normals.push_back(p);
  return m;
}

// Each undirected edge used exactly twice, once in each direction; no degenerate triangle.
bool closedAndOriented(const TriMesh& m) {
  std::map<std::pair<int32_t, int32_t>, int> uses;
  for (const auto& t : m.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return false;
    const Eigen::Vector3d n = (m.positions[size_t(t[1])] - m.positions[size_t(t[0])])
                                  .cross(m.positions[size_t(t[2])] - m.positions[size_t(t[0])]);
    if (!(n.norm() > 0)) return false;
    for (int i = 0; i < 3; ++i) uses[{t[i], t[(i + 1) % 3]}] += 1;
  }
  for (const auto& [e, n] : uses)
    if (n != 1 || !uses.count({e.second, e.first})) return false;
  return true;
}

TEST(MeshRepair, ValidMeshUnchanged) {
  TriMesh m = octahedron();
  const TriMesh before = m;
  const MeshRepair r = repairDegenerateTriangles(m);
  EXPECT_FALSE(r.changed());
  EXPECT_TRUE(r.newIndex.empty());
  EXPECT_EQ(m.triangles, before.triangles);
  EXPECT_EQ(m.positions, before.positions);
}

// Split the edge 0-2 with a vertex 6 at the position of vertex 0: the two triangles beside the
// edge become four, two of them of zero area (6 coincides with 0).
TEST(MeshRepair, CoincidentVertexSliverIsCollapsed) {
  TriMesh m = octahedron();
  m.positions.push_back(m.positions[0]);
  m.normals.push_back(m.normals[0]);
  m.triangles[0] = {0, 6, 4};
  m.triangles.push_back({6, 2, 4});
  m.triangles[4] = {2, 6, 5};
  m.triangles.push_back({6, 0, 5});
  ASSERT_FALSE(closedAndOriented(m));
  const MeshRepair r = repairDegenerateTriangles(m);
  EXPECT_TRUE(r.changed());
  EXPECT_EQ(r.collapsedEdges, 1);
  EXPECT_EQ(r.removedTriangles, 2);
  EXPECT_EQ(r.removedVertices, 1);
  ASSERT_EQ(r.newIndex.size(), 7u);
  EXPECT_EQ(r.newIndex[6], r.newIndex[0]);
  EXPECT_EQ(m.positions.size(), 6u);
  EXPECT_EQ(m.normals.size(), 6u);
  EXPECT_EQ(m.triangles.size(), 8u);
  EXPECT_TRUE(closedAndOriented(m));
}

// A triangle with a repeated vertex is dropped; the mesh around it is untouched.
TEST(MeshRepair, RepeatedVertexTriangleIsDropped) {
  TriMesh m = octahedron();
  m.triangles.push_back({4, 4, 2});
  const MeshRepair r = repairDegenerateTriangles(m);
  EXPECT_EQ(r.collapsedEdges, 0);
  EXPECT_EQ(r.removedTriangles, 1);
  EXPECT_EQ(r.removedVertices, 0);
  EXPECT_TRUE(closedAndOriented(m));
}

}  // namespace
}  // namespace vs
