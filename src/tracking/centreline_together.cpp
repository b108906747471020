// Forks of the search tree placed where the children's chains part (session 25, fork3). The tree of extracted
// paths branches at the first voxel where two paths differ; two paths to sibling branches can differ there by
// one voxel and then run side by side, a voxel apart, through their whole common parent to the real fork (the
// family's 10801 / 10201: 23-24 points). Refined separately, both chains are centred onto the parent's axis,
// the tree's fork lies far upstream of the junction, so the fork placements (centreline_junctions.cpp, which
// reach a few parent radii from the tree's fork) never see the junction, and the own-lobe step past it anchors
// points on a raw voxel that lies within a voxel of both children's axes (session 24 thin16). Here the two
// chains are one chain while their voxels stay neighbours, up to their last pair within a voxel: the later
// chain's points there follow the earlier chain's and its rest hangs from the earlier chain's point there.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tracking/centreline.h"
#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

namespace {

// The points of the plain chain from `c` (each with exactly one child) up to, not including, the first
// point with no child or several.
std::vector<size_t> plainChain(const std::vector<std::vector<int32_t>>& children, size_t c) {
  std::vector<size_t> out;
  for (size_t k = c; children[k].size() == 1; k = static_cast<size_t>(children[k][0])) out.push_back(k);
  return out;
}

// Neighbouring voxels (26-connected: two staircases along one vessel are diagonal neighbours at times), and
// within a voxel (the same voxel or a face neighbour).
bool neighbours(const Vec3& a, const Vec3& b) { return (a - b).cwiseAbs().maxCoeff() <= 1 + 1e-6; }
bool withinAVoxel(const Vec3& a, const Vec3& b) { return (a - b).cwiseAbs().sum() <= 1 + 1e-6; }

}  // namespace

TogetherForks mergeTogetherChains(const CentrelineTree& tree, const Vec3& spacing, double minTogetherMm) {
  TogetherForks out;
  const size_t n = tree.points.size();
  out.merged = tree;
  out.newIndex.resize(n);
  for (size_t k = 0; k < n; ++k) out.newIndex[k] = static_cast<int32_t>(k);
  if (tree.parent.size() != n || n == 0) return out;  // refineTree names what is wrong
  for (size_t k = 1; k < n; ++k)
    if (tree.parent[k] < 0 || tree.parent[k] >= static_cast<int32_t>(k)) return out;
  std::vector<std::vector<int32_t>> children(n);
  for (size_t k = 1; k < n; ++k) children[static_cast<size_t>(tree.parent[k])].push_back(static_cast<int32_t>(k));
  std::vector<int32_t> parent = tree.parent;
  out.leader.assign(n, -1);
  out.stepsUp.assign(n, 0);
  out.reattached.assign(n, -1);
  size_t merges = 0;
  for (size_t b = 0; b < n; ++b) {
    if (children[b].size() != 2) continue;
    // The earlier chain (the smaller index: its path was recorded first) leads; its points precede the later's.
    const size_t c0 = static_cast<size_t>(std::min(children[b][0], children[b][1]));
    const size_t c1 = static_cast<size_t>(std::max(children[b][0], children[b][1]));
    const std::vector<size_t> A = plainChain(children, c0), B = plainChain(children, c1);
    if (A.empty() || B.empty() || !withinAVoxel(tree.points[A[0]], tree.points[B[0]])) continue;
    // Walk both chains together (monotone, the nearest next pair) while their voxels are neighbours; a pair
    // within a voxel first: on thick slices a face neighbour across them (11402: 2.01 mm) lies farther than an
    // in-plane diagonal (1.40 mm), and the walk took diagonals past the pairs that carry the run on (session 30
    // thin27; on a grid whose slices are under 1.41 times the in-plane spacing the nearest pair is one anyway).
    auto dist = [&](size_t i, size_t j) {
      return (tree.points[A[i]] - tree.points[B[j]]).cwiseProduct(spacing).norm();
    };
    std::vector<size_t> pairOf(B.size(), 0);
    std::vector<double> pairDist(B.size(), std::numeric_limits<double>::infinity());
    size_t i = 0, j = 0, lastI = 0, lastJ = 0;
    pairDist[0] = dist(0, 0);
    for (;;) {
      const size_t opts[3][2] = {{i + 1, j + 1}, {i + 1, j}, {i, j + 1}};
      double best = std::numeric_limits<double>::infinity();
      bool bestWithin = false;
      size_t bi = i, bj = j;
      for (const auto& o : opts) {
        if (o[0] >= A.size() || o[1] >= B.size() || !neighbours(tree.points[A[o[0]]], tree.points[B[o[1]]])) continue;
        const double d = dist(o[0], o[1]);
        const bool within = withinAVoxel(tree.points[A[o[0]]], tree.points[B[o[1]]]);
        if (within > bestWithin || (within == bestWithin && d < best - 1e-9))
          best = d, bestWithin = within, bi = o[0], bj = o[1];
      }
      if (bi == i && bj == j) break;
      i = bi, j = bj;
      if (best < pairDist[j]) pairDist[j] = best, pairOf[j] = i;
      if (withinAVoxel(tree.points[A[i]], tree.points[B[j]])) lastI = i, lastJ = j;
    }
    // The run ends at its last pair within a voxel: its diagonal pairs after that are where the paths part
    // (10801: a fork at the last diagonal pair lay a voxel past the junction, in the crotch, 1.3 voxels off).
    i = lastI, j = lastJ;
    for (size_t s = 0; s <= j; ++s) pairOf[s] = std::min(pairOf[s], i);
    // Together along the leading chain from b to its point A[i]: short runs are the fork's own (the discrete
    // paths part over a few voxels at any fork) and are left to the fork placements.
    double alongMm = (tree.points[A[0]] - tree.points[b]).cwiseProduct(spacing).norm();
    for (size_t a = 1; a <= i; ++a) alongMm += (tree.points[A[a]] - tree.points[A[a - 1]]).cwiseProduct(spacing).norm();
    if (alongMm < minTogetherMm) continue;
    const size_t rest = static_cast<size_t>(children[B[j]][0]);  // the later chain's first point past the run
    if (A[i] >= rest) continue;                                  // parents must precede their children
    for (size_t s = 0; s <= j; ++s) {
      out.leader[B[s]] = static_cast<int32_t>(A[pairOf[s]]);
      out.stepsUp[B[s]] = static_cast<int32_t>(i - pairOf[s]);
      out.reattached[B[s]] = static_cast<int32_t>(rest);
    }
    parent[rest] = static_cast<int32_t>(A[i]);
    ++merges;
  }
  out.merges = merges;
  if (merges == 0) return out;
  // The merged tree: the followers left out, the rest in their order (parents still precede children).
  CentrelineTree& m = out.merged;
  m.points.clear(), m.parent.clear();
  for (size_t k = 0; k < n; ++k) {
    if (out.leader[k] >= 0) {
      out.newIndex[k] = -1;
      continue;
    }
    out.newIndex[k] = static_cast<int32_t>(m.points.size());
    out.oldIndex.push_back(static_cast<int32_t>(k));
    m.points.push_back(tree.points[k]);
    m.parent.push_back(k == 0 ? -1 : out.newIndex[static_cast<size_t>(parent[k])]);
  }
  return out;
}

