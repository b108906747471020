#include "tracking/box_rounds.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "tracking/open_voxels.h"

namespace vs::retrace {

using detail::OpenVoxels;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

BoxRounds::BoxRounds(const NodeCost3D& cost, const Box& b, const std::vector<Step>& steps, const Index3& from,
                     const Index3& to)
    : cost_(cost), b_(b), steps_(steps), s_(b.index(from)), t_(b.index(to)) {
  const Geometry& g = cost.geometry;
  double shortest = kInf;
  for (const Step& st : steps) {
    offsets_.push_back(
        {st.d[0] + b.n[0] * (st.d[1] + b.n[1] * st.d[2]), g.linear(st.d[0], st.d[1], st.d[2]), st.lengthMm});
    for (size_t a = 0; a < 3; ++a) reach_[a] = std::max(reach_[a], std::abs(st.d[a]));
    shortest = std::min(shortest, st.lengthMm);
  }
  // The least step cost in the box (edgeCost's: its length times the node weight times the two ends' mean; the sign
  // term adds nothing below 0), halved for the product's own rounding. A sum d + e with e at least that grows wherever
  // it is more than d's half last bit: below it times 2^-52 of d; 2^50 leaves a margin.
  float least = std::numeric_limits<float>::infinity();
  for (int64_t z = b.lo[2]; z < b.lo[2] + b.n[2]; ++z)
    for (int64_t y = b.lo[1]; y < b.lo[1] + b.n[1]; ++y)
      for (int64_t x = b.lo[0]; x < b.lo[0] + b.n[0]; ++x)
        least = std::min(least, cost.node[static_cast<size_t>(g.linear(x, y, z))]);
  const double eMin = 0.5 * double(cost.nodeWeight) * double(least) * shortest;
  const bool signNonNegative = cost.sign.empty() || cost.signWeight >= 0;
  if (signNonNegative && eMin > 0 && std::isfinite(eMin)) growsBelow_ = std::ldexp(eMin, 50);
}

std::vector<Index3> BoxRounds::search(const std::vector<uint8_t>& blocked, double* outCost, BoxSearchStats* stats) {
  bool resume = valid_ && blocked.size() == blocked_.size();
  for (size_t i = 0; resume && i < blocked.size(); ++i)
    if (blocked_[i] && !blocked[i]) resume = false;  // a voxel opened again: a route may have appeared
  return resume ? resumed(blocked, outCost, stats) : full(blocked, outCost, stats);
}

// boxPath's search, word for word in its order, its settled voxels, distances and prevs kept.
std::vector<Index3> BoxRounds::full(const std::vector<uint8_t>& blocked, double* outCost, BoxSearchStats* stats) {
  const size_t n = static_cast<size_t>(b_.size());
  dist_.assign(n, kInf);
  prev_.assign(n, -1);
  settled_.assign(n, 0);
  blocked_ = blocked;
  kept_ = 0;
  std::vector<uint8_t> closed = blocked;  // settled or blocked
  OpenVoxels q(b_.size());
  dist_[static_cast<size_t>(s_)] = 0;
  q.set(static_cast<int32_t>(s_), 0.0);
  BoxSearchStats count;
  double last = 0;
  const bool reached = settle(q, closed, false, count, last);
  valid_ = last < growsBelow_;
  count.entries = q.entries();
  if (stats) *stats = count;
  return reached ? routeTo(outCost) : std::vector<Index3>{};
}

// The round from the last one's voxels whose chains meet no voxel blocked since (box_rounds.h).
std::vector<Index3> BoxRounds::resumed(const std::vector<uint8_t>& blocked, double* outCost, BoxSearchStats* stats) {
  std::vector<uint8_t> keep;
  keepsChains(blocked, keep);
  std::vector<uint8_t> closed = blocked;
  std::vector<int32_t> frontier;  // open voxels a settled one had reached: those the kept ones may reach
  kept_ = 0;
  for (size_t i = 0; i < keep.size(); ++i) {
    if (keep[i]) {
      closed[i] = 1;
      ++kept_;
      continue;
    }
    if (!blocked[i] && (settled_[i] || dist_[i] < kInf)) frontier.push_back(static_cast<int32_t>(i));
    dist_[i] = kInf, prev_[i] = -1, settled_[i] = 0;
  }
  blocked_ = blocked;
  BoxSearchStats count;
  OpenVoxels q(b_.size());
  for (const int32_t v : frontier) reachFromKept(v, keep, q, count);
  if (keep[static_cast<size_t>(t_)]) {  // the target's own chain is open still: the same route
    if (stats) *stats = count;
    return routeTo(outCost);
  }
  double last = 0;
  const bool reached = settle(q, closed, true, count, last);
  if (!(last < growsBelow_)) return full(blocked, outCost, stats);  // the sums might not grow: search in full
  count.entries = q.entries();
  if (stats) *stats = count;
  return reached ? routeTo(outCost) : std::vector<Index3>{};
}

// keep[i] = 1: voxel i was settled in the last search and its chain of prevs back to the start meets no voxel
// blocked now (a settled voxel was open then: blocked now is blocked since).
bool BoxRounds::keepsChains(const std::vector<uint8_t>& blocked, std::vector<uint8_t>& keep) const {
  const size_t n = settled_.size();
  std::vector<uint8_t> verdict(n, 0);  // 0 not known, 1 kept, 2 not
  std::vector<size_t> chain;
  for (size_t i = 0; i < n; ++i) {
    if (!settled_[i] || verdict[i]) continue;
    chain.clear();
    uint8_t v = 2;
    for (size_t j = i;;) {
      if (verdict[j]) {
        v = verdict[j];
        break;
      }
      chain.push_back(j);
      if (!settled_[j] || blocked[j]) break;
      if (prev_[j] < 0) {
        v = static_cast<int64_t>(j) == s_ ? 1 : 2;
        break;
      }
      j = static_cast<size_t>(prev_[j]);
    }
    for (const size_t c : chain) verdict[c] = v;
  }
  keep.assign(n, 0);
  bool any = false;
  for (size_t i = 0; i < n; ++i) keep[i] = verdict[i] == 1 ? 1 : 0, any = any || keep[i];
  return any;
}

bool BoxRounds::settle(OpenVoxels& q, std::vector<uint8_t>& closed, bool byKey, BoxSearchStats& count, double& last) {
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    closed[static_cast<size_t>(u)] = 1;
    settled_[static_cast<size_t>(u)] = 1;
    ++count.settled;
    last = d;
    if (u == t_) return true;
    open(u, d, closed, q, byKey, count);
  }
  return false;
}

