// Another traced path whose lumen touches a point's (session 37 touch37): a trigger of the rounds' own-lobe step. See
// centreline_junctions.h (touchingPaths).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "tracking/centreline_junctions.h"
#include "tracking/point_cells.h"

namespace vs::centreline_detail {

std::vector<int64_t> touchingPaths(const JunctionInput& in, const CentrelineOptions& o, const std::vector<Vec3>& q) {
  const size_t n = std::min(q.size(), in.radius.size());
  std::vector<int64_t> out(n, -1);
  if (!in.raw || !(o.lobeForkRadii > 0)) return out;
  const bool debug = std::getenv("VS_TOUCH37_DEBUG") != nullptr;
  const auto known = [&](size_t k) { return std::isfinite(in.radius[k]) && in.radius[k] > 0; };
  // Pairs within the sum of two radii lie in the same or adjacent cells of a grid twice as wide as the largest radius.
  double cellMm = 0;
  for (size_t k = 0; k < n; ++k)
    if (known(k)) cellMm = std::max(cellMm, 2 * in.radius[k]);
  if (!(cellMm > 0)) return out;
  PointCells voxels(cellMm);  // the path voxels by cell
  for (size_t j = 0; j < n; ++j)
    if (known(j)) voxels.add(in.raw(j), j);
  // Per point: the voxel of another line of the tree (not up or down its own within the fork reach) lies within the
  // two radii (`beside`); the nearest such voxel not within the fork reach either (`out`: another path touching).
  std::vector<uint8_t> beside(n, 0);
  std::vector<size_t> upK, upJ;
  for (size_t k = 0; k < n; ++k) {
    if (!known(k) || !q[k].allFinite()) continue;
    double nearest = std::numeric_limits<double>::infinity();
    voxels.forEachNear(voxels.cellOf(q[k]), [&](size_t j) {
      const double d = (in.raw(j) - q[k]).norm();
      if (j == k || !(d <= in.radius[k] + in.radius[j])) return;
      const bool fork = withinForkReach(in, o, k, j, upK, upJ);  // fills upK / upJ
      if (std::find(upK.begin(), upK.end(), j) != upK.end() || std::find(upJ.begin(), upJ.end(), k) != upJ.end())
        return;  // the own line
      beside[k] = 1;
      if (!fork && d < nearest) nearest = d, out[k] = static_cast<int64_t>(j);
    });
  }
  // A touch is a contact only where the paths parted before it: up the point's chain a point with no other line
  // beside it comes before a branch point or the root (else the two share one tube from their fork: a narrow fork's
  // children side by side, two paths along one trunk's walls).
  for (size_t k = 0; k < n; ++k) {
    if (out[k] < 0) continue;
    int64_t a = in.parent[k];
    while (a >= 0 && beside[static_cast<size_t>(a)] && in.children[static_cast<size_t>(a)].size() < 2)
      a = in.parent[static_cast<size_t>(a)];
    if (a < 0 || beside[static_cast<size_t>(a)] || in.children[static_cast<size_t>(a)].size() >= 2) out[k] = -1;
    if (debug && out[k] >= 0)
      std::fprintf(stderr, "[touch37] %zu at %.2f %.2f %.2f mm touched by %lld, radii %.2f + %.2f mm\n", k, q[k][0],
                   q[k][1], q[k][2], static_cast<long long>(out[k]), in.radius[k],
                   in.radius[static_cast<size_t>(out[k])]);
  }
  return out;
}

}  // namespace vs::centreline_detail
