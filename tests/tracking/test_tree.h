// A refined-centreline tree built point by point for the junction tests (mm; parent -1: the root).
#pragma once

#include <cstdint>
#include <vector>

#include "tracking/centreline.h"

namespace vs {

struct TestTree {
  std::vector<int32_t> parent;
  std::vector<std::vector<int32_t>> children;
  std::vector<double> radius;
  std::vector<Vec3> q;
  // Appends a point under p (linked as its parent's last child) and returns its index.
  int32_t add(int32_t p, const Vec3& at, double r) {
    parent.push_back(p);
    children.emplace_back();
    if (p >= 0) children[static_cast<size_t>(p)].push_back(static_cast<int32_t>(q.size()));
    q.push_back(at), radius.push_back(r);
    return static_cast<int32_t>(q.size() - 1);
  }
};

}  // namespace vs
