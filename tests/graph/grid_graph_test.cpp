#include "graph/grid_graph.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "util/error.h"

namespace vs {
namespace {

TEST(GridGraph, DirectionCountsAndSymmetricOrder) {
  const std::pair<int, std::array<int64_t, 3>> cases[] = {
      {4, {5, 4, 1}}, {8, {5, 4, 1}}, {6, {5, 4, 3}}, {18, {5, 4, 3}}, {26, {5, 4, 3}}};
  for (const auto& [conn, dims] : cases) {
    GridGraph g(dims, {1, 1, 1}, conn);
    ASSERT_EQ(g.directionCount(), conn);
    std::set<std::array<int, 3>> seen;
    for (int k = 0; k < conn; ++k) {
      const auto o = g.offset(k);
      const auto p = g.offset(g.opposite(k));
      EXPECT_EQ(o[0], -p[0]);
      EXPECT_EQ(o[1], -p[1]);
      EXPECT_EQ(o[2], -p[2]);
      EXPECT_TRUE(seen.insert(o).second);
      EXPECT_EQ(g.direction(o[0], o[1], o[2]), k);
      const int nz = (o[0] != 0) + (o[1] != 0) + (o[2] != 0);
      EXPECT_GE(nz, 1);
      const int maxNz = (conn == 4 || conn == 6) ? 1 : (conn == 18 ? 2 : 3);
      EXPECT_LE(nz, maxNz);
      EXPECT_TRUE(!(conn == 4 || conn == 8) || o[2] == 0);
      if (k > 0) {  // dz slowest, then dy, dx fastest
        const auto q = g.offset(k - 1);
        EXPECT_LT(std::make_tuple(q[2], q[1], q[0]), std::make_tuple(o[2], o[1], o[0]));
      }
    }
  }
  // The documented 8-connected order.
  GridGraph g8({3, 3, 1}, {1, 1, 1}, 8);
  const int expect[8][2] = {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(g8.offset(k)[0], expect[k][0]);
    EXPECT_EQ(g8.offset(k)[1], expect[k][1]);
  }
  // 26: k = 9(dz+1) + 3(dy+1) + (dx+1), minus one past the centre.
  GridGraph g26({3, 3, 3}, {1, 1, 1}, 26);
  for (int k = 0; k < 26; ++k) {
    const auto o = g26.offset(k);
    int idx = 9 * (o[2] + 1) + 3 * (o[1] + 1) + (o[0] + 1);
    if (idx > 13) --idx;
    EXPECT_EQ(idx, k);
  }
}

TEST(GridGraph, PhysicalLengthsFromSpacing) {
  GridGraph g({4, 4, 4}, {0.5, 2.0, 3.0}, 26);
  for (int k = 0; k < 26; ++k) {
    const auto o = g.offset(k);
    EXPECT_DOUBLE_EQ(g.length(k), std::sqrt(0.25 * o[0] * o[0] + 4.0 * o[1] * o[1] + 9.0 * o[2] * o[2]));
    EXPECT_EQ(g.linearOffset(k), o[0] + 4 * (o[1] + 4 * o[2]));
  }
  EXPECT_DOUBLE_EQ(g.minLength(), 0.5);
}

TEST(GridGraph, NeighborsAndCoords) {
  GridGraph g({4, 3, 2}, {1, 1, 1}, 6);
  const int64_t n = g.node(3, 1, 0);
  EXPECT_EQ(g.coords(n), (std::array<int64_t, 3>{3, 1, 0}));
  EXPECT_EQ(g.neighbor(n, g.direction(1, 0, 0)), -1);
  EXPECT_EQ(g.neighbor(n, g.direction(-1, 0, 0)), g.node(2, 1, 0));
  EXPECT_EQ(g.neighbor(n, g.direction(0, 0, 1)), g.node(3, 1, 1));
  EXPECT_EQ(g.neighbor(n, g.direction(0, 0, -1)), -1);
}

TEST(GridGraph, RejectsBadArguments) {
  EXPECT_THROW(GridGraph({0, 3, 1}, {1, 1, 1}, 8), InvalidArgument);
  EXPECT_THROW(GridGraph({3, 3, 1}, {1, 0, 1}, 8), InvalidArgument);
  EXPECT_THROW(GridGraph({3, 3, 1}, {1, NAN, 1}, 8), InvalidArgument);
  EXPECT_THROW(GridGraph({3, 3, 2}, {1, 1, 1}, 8), InvalidArgument);  // 2D connectivity on 3D grid
  EXPECT_THROW(GridGraph({3, 3, 3}, {1, 1, 1}, 10), InvalidArgument);
  EXPECT_THROW(GridGraph({100000, 100000, 1}, {1, 1, 1}, 8), InvalidArgument);  // >= 2^32 nodes
  EXPECT_NO_THROW(GridGraph({3, 3, 1}, {1, 1, 1}, 26));                         // 3D connectivity on one slice
  GridGraph g({3, 3, 1}, {1, 1, 1}, 8);
  EXPECT_THROW(requireGridNode(g, 9, "target"), InvalidArgument);
  EXPECT_THROW(requireGridNode(g, -1, "source"), InvalidArgument);
  EXPECT_NO_THROW(requireGridNode(g, 8, "target"));
}

}  // namespace
}  // namespace vs
