// Plain geometric result types shared by the tools, writers and the renderer.
// All coordinates are world millimetres unless a field says otherwise.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vs {

// Indexed triangle mesh. Triangles are counter-clockwise seen from outside.
struct TriMesh {
  std::vector<Eigen::Vector3d> positions;         // world mm
  std::vector<std::array<int32_t, 3>> triangles;  // indices into positions
  std::vector<Eigen::Vector3d> normals;           // optional, per vertex (empty or positions.size())

  bool empty() const { return triangles.empty(); }
  // Throws InvalidArgument if an index is out of range or a position is not finite.
  void validate() const;
};

// A polyline (open or closed) with optional per-point radius, in world mm.
struct Polyline {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> radii;  // optional (empty or points.size()), mm
  bool closed = false;
};

// A rooted tree of points (SWC semantics): parent[i] == -1 for roots, otherwise the
// index of the parent node (< i is not required). Types follow SWC (0 undefined,
// 1 soma/root, 3 dendrite/vessel...). Radii in mm.
struct Tree {
  std::vector<Eigen::Vector3d> points;  // world mm
  std::vector<int32_t> parent;
  std::vector<double> radii;
  std::vector<int32_t> types;

  size_t size() const { return points.size(); }
  // Throws InvalidArgument on inconsistent sizes, bad parent indices or cycles.
  void validate() const;
  // Splits the tree into unbranched polylines (root -> branch point -> tip).
  std::vector<Polyline> toPolylines() const;
};

}  // namespace vs
