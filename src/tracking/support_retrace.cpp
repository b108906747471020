#include "tracking/support_retrace.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

#include "tracking/auto_cost.h"
#include "tracking/box_rounds.h"
#include "tracking/box_search.h"
#include "tracking/path_support.h"

namespace vs {

namespace {

using retrace::Box;
using retrace::mmOf;

// The node cost stores eps + (1 - s)^power as float: s below this is none (path_support.cpp's).
constexpr double kNoMembership = 1e-6;

// The support test's verdict per voxel (path_support.h), each voxel asked once.
class Support {
 public:
  Support(const NodeCost3D& cost, const CrossingOptions& o)
      : cost_(cost), o_(o), finest_(cost.geometry.spacing.minCoeff()) {}
  // Background, not a dim tube: unsupported and no brighter than the local background.
  bool background(const Index3& v) {
    const VoxelSupport& s = of(v);
    return !s.supported && s.contrast <= 0;
  }
  // The stretches the re-search takes on a path: runs of voxels without lumen in the cost's model (membership 0)
  // that cross the background - their mean contrast no brighter than the local background (blockStretch's level) -
  // spanning at least `minSteps` steps of the path. Not the note's stretches (path_support.h): its 5 mm floor keeps
  // the note silent on the family's right paths, but a hop of 4 voxels from the trunk to a branch beside it is
  // shorter (11702's path 2: 3.97 mm), and a voxel the noise lifts beyond one spread (contrast +10 against a spread of
  // 6.8) splits a hop into runs of the note's kind too short for any floor, while the run without membership holds it
  // whole. A dim tube's own stretch without membership is brighter than its background on the mean (11702's b10: +8
  // over 11 voxels), so it is none. A path is searched again for a run of at least the note's minSpacings (2) counted
  // in steps instead of the largest spacing's mm: a run of one step is one voxel's dip between two (a slice's, a
  // corner's at a wide lumen's wall), two steps or more cross something. A step counts the whole finest voxels its
  // length spans, at least one (session 38 hop927): in-plane and isotropic steps count one, a step across a slice at
  // least twice the in-plane spacing two or more - 10927's two voxels without lumen one 2.90 mm slice apart (in-plane
  // 0.99) hop ~9 mm from b6 down to b9's end. A new route is kept only where it has no such run at all (minSteps 0).
  const VoxelSupport& at(const Index3& v) { return of(v); }
  std::vector<UnsupportedStretch> stretches(const std::vector<Index3>& path, double minSteps) {
    const Geometry& g = cost_.geometry;
    std::vector<UnsupportedStretch> out;
    for (size_t i = 0; i < path.size();) {
      if (of(path[i]).membership > kNoMembership) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j + 1 < path.size() && !(of(path[j + 1]).membership > kNoMembership)) ++j;
      UnsupportedStretch s;
      s.first = i, s.last = j;
      double sum = 0, steps = 0, noise = 0;
      for (size_t k = i; k <= j; ++k) {
        sum += of(path[k]).contrast;
        noise = std::max(noise, of(path[k]).noise);
        if (k == i) continue;
        const double step = (mmOf(g, path[k]) - mmOf(g, path[k - 1])).norm();
        s.lengthMm += step;
        steps += std::max(1.0, std::floor(step / finest_ + 1e-9));
      }
      s.meanContrast = sum / double(j - i + 1);
      s.noise = noise;
      if (steps >= minSteps && s.meanContrast <= 0) out.push_back(s);
      i = j + 1;
    }
    return out;
  }

 private:
  const VoxelSupport& of(const Index3& v) {
    const int64_t key = cost_.geometry.linear(v[0], v[1], v[2]);
    const auto it = known_.find(key);
    if (it != known_.end()) return it->second;
    return known_.emplace(key, pathSupport({v}, cost_, *o_.autoCost, *o_.smoothed, *o_.background, *o_.estimate)[0])
        .first->second;
  }
  const NodeCost3D& cost_;
  const CrossingOptions& o_;
  double finest_;  // the finest spacing (mm)
  std::unordered_map<int64_t, VoxelSupport> known_;
};

// The darkest of a route's runs without lumen that cross the background (any length): its mean contrast and the
// noise spread along it; none: +infinity.
std::pair<double, double> darkest(const std::vector<UnsupportedStretch>& runs) {
  std::pair<double, double> d{std::numeric_limits<double>::infinity(), 0};
  for (const UnsupportedStretch& s : runs)
    if (s.meanContrast < d.first) d = {s.meanContrast, s.noise};
  return d;
}

// Blocks the background a flagged stretch runs through: its own background voxels and the background voxels joined to
// them (26-connected) up to the stretch's own length from them (it crosses no more background than that), each no
// brighter than the stretch's mean contrast. Noise leaves single supported voxels in the background; the fill goes
// round them, as a route would. Only the background, no brighter than the stretch (session 38 hop927): a route that
// enters a dim tube beside a hop has the tube's own voxels in its run (10731's b12: +11 / +15 at its end, -0 / -2
// along it, a noise spread of 8.2), and blocking them, or every voxel at the background's level within the run's
// length (10.4 mm across four slices), closed the tube to the target it leads to.
void blockStretch(const Geometry& g, const Box& b, const std::vector<Index3>& path, const UnsupportedStretch& s,
                  Support& support, std::vector<uint8_t>& blocked) {
  std::vector<Index3> seeds;
  double level = 0;
  for (size_t k = s.first; k <= s.last; ++k) {
    level += support.at(path[k]).contrast / double(s.last - s.first + 1);
    if (support.background(path[k])) seeds.push_back(path[k]);
  }
  const auto within = [&](const Index3& w) {
    for (const Index3& v : seeds)
      if ((mmOf(g, w) - mmOf(g, v)).norm() <= s.lengthMm) return true;
    return false;
  };
  std::vector<Index3> queue = seeds;
  for (const Index3& v : seeds) blocked[static_cast<size_t>(b.index(v))] = 1;
  while (!queue.empty()) {
    const Index3 v = queue.back();
    queue.pop_back();
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const Index3 w{v[0] + dx, v[1] + dy, v[2] + dz};
          if (!b.in(w) || blocked[static_cast<size_t>(b.index(w))] || !within(w) || !support.background(w) ||
              support.at(w).contrast > level)
            continue;
          blocked[static_cast<size_t>(b.index(w))] = 1;
          queue.push_back(w);
        }
  }
}

}  // namespace

