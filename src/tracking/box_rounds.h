// The support re-search's rounds in one box (support_retrace.cpp; session 44 speedC): every round is boxPath's search
// of the same box from the same start to the same target with an infinite cap, the voxels blocked so far blocked -
// more each round, none opened again. A round's search is a function of its blocked voxels only, so the rounds can
// share what does not change between them.
//
// Why a voxel's answer survives a round (Dijkstra in floating point, every step's sum above its start: fl(d + e) > d).
// The search settles voxels in (distance, box index) order, and a voxel's distance is the least over its open
// neighbours w of fl(D(w) + e(w, v)); its `prev` is the first settled neighbour reaching that least value - the one
// of least (distance, index). Blocking voxels only removes routes: no distance falls. A voxel u settled in the last
// round whose chain of prevs back to the start meets no voxel blocked since keeps that chain, so its distance stays
// D(u) (no lower: none falls; no higher: the chain is still there). Its prev stays too: a neighbour reaching D(u) now
// reached it before (its distance no lower now, the sum monotone in it), so it was no earlier than u's old prev in
// the (distance, index) order then, and is no earlier now (the old prev's key is unchanged, the other's no lower).
// And every such voxel is settled before the target: its key was below the target's then, the target's is no lower
// now. So a round starts with those voxels settled, their distances and prevs as they are, opens their open
// neighbours from them, and searches on; a voxel reached at the same distance from two settled neighbours keeps the
// one of least (distance, index) - the one the full search settles first. Where the sums might not grow (a distance
// so large that the least step is below half its last bit, or a step of cost 0), the round is searched in full.
#pragma once

#include <cstdint>
#include <vector>

#include "tracking/box_search.h"

namespace vs::retrace {

namespace detail {
class OpenVoxels;
}

class BoxRounds {
 public:
  BoxRounds(const NodeCost3D& cost, const Box& b, const std::vector<Step>& steps, const Index3& from, const Index3& to);
  // boxPath(cost, b, blocked, steps, from, to, +infinity, outCost, stats): the same route and cost. `blocked` holds
  // every voxel the last call's did (else the search is run in full); from and to open.
  std::vector<Index3> search(const std::vector<uint8_t>& blocked, double* outCost, BoxSearchStats* stats = nullptr);
  // Voxels the last search took settled from the round before it (0: searched in full).
  int64_t kept() const { return kept_; }

 private:
  std::vector<Index3> full(const std::vector<uint8_t>& blocked, double* outCost, BoxSearchStats* stats);
  std::vector<Index3> resumed(const std::vector<uint8_t>& blocked, double* outCost, BoxSearchStats* stats);
  bool keepsChains(const std::vector<uint8_t>& blocked, std::vector<uint8_t>& keep) const;
  std::vector<Index3> routeTo(double* outCost) const;
  bool settle(detail::OpenVoxels& q, std::vector<uint8_t>& closed, bool byKey, BoxSearchStats& count, double& last);
  void open(int32_t u, double d, std::vector<uint8_t>& closed, detail::OpenVoxels& q, bool byKey,
            BoxSearchStats& count);
  void reachFromKept(int32_t v, const std::vector<uint8_t>& keep, detail::OpenVoxels& q, BoxSearchStats& count);
  bool before(int32_t a, int32_t b) const {  // a settled before b: (distance, box index)
    const size_t i = static_cast<size_t>(a), j = static_cast<size_t>(b);
    return dist_[i] < dist_[j] || (dist_[i] == dist_[j] && a < b);
  }
  struct Offset {
    int64_t box, volume;
    double lengthMm;
  };

  const NodeCost3D& cost_;
  Box b_;
  std::vector<Step> steps_;
  int64_t s_, t_;
  std::vector<Offset> offsets_;
  Index3 reach_{0, 0, 0};  // the longest step along each axis
  double growsBelow_ = 0;  // every step's sum grows from any distance below this: fl(d + e) > d
  bool valid_ = false;     // the last search's settled voxels, distances and prevs are a full search's
  std::vector<double> dist_;
  std::vector<int32_t> prev_;
  std::vector<uint8_t> settled_, blocked_;  // the last search's settled voxels and blocked voxels
  int64_t kept_ = 0;
};

}  // namespace vs::retrace