// boxPath's steps from settled voxel u at distance d. byKey: a neighbour reached at its distance again takes u as its
// prev where u is settled before the prev it has - the order the full search reaches it in.
void BoxRounds::open(int32_t u, double d, std::vector<uint8_t>& closed, OpenVoxels& q, bool byKey,
                     BoxSearchStats& count) {
  const Geometry& g = cost_.geometry;
  const int32_t n0 = static_cast<int32_t>(b_.n[0]), n1 = static_cast<int32_t>(b_.n[1]);
  const int32_t ux = u % n0, uyz = u / n0;
  const Index3 uv{b_.lo[0] + ux, b_.lo[1] + uyz % n1, b_.lo[2] + uyz / n1};
  const int64_t ul = g.linear(uv[0], uv[1], uv[2]);
  bool inner = true;
  for (size_t a = 0; a < 3; ++a)
    inner = inner && uv[a] - reach_[a] >= b_.lo[a] && uv[a] + reach_[a] < b_.lo[a] + b_.n[a];
  for (size_t k = 0; k < offsets_.size(); ++k) {
    const Offset& o = offsets_[k];
    if (!inner && !b_.in({uv[0] + steps_[k].d[0], uv[1] + steps_[k].d[1], uv[2] + steps_[k].d[2]})) continue;
    const int64_t vi = u + o.box;
    const size_t v = static_cast<size_t>(vi);
    if (closed[v]) continue;
    ++count.costsRead;
    const double nd = d + cost_.edgeCost(ul, ul + o.volume, o.lengthMm);
    if (nd < dist_[v]) {
      dist_[v] = nd;
      prev_[v] = u;
      q.set(static_cast<int32_t>(vi), nd);
    } else if (byKey && nd == dist_[v] && prev_[v] >= 0 && before(u, prev_[v])) {
      prev_[v] = u;
    }
  }
}

// Open voxel v reached from its kept neighbours (each sum as the full search forms it: from the settled voxel along
// the step), the least distance taken, of its ties the neighbour settled first. A voxel no settled one had reached in
// the last search is reached by no kept one now (every settled voxel's steps were taken; a step it did not take into
// an open voxel costs no finite sum), so the frontier holds every voxel the kept ones reach.
void BoxRounds::reachFromKept(int32_t v, const std::vector<uint8_t>& keep, OpenVoxels& q, BoxSearchStats& count) {
  const Geometry& g = cost_.geometry;
  const Index3 vv = b_.voxel(v);
  const int64_t vl = g.linear(vv[0], vv[1], vv[2]);
  bool inner = true;
  for (size_t a = 0; a < 3; ++a)
    inner = inner && vv[a] - reach_[a] >= b_.lo[a] && vv[a] + reach_[a] < b_.lo[a] + b_.n[a];
  double best = kInf;
  int32_t from = -1;
  for (size_t k = 0; k < offsets_.size(); ++k) {
    const Offset& o = offsets_[k];
    if (!inner && !b_.in({vv[0] - steps_[k].d[0], vv[1] - steps_[k].d[1], vv[2] - steps_[k].d[2]})) continue;
    const int64_t wi = v - o.box;  // w + step k = v
    if (!keep[static_cast<size_t>(wi)]) continue;
    ++count.costsRead;
    const int32_t w = static_cast<int32_t>(wi);
    const double nd = dist_[static_cast<size_t>(wi)] + cost_.edgeCost(vl - o.volume, vl, o.lengthMm);
    if (nd < best || (nd == best && from >= 0 && before(w, from))) best = nd, from = w;
  }
  if (!(best < kInf)) return;
  dist_[static_cast<size_t>(v)] = best;
  prev_[static_cast<size_t>(v)] = from;
  q.set(v, best);
}

std::vector<Index3> BoxRounds::routeTo(double* outCost) const {
  std::vector<Index3> path;
  for (int64_t i = t_; i >= 0; i = prev_[static_cast<size_t>(i)]) path.push_back(b_.voxel(i));
  std::reverse(path.begin(), path.end());
  *outCost = dist_[static_cast<size_t>(t_)];
  return path;
}

}  // namespace vs::retrace
