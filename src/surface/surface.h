// Surface extraction from three orthogonal contours: the deformed-triangle subdivision of thesis
// 4.3.1 (issue 15; reading-notes.md for the lost Figure 24).
//
// Three planes x = x0, y = y0, z = z0 (voxel indices) meet at the centre O. Each of the six
// half-lines from O along an axis crosses the surface; its outermost crossing of the iso-value is a
// corner. Each octant (signs sx, sy, sz) is one deformed triangle: corners A (x half-line),
// B (y half-line), C (z half-line); sides AB in plane z = z0, BC in x = x0, CA in y = y0, each a 2D
// live-wire path (cost/live_wire_cost.h edge costs plus the iso term of surface_cost.h)
// restricted to the plane's quadrant. Subdivision then splits sides at their middle voxel and
// joins the midpoints by 3D minimum-cost paths (graph/ engine, surface_cost.h) inside the octant.
//
// SUBDIVISION RULES (the design that replaces Figure 24). Every edge of the mesh is a *curve*, a
// voxel path between two mesh vertices. A curve is split at most once, at the voxel nearest half
// its physical length, and only if it has at least two steps (three voxels); the split is cached on
// the curve, so the two triangles sharing a side see the same midpoint vertex and the same two
// half-curves (no crack, figure 23). A triangle is then subdivided by how many of its sides split:
//   3 sides split (the normal case): 4 triangles, corner triangles + the midpoint triangle, joined
//     by 3 new curves between the midpoints;
//   2 sides split (the third is one step): 3 triangles; the corner triangle at the split sides'
//     common corner, and the remaining quadrilateral cut along its shorter diagonal (2 new curves);
//   1 side split: 2 triangles, the midpoint joined to the opposite corner (1 new curve);
//   0 sides split: the triangle is kept.
// Every rule replaces a triangle by a fan that uses exactly the (split) boundary of the original,
// with the same orientation, so the mesh stays an edge-manifold disc bounded by the three contours
// (closed: a sphere) and consistently oriented; level n has 4^n triangles when all sides keep at
// least two steps (Table 1's 4, 16, 64, 256), fewer once sides reach one step (Table 1's 58, 202).
// Shared contours in a closed surface are split identically by both octants (the split depends on
// the curve alone), so octants run in parallel and are stitched by the contour voxels.
//
// Folds: an octant whose object comes back beyond its patch along rays from O (an ear, an
// overhang) is reported per octant (fold_check.h, OctantReport); the mesh is never folded to
// follow it.
//
// Vertices: each vertex voxel is moved to the iso-surface by Newton steps along the trilinear
// gradient (at most one voxel), mapped to world mm (LPS) with the volume's spacing and direction;
// normals from the gradient, pointing out of the object (the side of the iso-value that holds O).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cost/live_wire_cost.h"
#include "mesh/tri_mesh.h"
#include "surface/mesh_quality.h"
#include "surface/surface_cost.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

// One octant: sign per axis (+1 / -1).
using OctantSigns = std::array<int, 3>;
std::string octantName(const OctantSigns& s);      // "+x+y+z"
OctantSigns parseOctant(const std::string& name);  // throws InvalidArgument

struct SurfaceOptions {
  Index3 planes{0, 0, 0};       // x0, y0, z0 (voxel indices)
  std::optional<double> iso;    // iso-value; default: Otsu threshold of the volume
  int level = 4;                // subdivision levels (0 = the deformed triangle)
  int connectivity = 18;        // 3D paths: 6, 18 or 26 (the thesis: 18)
  bool closed = false;          // all eight octants stitched watertight
  OctantSigns octant{1, 1, 1};  // the octant when not closed
  // Corner overrides per half-line, index 2*axis + (sign < 0): +x, -x, +y, -y, +z, -z.
  std::array<std::optional<Index3>, 6> corners;
  // Intermediate voxels a side must pass through (the thesis's stylus editing), per side, in
  // order from the first corner to the second; key = sideName() ("z+x+y" ...).
  std::vector<std::pair<std::string, std::vector<Index3>>> via;
  SurfaceCostOptions cost;
  LiveWireCostOptions sideCost;  // 2D live-wire cost of the sides (Mortensen-Barrett)
  bool geometryOnly = false;     // baseline: interior vertices interpolated from the contours
  // Finer mesh: every voxel of every path (contours and 3D paths) is a vertex; each triangle of
  // the subdivision is re-triangulated over the voxels of its three paths (voxels shared by paths
  // merged, loops ear-clipped in the triangle's plane; surface.cpp finishOctant). Same topology (a
  // disc per octant, watertight when closed). Not with geometryOnly.
  bool everyPathVoxel = false;
  // The shared surface policy (surface_policy.h), checked by the extraction and every edit: a mesh
  // that is not edge-manifold and oriented (watertight when closed) after degenerate triangles are
  // repaired is a DataError, and so is a folded octant unless allowFolds.
  bool allowFolds = false;
};

