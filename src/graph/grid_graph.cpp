#include "graph/grid_graph.h"

#include <cmath>
#include <sstream>

#include "util/error.h"

namespace vs {

GridGraph::GridGraph(std::array<int64_t, 3> dims, std::array<double, 3> spacing, int connectivity)
    : dims_(dims), spacing_(spacing), connectivity_(connectivity) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1)
      throw InvalidArgument("GridGraph: dims[" + std::to_string(a) + "] = " + std::to_string(dims[a]) +
                            " must be >= 1");
    if (!(std::isfinite(spacing[a]) && spacing[a] > 0))
      throw InvalidArgument("GridGraph: spacing[" + std::to_string(a) + "] = " + std::to_string(spacing[a]) +
                            " must be finite and > 0 mm");
  }
  const double n = static_cast<double>(dims[0]) * static_cast<double>(dims[1]) * static_cast<double>(dims[2]);
  if (n >= 4294967295.0)
    throw InvalidArgument("GridGraph: " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                          std::to_string(dims[2]) + " has too many nodes (limit 2^32-1)");
  const bool twoD = connectivity == 4 || connectivity == 8;
  if (!twoD && connectivity != 6 && connectivity != 18 && connectivity != 26)
    throw InvalidArgument("GridGraph: connectivity " + std::to_string(connectivity) +
                          " must be 4, 8 (2D) or 6, 18, 26 (3D)");
  if (twoD && dims[2] != 1)
    throw InvalidArgument("GridGraph: connectivity " + std::to_string(connectivity) +
                          " needs a 2D grid (dims z = 1), got z = " + std::to_string(dims[2]));
  const int maxNonZero = (connectivity == 4 || connectivity == 6) ? 1 : (connectivity == 18 ? 2 : 3);
  k_ = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nz = (dx != 0) + (dy != 0) + (dz != 0);
        if (nz == 0 || nz > maxNonZero) continue;
        if (twoD && dz != 0) continue;
        offsets_[k_] = {dx, dy, dz};
        linear_[k_] = dx + dims[0] * (dy + dims[1] * dz);
        lengths_[k_] = std::sqrt(dx * dx * spacing[0] * spacing[0] + dy * dy * spacing[1] * spacing[1] +
                                 dz * dz * spacing[2] * spacing[2]);
        ++k_;
      }
}

int GridGraph::direction(int dx, int dy, int dz) const {
  for (int k = 0; k < k_; ++k)
    if (offsets_[k][0] == dx && offsets_[k][1] == dy && offsets_[k][2] == dz) return k;
  return -1;
}

int64_t GridGraph::neighbor(int64_t node, int k) const {
  const auto c = coords(node);
  const auto& o = offsets_[k];
  if (!contains(c[0] + o[0], c[1] + o[1], c[2] + o[2])) return -1;
  return node + linear_[k];
}

double GridGraph::minLength() const {
  double m = lengths_[0];
  for (int k = 1; k < k_; ++k) m = std::min(m, lengths_[k]);
  return m;
}

std::string GridGraph::describe() const {
  std::ostringstream s;
  s << dims_[0] << "x" << dims_[1] << "x" << dims_[2] << ", " << connectivity_ << "-connected, " << spacing_[0] << "x"
    << spacing_[1] << "x" << spacing_[2] << " mm";
  return s.str();
}

void requireGridNode(const GridGraph& g, int64_t node, const std::string& what) {
  if (!g.containsNode(node))
    throw InvalidArgument(what + " node " + std::to_string(node) + " is outside the grid " + g.describe() + " (0.." +
                          std::to_string(g.nodeCount() - 1) + ")");
}

}  // namespace vs
