// Internals of the surface extraction (surface.h), shared by its files, one per concern:
//   surface_sides.cpp        corners on the half-lines and the quadrant contours (2D live-wire)
//   surface_domain.h         one octant's 3D search domain (box, node costs, search band)
//   surface_subdivision.h    one octant's deformed-triangle subdivision (OctantBuilder)
//   surface_finish.cpp       vertices onto the iso-surface, the every-voxel re-triangulation
//   surface.cpp              names, the extraction's state, assembly, policy and editing
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "features/features2d.h"
#include "graph/grid_graph.h"
#include "graph/shortest_path.h"
#include "surface/surface.h"
#include "util/error.h"
#include "util/parallel.h"
#include "util/text.h"

namespace vs::surface_detail {

using Clock = std::chrono::steady_clock;
inline double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

inline std::string halfLineName(int h) { return std::string(h % 2 ? "-" : "+") + "xyz"[h / 2]; }
inline Vec3 toVec(const Index3& p) { return Vec3(double(p[0]), double(p[1]), double(p[2])); }

// The two in-plane axes of plane `k`, smaller first.
inline std::array<int, 2> planeAxes(int k) { return {k == 0 ? 1 : 0, k == 2 ? 1 : 2}; }
inline int sideId(int k, int si, int sj) { return 4 * k + 2 * (si < 0) + (sj < 0); }

struct Shared {
  const VolumeF32& vol;
  const SurfaceOptions& opt;
  Index3 center;
  double iso = 0;
  bool brightInside = true;  // the object (O's side of the iso-value) is brighter than the iso-value
  double finest = 1;         // finest spacing, mm
  Index3 costLo{0, 0, 0};    // the cost array covers the box costLo .. costLo + costDims - 1
  Index3 costDims{0, 0, 0};
  bool inside(double v) const { return brightInside ? v >= iso : v < iso; }
  double mmDistance(const Vec3& a, const Vec3& b) const { return (a - b).cwiseProduct(vol.geometry().spacing).norm(); }
};

// Outermost crossing of the iso-value on half-line h: the voxel nearest the iso-value among the
// outermost object voxel and its outer neighbour.
Index3 findCorner(const Shared& s, int h);
// Throws InvalidArgument when a given corner is not on its half-line.
void checkCorner(const Shared& s, int h, const Index3& c);
// One quadrant contour: 2D live-wire in plane k = center[k] from corner `from` to corner `to`
// through the via points, restricted to the quadrant (signs si, sj of the in-plane axes).
std::vector<Index3> computeSide(const Shared& s, int k, int si, int sj, const Index3& from, const Index3& to,
                                const std::vector<Index3>& via);

// ---- one octant's subdivision ------------------------------------------------------------------

struct Vertex {
  Vec3 pos;             // index space; voxel centre for path voxels, continuous for baseline blends
  bool onImage = true;  // from the image (contour or 3D path): refined onto the iso-surface
  int corner = -1;      // half-line id for a corner
  int side = -1;        // side id for a contour vertex
  int64_t sideIndex = -1;
};

struct Curve {
  int a = -1, b = -1;     // end vertices (pts.front() is a's position)
  std::vector<Vec3> pts;  // index space
  int side = -1;          // contour curves: side id and offset of pts[0] in that side
  int64_t sideOffset = 0;
  int child0 = -1, child1 = -1, mid = -1;  // the split, once done
  bool unsplittable = false;               // decided once: one step, or no free voxel to split at
};

struct Tri {
  std::array<int, 3> v;
  std::array<int, 3> e;  // e[i] joins v[i] and v[(i+1)%3]
};

}  // namespace vs::surface_detail
