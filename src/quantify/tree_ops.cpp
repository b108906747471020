// The tree-level helpers of quantify.h: coincident branches merged, a tree checked against a
// volume, the measured radii written back to the tree.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "quantify/quantify.h"
#include "util/error.h"

namespace vs {

Tree mergeCoincidentBranches(const Tree& input, int* merged) {
  Tree tree = input;
  if (merged) *merged = 0;
  auto radius = [&](int32_t i) { return tree.radii.empty() ? 0.0 : tree.radii[static_cast<size_t>(i)]; };
  for (bool changed = true; changed;) {
    changed = false;
    const size_t n = tree.size();
    std::vector<std::vector<int32_t>> children(n);
    for (size_t i = 0; i < n; ++i)
      if (tree.parent[i] >= 0) children[static_cast<size_t>(tree.parent[i])].push_back(static_cast<int32_t>(i));
    auto chain = [&](int32_t c) {
      std::vector<int32_t> out{c};
      while (children[static_cast<size_t>(out.back())].size() == 1)
        out.push_back(children[static_cast<size_t>(out.back())][0]);
      return out;
    };
    std::vector<char> drop(n, 0);
    for (size_t b = 0; b < n && !changed; ++b) {
      const auto& ch = children[b];
      for (size_t i = 0; i < ch.size() && !changed; ++i)
        for (size_t j = 0; j < ch.size() && !changed; ++j) {
          if (i == j) continue;
          std::vector<int32_t> A = chain(ch[i]), B = chain(ch[j]);
          if (A.size() < B.size() || (A.size() == B.size() && i > j)) continue;  // B: the shorter chain
          A.insert(A.begin(), static_cast<int32_t>(b));
          auto nearest = [&](int32_t q) {
            int32_t best = A[0];
            double bd = 1e300;
            for (int32_t a : A) {
              const double d = (tree.points[static_cast<size_t>(a)] - tree.points[static_cast<size_t>(q)]).norm();
              if (d < bd) bd = d, best = a;
            }
            return std::pair<int32_t, double>(best, bd);
          };
          size_t K = 0;
          while (K < B.size()) {
            const auto [a, d] = nearest(B[K]);
            if (!(d < 0.5 * radius(a))) break;
            ++K;
          }
          if (K < 2) continue;
          // B[0..K-1] run inside A's lumen: drop them, hang the rest of B (or B's children) on A.
          for (size_t k = 0; k < K; ++k) drop[static_cast<size_t>(B[k])] = 1;
          if (K < B.size()) {
            tree.parent[static_cast<size_t>(B[K])] = nearest(B[K]).first;
          } else {
            for (int32_t c : children[static_cast<size_t>(B.back())])
              tree.parent[static_cast<size_t>(c)] = nearest(c).first;
          }
          changed = true;
        }
    }
    if (!changed) break;
    if (merged) ++*merged;
    std::vector<int32_t> map(n, -1);
    Tree out;
    for (size_t i = 0; i < n; ++i) {
      if (drop[i]) continue;
      map[i] = static_cast<int32_t>(out.points.size());
      out.points.push_back(tree.points[i]);
      out.parent.push_back(tree.parent[i]);
      if (!tree.radii.empty()) out.radii.push_back(tree.radii[i]);
      if (!tree.types.empty()) out.types.push_back(tree.types[i]);
    }
    for (auto& p : out.parent)
      if (p >= 0) p = map[static_cast<size_t>(p)];
    tree = std::move(out);
  }
  return tree;
}

void checkTreeInVolume(const Geometry& g, const Tree& tree, const std::string& treeName) {
  tree.validate();
  if (tree.size() == 0) throw DataError(treeName + " has no points");
  size_t outside = 0, first = 0;
  for (size_t i = 0; i < tree.size(); ++i)
    if (!g.nearVolume(tree.points[i])) {
      if (outside++ == 0) first = i;
    }
  if (outside > 0) {
    const Vec3& p = tree.points[first];
    const Vec3 idx = g.worldToIndex(p);
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%zu of %zu points of %s lie outside the volume (%s), e.g. point %zu at "
                  "(%.1f, %.1f, %.1f) mm = voxel (%.1f, %.1f, %.1f): the tree does not belong to this volume "
                  "(another image or geometry)",
                  outside, tree.size(), treeName.c_str(), g.describe().c_str(), first, p[0], p[1], p[2], idx[0], idx[1],
                  idx[2]);
    throw DataError(buf);
  }
}

Tree treeWithMeasuredRadii(const TreeMeasurement& m, bool flaggedAsNaN) {
  const Tree& tree = m.tree;
  Tree out = tree;
  if (out.radii.size() != out.size() || flaggedAsNaN)
    out.radii.assign(out.size(), flaggedAsNaN ? std::numeric_limits<double>::quiet_NaN() : 0.0);
  for (const auto& seg : m.segments) {
    std::vector<std::pair<double, double>> prof;  // arc, radius
    for (int i : seg.sections) {
      const CrossSection& cs = m.sections[static_cast<size_t>(i)];
      if (cs.measured())
        prof.emplace_back(cs.arcMm, 0.5 * cs.equivalentDiameterMm);
      else if (flaggedAsNaN)
        prof.emplace_back(cs.arcMm, std::numeric_limits<double>::quiet_NaN());
    }
    if (prof.empty()) continue;
    double s = 0;
    for (size_t k = 0; k < seg.nodes.size(); ++k) {
      if (k > 0)
        s += (tree.points[static_cast<size_t>(seg.nodes[k])] - tree.points[static_cast<size_t>(seg.nodes[k - 1])])
                 .norm();
      if (k == 0 && seg.parent >= 0) continue;  // a branch point keeps its parent segment's radius
      auto best = std::min_element(prof.begin(), prof.end(), [&](const auto& a, const auto& b) {
        return std::abs(a.first - s) < std::abs(b.first - s);
      });
      out.radii[static_cast<size_t>(seg.nodes[k])] = best->second;
    }
  }
  return out;
}

}  // namespace vs
