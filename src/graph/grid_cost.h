// Edge cost models for implicit grid graphs (issue 3). Non-owning: the arrays must outlive
// every search that uses the GridCost. All arrays are per node in the grid's layout
// (linear index x + nx*(y + ny*z)). Costs must be >= 0 (+inf allowed: impassable); the
// search rejects NaN or negative values with DataError naming the array and the voxel.
//
// (a) Node costs c:  w(u,v) = len(u,v) * (c(u) + c(v)) / 2                       [GridCost::nodes]
//     exactly scikit-image MCP_Geometric (len in mm from the spacing).
// (b) 3D scissors cost (thesis eq. 19-22 as corrected in the reading notes):
//     w(u,v) = len(u,v) * ( w_g * (g(u) + g(v)) / 2 + w_z * f_z(u,v) )             [GridCost::scissors]
//     g = 1 - G/maxG per node (the caller computes it), f_z = 0 if sign(u) != sign(v)
//     (a Laplacian zero crossing; sign: any byte, compared as zero / non-zero), else 1.
// (c) Per-edge costs precomputed per direction:                                   [GridCost::perEdge]
//     w(u -> u+offset(k)) = edge[u*K + k], K = GridGraph::directionCount(), direction order in
//     grid_graph.h. Used as is (the caller includes the edge length if it wants one). Directed:
//     a search from the source uses the weights of the edges leaving each settled node, so the
//     path cost is the sum of edge[u*K+k] along source -> target. Entries for edges that leave
//     the grid are ignored (never read or validated).
#pragma once

#include <cstdint>
#include <span>

namespace vs {

struct GridCost {
  enum class Kind { Node, PerEdge };
  Kind kind = Kind::Node;
  std::span<const float> node;    // (a)/(b): N values
  std::span<const uint8_t> sign;  // (b): N values, optional (empty = no zero-crossing term)
  float nodeWeight = 1.0f;        // (b): w_g (thesis 0.7); 1 for (a)
  float signWeight = 0.0f;        // (b): w_z (thesis 0.3); 0 for (a)
  std::span<const float> edge;    // (c): N*K values

  static GridCost nodes(std::span<const float> c) {
    GridCost g;
    g.kind = Kind::Node;
    g.node = c;
    return g;
  }
  static GridCost scissors(std::span<const float> g, std::span<const uint8_t> sign, float wg = 0.7f, float wz = 0.3f) {
    GridCost c;
    c.kind = Kind::Node;
    c.node = g;
    c.sign = sign;
    c.nodeWeight = wg;
    c.signWeight = wz;
    return c;
  }
  static GridCost perEdge(std::span<const float> e) {
    GridCost g;
    g.kind = Kind::PerEdge;
    g.edge = e;
    return g;
  }
};

}  // namespace vs