SupportRetrace retraceUnsupported(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                  const CrossingOptions& o) {
  SupportRetrace r;
  r.oldCost = chainCost(cost, path);
  if (!o.autoCost || !o.background || !o.estimate || !o.smoothed || path.size() < 3) return r;
  Support support(cost, o);
  std::vector<UnsupportedStretch> flagged = support.stretches(path, PathSupportOptions{}.minSpacings);
  r.stretches = static_cast<int>(flagged.size());
  if (flagged.empty()) return r;
  // The fallback where no route searched is free of such runs (session 38 hop927): the route whose darkest run is the
  // brightest, kept where that run lies within the noise spread of the background (the support test's unit: the
  // largest spread along it) and is brighter than the path's own darkest. A dim tube leading to its target can have
  // no route free of runs at the background's level (10731's b12: its last 8 voxels a mean -0.6, noise 8.2) while the
  // hop's run lies far below it (-47); the free route still wins wherever the schedule finds one, so a hop with a noise
  // voxel (10403's +3 -17 +5) is not taken before the tree's free route (the run test at -noise itself took it).
  std::vector<Index3> best;
  double bestCost = 0, bestLevel = darkest(support.stretches(path, 0)).first;
  const auto fallback = [&](const char* why) {
    if (best.empty()) {
      r.why = why;
      return r;
    }
    return retrace::accepted(r, r.oldCost, bestCost, std::move(best));
  };
  const Geometry& g = cost.geometry;
  // The box: the path's, with the other re-searches' margin (boxAround's), grown - its margin doubled - while no
  // route the test passes lies inside it, up to the whole volume or the re-searches' box limit. The tree's route round
  // the hop may run far from the path (11702: ~115 mm through branch 4 and the curled branch's first half, ending 15 mm
  // from the root), so one box of a fixed margin would not hold it; the growth finds it without a whole-volume search.
  std::vector<std::pair<std::vector<Index3>, UnsupportedStretch>> blocks;  // every stretch blocked so far, its route
  for (const UnsupportedStretch& s : flagged) blocks.emplace_back(path, s);
  const std::vector<retrace::Step> steps = retrace::stepsFor(g, connectivity);
  for (double margin = 12;; margin *= 2) {  // boxAround's default margin first
    const Box b = retrace::boxAround(g, path, 0, path.size() - 1, margin);
    if (b.size() > (int64_t(1) << 23)) {
      return fallback("no route within the re-searches' box limit with the stretch without lumen blocked");
    }
    std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
    for (const auto& [route, s] : blocks) blockStretch(g, b, route, s, support, blocked);
    // The rounds search the same box with more blocked each round: each takes the voxels whose routes the new blocks
    // leave as they were from the round before (box_rounds.h; session 44 speedC) - boxPath's routes, searched once.
    retrace::BoxRounds search(cost, b, steps, path.front(), path.back());
    for (int round = 0; round < std::max(1, o.maxRounds); ++round) {
      blocked[static_cast<size_t>(b.index(path.front()))] = 0;
      blocked[static_cast<size_t>(b.index(path.back()))] = 0;
      double c = 0;
      std::vector<Index3> route = search.search(blocked, &c);
      ++r.rounds;
      if (route.empty()) break;  // none inside this box: a larger one
      flagged = support.stretches(route, 0);
      if (flagged.empty()) return retrace::accepted(r, r.oldCost, c, std::move(route));
      if (const auto [level, noise] = darkest(flagged); level > -noise && level > bestLevel)
        best = route, bestCost = c, bestLevel = level;
      for (const UnsupportedStretch& s : flagged) {
        blockStretch(g, b, route, s, support, blocked);
        blocks.emplace_back(route, s);
      }
    }
    if (b.size() == g.dims[0] * g.dims[1] * g.dims[2]) break;  // the whole volume searched
  }
  return fallback("every route searched again still crosses a stretch without lumen");
}

}  // namespace vs