RefinedCentreline expandTogether(const TogetherForks& t, const CentrelineTree& tree, const RefinedCentreline& r) {
  if (t.merges == 0) return r;
  const size_t n = tree.points.size(), nm = t.oldIndex.size(), total = n + (r.points.size() - nm);
  auto toOld = [&](int32_t k) {
    if (k < 0) return k;
    const size_t u = static_cast<size_t>(k);
    return u < nm ? t.oldIndex[u] : static_cast<int32_t>(n + (u - nm));
  };
  RefinedCentreline out;
  out.polarity = r.polarity;  // confineToLumen's image test and ridgeDimPoints need it (session 36 diag024)
  out.points.resize(total), out.radiiMm.resize(total), out.parent.resize(total), out.source.resize(total);
  const bool wide = r.wideTrunk.size() == r.points.size();
  if (wide) out.wideTrunk.resize(total);
  auto take = [&](size_t k, size_t from) {
    out.points[k] = r.points[from], out.radiiMm[k] = r.radiiMm[from];
    if (wide) out.wideTrunk[k] = r.wideTrunk[from];
  };
  for (size_t k = 0; k < n; ++k) {
    out.source[k] = static_cast<int32_t>(k);
    if (t.leader[k] < 0) {
      const size_t mk = static_cast<size_t>(t.newIndex[k]);
      take(k, mk);
      // The later chain's rest keeps its own parent in the output tree (each path's chain as searched).
      const bool rest = k > 0 && t.newIndex[static_cast<size_t>(tree.parent[k])] < 0;
      out.parent[k] = rest ? tree.parent[k] : toOld(r.parent[mk]);
      continue;
    }
    // A follower: the point stepsUp above the refined parent of its chain's rest (a copy there where the
    // fork was re-branched), i.e. its leader as refined.
    int32_t at = r.parent[static_cast<size_t>(t.newIndex[static_cast<size_t>(t.reattached[k])])];
    for (int32_t s = 0; s < t.stepsUp[k] && at >= 0; ++s) at = r.parent[static_cast<size_t>(at)];
    take(k, at >= 0 ? static_cast<size_t>(at) : static_cast<size_t>(t.newIndex[static_cast<size_t>(t.leader[k])]));
    out.parent[k] = tree.parent[k];
  }
  for (size_t u = nm; u < r.points.size(); ++u) {
    const size_t k = n + (u - nm);
    take(k, u);
    out.parent[k] = toOld(r.parent[u]);
    out.source[k] = toOld(r.source[u]);
  }
  return out;
}

}  // namespace vs::centreline_detail

namespace vs {

RefinedCentreline refineCentreline(const VolumeF32& vol, const CentrelineTree& tree, const CentrelineOptions& o,
                                   Progress& progress) {
  if (!(o.togetherForkMm > 0) || !o.junctions || o.iterations == 0)
    return centreline_detail::refineTree(vol, tree, o, progress);
  const centreline_detail::TogetherForks t =
      centreline_detail::mergeTogetherChains(tree, vol.geometry().spacing, o.togetherForkMm);
  if (t.merges == 0) return centreline_detail::refineTree(vol, tree, o, progress);
  return centreline_detail::expandTogether(t, tree, centreline_detail::refineTree(vol, t.merged, o, progress));
}

}  // namespace vs