// Name of the quadrant contour in plane `axis` = planes[axis] with signs of the two other axes,
// e.g. "z+x+y" (plane z = z0, quadrant x >= x0, y >= y0).
std::string sideName(int planeAxis, int signFirst, int signSecond);

struct SurfaceLevelStats {
  int level = 0;
  int64_t triangles = 0;     // after this level
  int64_t paths = 0;         // 3D paths searched at this level
  int64_t nodesSettled = 0;  // graph nodes settled by those searches
  int64_t edgesScanned = 0;  // edges examined (settled nodes x connectivity)
  double seconds = 0;        // wall time of this level (all octants)
};

struct OctantReport {
  OctantSigns octant{1, 1, 1};
  int64_t triangles = 0;
  // Triangles facing O, for information (slivers flip a little area at the finest levels).
  int64_t backFacingTriangles = 0;
  double backFacingAreaFraction = 0;
  // Fold check (fold_check.h): rays from O through the octant that meet the patch, those along
  // which the object comes back beyond it (an ear, an overhang), and where the first does.
  int64_t foldCheckRays = 0;
  int64_t foldedRays = 0;
  double foldedRayFraction = 0;
  int64_t otherObjectRays = 0;    // rays meeting a separate object beyond the patch (not a fold)
  std::optional<Vec3> firstFold;  // continuous index
  bool folded = false;            // foldedRayFraction above kFoldRayFraction (1%)
};

struct SurfaceResult {
  TriMesh mesh;  // world mm, outward normals, counter-clockwise from outside
  double iso = 0;
  std::string costDescription;
  Vec3 centerIndex{0, 0, 0};
  std::array<std::optional<Index3>, 6> corners;  // the corners used (half-lines used only)
  std::vector<SurfaceLevelStats> levels;
  std::vector<OctantReport> octants;
  double secondsCost = 0, secondsSides = 0, secondsTotal = 0;
  // Index-space (voxel) positions of the mesh vertices before refinement, for tests.
  std::vector<Index3> vertexVoxels;
  // The side contours (voxel paths) by sideName, from the first corner to the second.
  std::vector<std::pair<std::string, std::vector<Index3>>> sides;
  // The mesh's topology after the repair of degenerate triangles (surface_policy.h), and how many
  // triangles that repair removed (collapsed slivers and what they left repeated).
  MeshTopology topology;
  int64_t repairedTriangles = 0;
};

struct SurfaceEditReport {
  std::string side;
  std::vector<OctantSigns> octants;  // the octants re-subdivided (those sharing the side)
  int64_t paths = 0;                 // 3D paths searched for them
  int64_t nodesSettled = 0;
  double seconds = 0;  // side, subdivision, vertices and re-assembly of the mesh
};

// An extracted surface that can be edited (the thesis's stylus editing of a contour). It keeps
// the cost, the sides and every octant's subdivision; editSide() replaces one side by the
// live-wire from its first corner through the given points to its second, and re-subdivides only
// the octants that share that side (one, or two when closed). The other octants' triangles and
// vertices are reused unchanged, and the result equals a fresh extraction with those points as
// the side's `via`. References `volume`: it must outlive the object.
// The constructor throws as extractSurface; editSide throws InvalidArgument for a side no octant
// uses or a point outside the side's quadrant, DataError for no path, a level too deep or a mesh
// the surface policy refuses, and leaves the surface unchanged when it throws.
class SurfaceExtraction {
 public:
  SurfaceExtraction(const VolumeF32& volume, const SurfaceOptions& options, Progress& progress = Progress::none());
  ~SurfaceExtraction();
  SurfaceExtraction(const SurfaceExtraction&) = delete;
  SurfaceExtraction& operator=(const SurfaceExtraction&) = delete;
  const SurfaceResult& result() const;
  // `side`: sideName() such as "z+x+y"; `points`: in order from the side's first corner to its
  // second (empty: the plain live-wire between the corners).
  SurfaceEditReport editSide(const std::string& side, const std::vector<Index3>& points,
                             Progress& progress = Progress::none());

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Throws InvalidArgument (exit 2 in the CLI) for planes outside the volume, a level outside
// 0..8, a corner not on its half-line; DataError (exit 1) for no surface crossing on a half-line,
// a side with no path in its quadrant, a level too deep for the object (no side left to split),
// naming the octant and side, and for a mesh the surface policy refuses (surface_policy.h:
// invalid after repair, or folded unless options.allowFolds). Cancellable; octants in parallel.
SurfaceResult extractSurface(const VolumeF32& volume, const SurfaceOptions& options,
                             Progress& progress = Progress::none());

// For accuracy measurements: the vertices (world mm) of a reference iso-surface mesh that lie in
// octant `octant` around `centerIndex` and are the outermost crossing of `iso` along their ray
// from the centre (what a patch bounded by the three contours describes: inner surfaces such as
// sinuses, and overhangs, are left out). The object is the side of `iso` that holds the centre.
std::vector<Vec3> outermostInOctant(const TriMesh& reference, const VolumeF32& volume, double iso,
                                    const Vec3& centerIndex, const OctantSigns& octant);

}  // namespace vs
