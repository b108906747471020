// Shortest distances from sources over a graph whose edge lengths all lie in [minStep, maxStep], minStep > 0
// (a voxel grid's geodesic distance: the steps' lengths in mm), by a queue of buckets minStep / 2 wide (Dial's
// buckets, Dinitz's rule): every node in the lowest non-empty bucket has its final distance, since a node
// reached from a node not settled yet lies at least minStep beyond it, at least one whole bucket further. No
// heap: each entry is appended to its bucket once and read once.
//
// The distances are the same doubles a Dijkstra with any exact priority queue gives (the binary heap of
// (distance, id) pairs, util/exact_radix_queue.h): both give each node the least of its start and, over its
// neighbours, fl(the neighbour's distance + the edge), and that system has one solution (with edges > 0,
// fl(d + e) > d: the node where two solutions first differ would take its value from a neighbour on which
// they agree). Only the order in which equal distances are settled differs, which decides predecessors (not
// kept here), not distances.
#pragma once

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace vs {

// n nodes; sources: (node, start distance >= 0); each(u, relax) calls relax(v, edge length) for every
// neighbour v of u (edge lengths in [minStep, maxStep]); onPush(v) is called when v's distance is lowered
// (e.g. to prefetch what settling it reads). Unreached nodes keep +infinity.
template <class ForEachNeighbour, class OnPush>
std::vector<double> bucketDistances(size_t n, const std::vector<std::pair<int32_t, double>>& sources, double minStep,
                                    double maxStep, ForEachNeighbour&& each, OnPush&& onPush) {
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  if (sources.empty()) return dist;
  assert(minStep > 0 && maxStep >= minStep);
  const double width = 0.5 * minStep;
  const auto bucketOf = [&](double d) { return static_cast<int64_t>(std::floor(d / width)); };
  // Pending keys lie in [current, current + ring): a push from the current bucket lands at most
  // ceil(maxStep / width) + 1 buckets further; one more for the rounding of the floor.
  const auto ring = static_cast<int64_t>(std::ceil(maxStep / width)) + 3;
  std::vector<std::vector<int32_t>> bucket(static_cast<size_t>(ring));
  auto slotOf = [&](int64_t k) -> std::vector<int32_t>& { return bucket[static_cast<size_t>(k % ring)]; };
  std::vector<uint64_t> settled((n + 63) / 64, 0);
  auto isSettled = [&](int32_t v) { return (settled[static_cast<size_t>(v) >> 6] >> (v & 63)) & 1u; };
  size_t pending = 0;
  auto enter = [&](int32_t s, double d0, int64_t k) {
    if (!isSettled(s) && d0 < dist[static_cast<size_t>(s)])
      dist[static_cast<size_t>(s)] = d0, slotOf(k).push_back(s), ++pending;
  };
  // Sources within the ring of the nearest one enter at once; any further ones (starts further apart than
  // the ring) when the queue reaches their bucket.
  int64_t current = std::numeric_limits<int64_t>::max();
  for (const auto& src : sources) current = std::min(current, bucketOf(src.second));
  std::vector<std::pair<double, int32_t>> later;
  for (const auto& [s, d0] : sources)
    if (bucketOf(d0) < current + ring - 1)
      enter(s, d0, bucketOf(d0));
    else
      later.push_back({d0, s});
  std::sort(later.begin(), later.end());
  size_t nextLater = 0;
  while (pending > 0 || nextLater < later.size()) {
    if (pending == 0) current = std::max(current, bucketOf(later[nextLater].first));
    for (; nextLater < later.size() && bucketOf(later[nextLater].first) <= current; ++nextLater)
      enter(later[nextLater].second, later[nextLater].first, current);
    std::vector<int32_t>& now = slotOf(current);
    for (size_t i = 0; i < now.size(); ++i) {  // by index: a push into the current bucket is read too
      const int32_t u = now[i];
      if (isSettled(u)) continue;  // a stale entry: settled from a lower bucket
      settled[static_cast<size_t>(u) >> 6] |= uint64_t{1} << (u & 63);
      const double d = dist[static_cast<size_t>(u)];
      each(u, [&](int32_t v, double mm) {
        if (isSettled(v)) return;
        double& dv = dist[static_cast<size_t>(v)];
        const double nd = d + mm;
        if (nd < dv) {
          dv = nd;
          const int64_t k = std::max(current, bucketOf(nd));
          assert(k < current + ring);
          slotOf(k).push_back(v);
          ++pending;
          onPush(v);
        }
      });
    }
    pending -= now.size();
    now.clear();
    ++current;
  }
  return dist;
}

}  // namespace vs
