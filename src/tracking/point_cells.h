// Points bucketed in cubic cells: pairs nearer than the cell's side lie in the same or adjacent cells, so a
// neighbour query reads 27 cells instead of every point (the refinement's pair tests: two_tubes.cpp's drawnTogether,
// touching_paths.cpp's touchingPaths).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "volume/geometry.h"

namespace vs::centreline_detail {

class PointCells {
 public:
  using Cell = std::array<int64_t, 3>;
  explicit PointCells(double cellMm) : cellMm_(cellMm) {}
  Cell cellOf(const Vec3& p) const {
    return Cell{static_cast<int64_t>(std::floor(p[0] / cellMm_)), static_cast<int64_t>(std::floor(p[1] / cellMm_)),
                static_cast<int64_t>(std::floor(p[2] / cellMm_))};
  }
  void add(const Vec3& p, size_t k) { cells_[cellOf(p)].push_back(k); }
  // The cells in order, each with its points in the order added.
  const std::map<Cell, std::vector<size_t>>& cells() const { return cells_; }
  // f(j) for each point of the cell c and the 26 around it.
  template <class F>
  void forEachNear(const Cell& c, F&& f) const {
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          const auto cell = cells_.find(Cell{c[0] + dx, c[1] + dy, c[2] + dz});
          if (cell == cells_.end()) continue;
          for (size_t j : cell->second) f(j);
        }
  }

 private:
  double cellMm_;
  std::map<Cell, std::vector<size_t>> cells_;
};

}  // namespace vs::centreline_detail
