#include "tracking/tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "features/features3d.h"
#include "tracking/auto_cost.h"
#include "tracking/contact_retrace.h"
#include "tracking/dip_retrace.h"
#include "tracking/fused_fork.h"
#include "tracking/lumen_recentre.h"
#include "tracking/neck_retrace.h"
#include "tracking/support_retrace.h"
#include "tracking/tracker_impl.h"
#include "tracking/trunk_join.h"
#include "tracking/voxel_line.h"
#include "volume/neighbourhood.h"
#include "volume/sample.h"

namespace vs {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string str(const Index3& v) {
  return "(" + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]) + ")";
}

// The stretch a re-search replaced in tp (found: the search's route): both routes
// up to the first voxel of their common tail (at least the target).
Reroute rerouteOf(const std::vector<Index3>& found, const TracedPath& tp) {
  const std::vector<Index3>& kept = tp.voxels;
  size_t tail = 0;
  while (tail < found.size() && tail < kept.size() && found[found.size() - 1 - tail] == kept[kept.size() - 1 - tail])
    ++tail;
  tail = std::max<size_t>(tail, 1);
  Reroute r;
  r.found.assign(found.begin(), found.end() - static_cast<std::ptrdiff_t>(tail) + 1);
  r.kept.assign(kept.begin(), kept.end() - static_cast<std::ptrdiff_t>(tail) + 1);
  r.sidewaysSteps = tp.sidewaysSteps;
  r.neckCrossings = tp.neckCrossings;
  return r;
}

// Gives tp the replacement r when tp's route from the root runs through r's stretch, or ends inside it
// on a voxel the replacement passes (its target lies between the step and where the routes meet again).
bool takeReroute(TracedPath& tp, const Reroute& r, const NodeCost3D& cost) {
  if (r.ownTube) return false;
  const size_t n = std::min(tp.voxels.size(), r.found.size());
  if (!std::equal(tp.voxels.begin(), tp.voxels.begin() + static_cast<std::ptrdiff_t>(n), r.found.begin())) return false;
  std::vector<Index3> v;
  if (n == r.found.size()) {
    v = r.kept;
    v.insert(v.end(), tp.voxels.begin() + static_cast<std::ptrdiff_t>(n), tp.voxels.end());
  } else {
    const auto at = std::find(r.kept.begin(), r.kept.end(), tp.voxels.back());
    if (at == r.kept.end()) return false;
    v.assign(r.kept.begin(), at + 1);
  }
  if (v == tp.voxels) return false;  // it ends before the stretch
  tp.voxels = std::move(v);
  tp.cost = chainCost(cost, tp.voxels);
  if (!tp.retraced) tp.sidewaysSteps = r.sidewaysSteps, tp.neckCrossings = r.neckCrossings;
  tp.retraced = true;
  return true;
}

// A re-search keeps the route up to a voxel and searches again from there, so its new stretch can start by running back
// along the route kept before it (17401 path 2: the search hopped through the background from a sibling's tip to the
// target, and the support re-search from that tip went back down the sibling to where the routes part; 17712 path 1:
// the lateral-step re-search from 6 voxels into the neighbour went back 4 of them). A minimum-cost route from the root
// passes no place twice: where the new stretch's first voxels each lie within a voxel of the kept route and reach back
// to a kept voxel more than a voxel from where it starts (not a corner), the kept route is cut back to that voxel and
// joined to the stretch where the stretch leaves it. old: the route before the re-search; true when it cut.
bool cutRetracedStart(const std::vector<Index3>& old, std::vector<Index3>& route) {
  size_t same = 0;
  while (same < old.size() && same < route.size() && old[same] == route[same]) ++same;
  if (same < 2 || same >= route.size()) return false;
  const size_t start = same - 1;  // the stretch's first voxel, the last one both routes share
  const auto near = [](const Index3& a, const Index3& b) {
    return std::abs(a[0] - b[0]) <= 1 && std::abs(a[1] - b[1]) <= 1 && std::abs(a[2] - b[2]) <= 1;
  };
  const auto firstNear = [&](const Index3& v) {  // the earliest kept voxel within a voxel of v (start if none)
    return static_cast<size_t>(std::find_if(route.begin(), route.begin() + static_cast<std::ptrdiff_t>(start),
                                            [&](const Index3& k) { return near(k, v); }) -
                               route.begin());
  };
  size_t back = start;  // the stretch's last voxel of its run beside the kept route
  while (back + 1 < route.size() && firstNear(route[back + 1]) < start) ++back;
  if (back == start) return false;
  const size_t cut = firstNear(route[back]);
  if (near(route[cut], route[start])) return false;
  route.erase(route.begin() + static_cast<std::ptrdiff_t>(route[cut] == route[back] ? cut : cut + 1),
              route.begin() + static_cast<std::ptrdiff_t>(back));
  return true;
}

// The checks and re-searches on tp's voxels from `from` on (those before are kept); true when a
// re-search replaced a stretch. level: the lumen's cost level, estimated once per tracker
// (negative: not yet), only when a re-search needs it.
bool retraceFrom(const NodeCost3D& nodeCost, const TrackerOptions& opt, double& level, const Geometry& geom,
                 TracedPath& tp, size_t from, LoopedTurnMemo& loopedTurns, NeckSectionMemo& sections, bool& ownTube) {
  ownTube = false;
  CrossingOptions crossing = opt.crossing;  // with the tracker's sections already read (neck_sections.h)
  crossing.neckSections = &sections;
  const std::vector<Index3> part(tp.voxels.begin() + static_cast<std::ptrdiff_t>(from), tp.voxels.end());
  auto lumenLevel = [&] {
    if (level < 0) level = std::isnan(crossing.lumenLevel) ? lumenCostThreshold(nodeCost) : crossing.lumenLevel;
    return level;
  };
  std::vector<Index3> voxels;
  double cost = 0;
  int sideways = 0, neck = 0;
  const auto take = [&](RetraceOutcome&& r) {  // a re-search's new route, where it changed one
    if (r.changed) voxels = std::move(r.voxels), cost = r.newCost;
    return r.changed;
  };
  // A re-search between two touching tubes moves a path out of the tube it strayed into: its new route is refused where
  // it changes tube more times than the route it replaces, the tube read by the width of the lobe the route runs in
  // (tubeWidthChanges, neck_retrace.h) - across a contact fused by thick slices the two tubes cost alike and the blocks
  // leave a route in the other tube as readily as the own one.
  const auto noMoreChanges = [&](RetraceOutcome&& r, const std::vector<Index3>& old) {
    if (r.changed && tubeWidthChanges(r.voxels, crossing) > tubeWidthChanges(old, crossing)) r.changed = false;
    return std::move(r);
  };
  const auto retraceNeck = [&](const std::vector<Index3>& route, const CrossingOptions& how) {
    NeckRetrace nr = retraceAcrossNeck(nodeCost, route, opt.connectivity, how);
    const int crossings = nr.crossings;
    if (take(noMoreChanges(std::move(nr), route))) neck = crossings;
  };
  std::vector<LateralStep> steps = findLateralSteps(geom, part, crossing);
  if (!steps.empty() || crossing.driftSteps > 0)  // drifts are found with the lumen only
    steps = findLateralSteps(geom, part, crossing, &nodeCost, lumenLevel());
  sideways = static_cast<int>(steps.size());
  if (!steps.empty()) {
    take(noMoreChanges(retraceAcrossCrossings(nodeCost, part, opt.connectivity, lumenLevel(), crossing), part));
  }
  // A drift across the contact of two touching tubes: found on the smoothed intensity's lobes. Also
  // on a route the lateral-step re-search changed: it replaces only the stretch round its step, and the
  // route after it may still run in the touching tube (10612: path 0 in B from the fork to where the
  // tubes part, 34 points on the neighbour, never looked at for a neck).
  if (crossing.smoothed) {
    retraceNeck(voxels.empty() ? part : voxels, crossing);
  }
  // A jump through the background between two tubes a slice apart: found on the smoothed intensity.
  if (voxels.empty() && crossing.smoothed &&
      take(retraceAcrossDip(nodeCost, part, opt.connectivity, lumenLevel(), crossing))) {
    // The dip's new route may step into the other tube only where it departs, having run along the
    // tube left from the fork (11407: A to x 72, then B): the neck tests see that crossing.
    // Where the cost reads the tube taken as background (it did across the dip) its route round the
    // neck costs more than the slack allows everywhere; held to the lumen by intensity instead.
    CrossingOptions byIntensity = crossing;
    byIntensity.neckByIntensity = true;
    retraceNeck(voxels, byIntensity);
  }
  // Where no re-search changed the path: the neck re-search held to the lumen by intensity, only where the node cost
  // reads a stretch of that route as no lumen (11709: 12 mm of the thin tube at the cost's ceiling, the path in the
  // thick one; 11407 is held today only because a hole in its own tube triggers the dip re-search above).
  if (voxels.empty() && crossing.smoothed) {
    CrossingOptions byIntensity = crossing;
    byIntensity.neckByIntensity = true;
    byIntensity.neckByIntensityInHole = true;
    retraceNeck(part, byIntensity);
  }
  // A corner cut through the contact of two tubes crossing at an angle (contact_retrace.h).
  if (voxels.empty()) take(retraceAcrossContact(nodeCost, part, opt.connectivity, lumenLevel(), crossing));
  // A turn into a tube that loops back to the fork the path came from (contact_retrace.h).
  if (voxels.empty())
    take(retraceLoopedContact(nodeCost, part, opt.connectivity, lumenLevel(), crossing, &loopedTurns));
  // A stretch the path support test flags (no lumen, no contrast: a hop through the background) searched again with
  // that background blocked, kept only where the new route has no such stretch (support_retrace.h).
  if (voxels.empty()) take(retraceUnsupported(nodeCost, part, opt.connectivity, crossing));
  // The route's own tube read by width (retraceByWidth, neck_retrace.h): a stretch in the other width searched again
  // with that width's lobe blocked - the ties the search itself loses at a fused contact (kind A).
  bool wholeRoute = false;  // the width re-search's route replaces the path from its start (below)
  if (crossing.smoothed) {
    const std::vector<Index3> route = voxels.empty() ? part : voxels;
    bool startBlocked = false;
    RetraceOutcome bw = retraceByWidth(nodeCost, route, opt.connectivity, crossing, &startBlocked);
    // A later round's stretch that starts inside the lobe to block starts in the other tube: the route before it came
    // along that tube from the fork, and the path's own start is the one place known to lie before the fork (the
    // first round's, retraceByWidth's own rule) - the whole route read and searched again from there (8007 path 0:
    // its second round's stretch starts 17 sections into the wide neighbour, its own thin lobe over the last 8).
    if (!bw.changed && startBlocked && from > 0) {
      std::vector<Index3> whole(tp.voxels.begin(), tp.voxels.begin() + static_cast<std::ptrdiff_t>(from));
      whole.insert(whole.end(), route.begin(), route.end());
      RetraceOutcome fromStart = retraceByWidth(nodeCost, whole, opt.connectivity, crossing);
      if (fromStart.changed) bw = std::move(fromStart), wholeRoute = true;
    }
    ownTube = bw.changed && voxels.empty();
    take(std::move(bw));
  }
  if (from == 0 && !tp.retraced) tp.sidewaysSteps = sideways;  // the search's own path: counted even if kept
  if (voxels.empty()) return false;
  std::vector<Index3> route;
  if (from == 0 || wholeRoute) {
    route = std::move(voxels);
  } else {
    route.assign(tp.voxels.begin(), tp.voxels.begin() + static_cast<std::ptrdiff_t>(from));
    route.insert(route.end(), voxels.begin(), voxels.end());
  }
  const bool cut = cutRetracedStart(tp.voxels, route);
  tp.voxels = std::move(route);
  tp.cost = (from == 0 || wholeRoute) && !cut ? cost : chainCost(nodeCost, tp.voxels);
  if (from > 0) tp.sidewaysSteps += sideways;
  tp.neckCrossings += neck;
  tp.retraced = true;
  return true;
}
}  // namespace

VesselTracker::VesselTracker(const VolumeF32& volume, const NodeCost3D& cost, const Index3& root,
                             const TrackerOptions& options, Progress& progress)
    : impl_(std::make_unique<Impl>(volume, cost, options)), geom_(volume.geometry()) {
  VS_REQUIRE(!volume.empty(), "tracker: empty volume");
  VS_REQUIRE(cost.node.size() == static_cast<size_t>(volume.size()),
             "tracker: cost volume size differs from the intensity volume");
  VS_REQUIRE(options.connectivity == 6 || options.connectivity == 18 || options.connectivity == 26,
             "--connectivity must be 6, 18 or 26, got " + std::to_string(options.connectivity));
  if (!geom_.contains(root))
    throw InvalidArgument("root voxel " + str(root) + " is outside the volume " + geom_.describe());
  requestedRoot_ = root;
  Impl& m = *impl_;
  const auto t0 = Clock::now();
  m.stats.voxels = geom_.voxelCount();
  SearchOptions so;
  so.queue = options.queue;
  if (options.prune == PruneMode::None) {
    m.grid.emplace(geom_.dims, std::array<double, 3>{geom_.spacing[0], geom_.spacing[1], geom_.spacing[2]},
                   options.connectivity);
    m.gridCost = cost.gridCost();
    m.stats.nodes = m.stats.voxels;
    int64_t e = 0;
    for (int k = m.grid->directionCount() / 2; k < m.grid->directionCount(); ++k) {
      const auto& o = m.grid->offset(k);
      e += (geom_.dims[0] - std::abs(o[0])) * (geom_.dims[1] - std::abs(o[1])) * (geom_.dims[2] - std::abs(o[2]));
    }
    m.stats.edges = e;
    m.rootNode = m.grid->node(root[0], root[1], root[2]);
    m.stats.graphSeconds = since(t0);
    const auto t1 = Clock::now();
    m.search = std::make_unique<ShortestPathSearch>(*m.grid, m.gridCost, std::vector<int64_t>{m.rootNode}, so);
    m.stats.searchSeconds += since(t1);
  } else {
    m.pruned = std::make_unique<PrunedGraph>(
        buildPrunedGraph(volume, cost, options.connectivity, options.isoRegion, progress));
    m.stats.nodes = m.pruned->nodes;
    m.stats.edges = m.pruned->edges;
    m.stats.repairEdges = m.pruned->repairEdges;
    m.rootNode = m.pruned->nearestNode(root);
    if (m.rootNode < 0) throw DataError("the pruned graph has no node (empty volume after thresholding?)");
    m.stats.graphSeconds = since(t0);
    const auto t1 = Clock::now();
    m.search = std::make_unique<ShortestPathSearch>(m.pruned->graph, std::vector<int64_t>{m.rootNode}, so);
    m.stats.searchSeconds += since(t1);
  }
  root_ = geom_.unlinear(m.voxelOfNode(m.rootNode));
  // The tree starts with the root.
  m.treeIndex[m.voxelOfNode(m.rootNode)] = 0;
  m.treeVoxel.push_back(root_);
  m.treeParent.push_back(-1);
  m.treeChildren.push_back(0);
  m.treeOwner.push_back(-1);
}

VesselTracker::~VesselTracker() = default;

const TracedPath& VesselTracker::addTarget(const Index3& target, Progress& progress) {
  Impl& m = *impl_;
  if (!geom_.contains(target))
    throw InvalidArgument("target voxel " + str(target) + " is outside the volume " + geom_.describe());
  TracedPath tp;
  tp.requested = target;
  const int64_t node = m.snap(target);
  tp.target = geom_.unlinear(m.voxelOfNode(node));
  const auto t0 = Clock::now();
  const bool ok = m.search->settleUntil(node, progress);
  m.stats.searchSeconds += since(t0);
  if (ok) {
    const Path p = m.search->settledPath(node);
    tp.reached = !p.empty();
    tp.cost = p.cost;
    // Voxel chain; long (pruned) edges are rasterised so the chain is 26-connected.
    std::vector<Index3> nodesVox;
    nodesVox.reserve(p.nodes.size());
    for (int64_t n : p.nodes) nodesVox.push_back(geom_.unlinear(m.voxelOfNode(n)));
    for (size_t i = 0; i < nodesVox.size(); ++i) {
      if (i == 0) {
        tp.voxels.push_back(nodesVox[0]);
        continue;
      }
      forEachVoxelAfter(nodesVox[i - 1], nodesVox[i], [&](const Index3& q) { tp.voxels.push_back(q); });
    }
  }
  if (tp.reached && m.grid && m.opt.crossing.enabled) {
    retraceCrossings(tp);
    joinTrunks(tp);
    // A route whose start reads one flat lumen (section_shape.h: elongated, no waist, a plateau) searched again in its
    // own lumen, centred (lumen_recentre.h): on main's flat floor a flat lumen's routes fan off its centre line. Two
    // tubes fused at a contact and a round trunk's parallel routes share sections too, but read a waist or no
    // plateau, or round (sessions 48-49: flatre, flatpeaks, flatshared centred them all). After the re-searches,
    // which read a route's steps between touching tubes as the search left them.
    if (m.lumenLevel < 0)
      m.lumenLevel = std::isnan(m.opt.crossing.lumenLevel) ? lumenCostThreshold(m.cost) : m.opt.crossing.lumenLevel;
    // The shape read on the model's smoothed intensities and its background (none without the auto cost's model).
    RecentreImage image;
    const CrossingOptions& co = m.opt.crossing;
    if (co.smoothed && co.autoCost && co.estimate)
      image = {co.smoothed, co.brightLumen ? 1.0 : -1.0, co.autoCost->valleyNoiseFloor * co.estimate->spread,
               co.estimate->surround};
    if (co.estimate && routeStartReadsFlat(m.cost.geometry, tp.voxels, co.estimate->rootRadiusMm, image)) {
      const std::function<bool(int64_t)> taken = [&](int64_t lin) { return m.treeIndex.count(lin) > 0; };
      // The own lumen read by the mask alone: on a flat plateau the image stop reads noise and bias as dips and cuts
      // the sections short (session 48 flatpeaks / session 49 flatshared).
      std::vector<Index3> centred = recentreInOwnLumen(m.cost, m.lumenLevel, tp.voxels, &taken);
      if (centred != tp.voxels) tp.voxels = std::move(centred), tp.cost = chainCost(m.cost, tp.voxels);
    }
  }
  return recordPath(std::move(tp));
}

void VesselTracker::retraceCrossings(TracedPath& tp) {
  Impl& m = *impl_;
  // The voxels before `from` are a replacement already decided (an earlier path's, taken as one trunk,
  // or this path's own): the checks look at the rest only, so a step into a touching tube further
  // along is searched again too (session 24: a path given a shared stretch skipped its own checks).
  size_t from = 0;
  for (const Reroute& r : m.reroutes)
    if (takeReroute(tp, r, m.cost)) from = std::max(from, r.kept.size() - 1);
  bool changed = false;
  constexpr int maxOwnRetraces = 4;  // re-searches one after another on one path, each beyond the last
  for (int round = 0; round < maxOwnRetraces && from + 1 < tp.voxels.size(); ++round) {
    const std::vector<Index3> found = tp.voxels;
    bool ownTube = false;
    const bool retraced =
        retraceFrom(m.cost, m.opt, m.lumenLevel, geom_, tp, from, m.loopedTurns, m.neckSections, ownTube);
    m.stats.loopedTurnsReused = m.loopedTurns.reused;
    if (!retraced) break;
    m.reroutes.push_back(rerouteOf(found, tp));
    m.reroutes.back().ownTube = ownTube;
    const size_t next = m.reroutes.back().kept.size() - 1;
    for (TracedPath& p : paths_)
      if (p.reached) changed = takeReroute(p, m.reroutes.back(), m.cost) || changed;
    if (next <= from) break;
    from = next;
  }
  changed = retraceFusedForks(tp) || changed;
  if (changed) rebuildTree();
}

// A path fused with another past their parting (fused_fork.h): the new path against every earlier one and each
// earlier one against it; a kept route is given to every path through the stretch. True when an earlier path changed.
bool VesselTracker::retraceFusedForks(TracedPath& tp) {
  Impl& m = *impl_;
  if (m.lumenLevel < 0)
    m.lumenLevel = std::isnan(m.opt.crossing.lumenLevel) ? lumenCostThreshold(m.cost) : m.opt.crossing.lumenLevel;
  bool changed = false;
  for (size_t q = 0; q < paths_.size(); ++q) {
    if (!paths_[q].reached) continue;
    for (int way = 0; way < 2; ++way) {
      TracedPath& p = way == 0 ? tp : paths_[q];
      const TracedPath& s = way == 0 ? paths_[q] : tp;
      FusedForkRetrace fr =
          retraceFusedFork(m.cost, p.voxels, s.voxels, m.opt.connectivity, m.lumenLevel, m.opt.crossing);
      if (!fr.changed) continue;
      const std::vector<Index3> found = p.voxels;
      p.voxels = std::move(fr.voxels);
      p.cost = chainCost(m.cost, p.voxels);
      p.retraced = true;
      changed = changed || &p != &tp;
      m.reroutes.push_back(rerouteOf(found, p));
      for (TracedPath& other : paths_)
        if (other.reached && &other != &p) changed = takeReroute(other, m.reroutes.back(), m.cost) || changed;
      if (&p != &tp) takeReroute(tp, m.reroutes.back(), m.cost);
    }
  }
  return changed;
}

void VesselTracker::joinTrunks(TracedPath& tp) {
  Impl& m = *impl_;
  if (m.lumenLevel < 0)
    m.lumenLevel = std::isnan(m.opt.crossing.lumenLevel) ? lumenCostThreshold(m.cost) : m.opt.crossing.lumenLevel;
  const double holeMm = m.opt.crossing.lumenHoleVoxels * geom_.spacing.minCoeff();
  std::unordered_set<int64_t> researched;  // the voxels re-searches put on a path (not on the search's route)
  for (const Reroute& r : m.reroutes) {
    std::unordered_set<int64_t> found;
    for (const Index3& v : r.found) found.insert(geom_.linear(v[0], v[1], v[2]));
    for (const Index3& v : r.kept)
      if (!found.count(geom_.linear(v[0], v[1], v[2]))) researched.insert(geom_.linear(v[0], v[1], v[2]));
  }
  std::vector<TracedPath*> all;
  for (TracedPath& p : paths_)
    if (p.reached) all.push_back(&p);
  all.push_back(&tp);
  // A stretch an earlier path changes may part from and meet a third path again: a few rounds.
  bool earlier = false;
  constexpr int maxRounds = 4;
  for (int round = 0; round < maxRounds; ++round) {
    bool any = false;
    for (size_t i = 0; i < all.size(); ++i)
      for (size_t j = i + 1; j < all.size(); ++j) {
        const int c = joinSharedLumen(all[i]->voxels, all[j]->voxels, m.cost, m.lumenLevel, holeMm, researched);
        if (c & 1) all[i]->cost = chainCost(m.cost, all[i]->voxels), earlier = earlier || all[i] != &tp;
        if (c & 2) all[j]->cost = chainCost(m.cost, all[j]->voxels), earlier = earlier || all[j] != &tp;
        any = any || c != 0;
      }
    if (!any) break;
  }
  // A later path that parts from an earlier one inside one lumen and runs on beside it shares its trunk up to
  // where the lumen parts (trunk_join.h) - its parent only: the earlier path it shares the longest start with.
  for (size_t j = 1; j < all.size(); ++j) {
    size_t parent = 0, longest = 0;
    for (size_t i = 0; i < j; ++i) {
      const std::vector<Index3>&a = all[i]->voxels, &b = all[j]->voxels;
      size_t n = 0;
      while (n < a.size() && n < b.size() && a[n] == b[n]) ++n;
      if (n > longest) longest = n, parent = i;
    }
    if (longest > 0 && joinPartedLumen(all[parent]->voxels, all[j]->voxels, m.cost, m.lumenLevel, holeMm)) {
      all[j]->cost = chainCost(m.cost, all[j]->voxels);
      earlier = earlier || all[j] != &tp;
    }
  }
  if (earlier) rebuildTree();
}

void VesselTracker::rebuildTree() {
  Impl& m = *impl_;
  std::vector<TracedPath> old = std::move(paths_);
  paths_.clear();
  pathTreePoints_.clear();
  m.treeIndex.clear();
  m.treeIndex[geom_.linear(root_[0], root_[1], root_[2])] = 0;
  m.treeVoxel.assign(1, root_);
  m.treeParent.assign(1, -1);
  m.treeChildren.assign(1, 0);
  m.treeOwner.assign(1, -1);
  for (TracedPath& p : old) {
    p.parentPath = -1;
    p.junctionIndex = 0;
    recordPath(std::move(p));
  }
}

const TracedPath& VesselTracker::recordPath(TracedPath tp) {
  Impl& m = *impl_;
  const int idx = static_cast<int>(paths_.size());
  if (!tp.reached) {
    pathTreePoints_.emplace_back();
    paths_.push_back(std::move(tp));
    return paths_.back();
  }
  tp.lengthMm = 0;
  for (size_t i = 1; i < tp.voxels.size(); ++i) {
    const Index3& a = tp.voxels[i - 1];
    const Index3& b = tp.voxels[i];
    tp.lengthMm += geom_.stepLength(
        Vec3(static_cast<double>(b[0] - a[0]), static_cast<double>(b[1] - a[1]), static_cast<double>(b[2] - a[2])));
  }
  // Merge into the tree of extracted paths.
  std::vector<int32_t> treePoints;
  treePoints.reserve(tp.voxels.size());
  int32_t prev = -1;
  bool diverged = false;
  for (size_t i = 0; i < tp.voxels.size(); ++i) {
    const int64_t lin = geom_.linear(tp.voxels[i][0], tp.voxels[i][1], tp.voxels[i][2]);
    auto it = m.treeIndex.find(lin);
    if (it != m.treeIndex.end() && !diverged) {
      prev = it->second;
      tp.junctionIndex = i;
      tp.parentPath = m.treeOwner[static_cast<size_t>(prev)];
      treePoints.push_back(prev);
      continue;
    }
    diverged = true;
    const int32_t id = static_cast<int32_t>(m.treeVoxel.size());
    if (it == m.treeIndex.end()) m.treeIndex[lin] = id;
    m.treeVoxel.push_back(tp.voxels[i]);
    m.treeParent.push_back(prev);
    m.treeChildren.push_back(0);
    m.treeOwner.push_back(idx);
    if (prev >= 0) ++m.treeChildren[static_cast<size_t>(prev)];
    prev = id;
    treePoints.push_back(id);
  }
  pathTreePoints_.push_back(std::move(treePoints));
  paths_.push_back(std::move(tp));
  return paths_.back();
}

void VesselTracker::runToCompletion(Progress& progress) {
  const auto t0 = Clock::now();
  impl_->search->runToCompletion(progress);
  impl_->stats.searchSeconds += since(t0);
}

std::vector<Index3> VesselTracker::branchPoints() const {
  std::vector<Index3> out;
  for (size_t i = 0; i < impl_->treeVoxel.size(); ++i)
    if (impl_->treeChildren[i] >= 2) out.push_back(impl_->treeVoxel[i]);
  return out;
}

double VesselTracker::totalCost(const Index3& v) const {
  if (!geom_.contains(v)) return std::numeric_limits<double>::infinity();
  const int64_t n = impl_->nodeOfVoxel(geom_.linear(v[0], v[1], v[2]));
  if (n < 0) return std::numeric_limits<double>::infinity();
  const double t = impl_->search->totalCost(n);
  return std::isfinite(t) && t >= 0 ? t : std::numeric_limits<double>::infinity();
}

TrackerStats VesselTracker::stats() const {
  TrackerStats s = impl_->stats;
  s.settled = impl_->search->settledCount();
  s.fullSearch = impl_->search->finished();
  return s;
}

double VesselTracker::radiusAt(const Index3& v, double maxMm) const {
  const VolumeF32& vol = impl_->vol;
  const Geometry& g = geom_;
  const double minSp = g.spacing.minCoeff();
  double centre = 0;
  int n = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (g.contains(v[0] + dx, v[1] + dy, v[2] + dz)) centre += vol(v[0] + dx, v[1] + dy, v[2] + dz), ++n;
  centre /= n;
  std::vector<double> far;
  std::vector<std::vector<double>> profiles;
  std::vector<double> stepMm;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const double mm = g.stepLength(Vec3(dx, dy, dz));
        const int steps = std::max(1, static_cast<int>(maxMm / mm));
        std::vector<double> prof{static_cast<double>(vol(v[0], v[1], v[2]))};
        for (int s = 1; s <= steps; ++s) {
          const int64_t x = v[0] + dx * s, y = v[1] + dy * s, z = v[2] + dz * s;
          if (!g.contains(x, y, z)) break;
          prof.push_back(vol(x, y, z));
        }
        far.push_back(prof.back());
        profiles.push_back(std::move(prof));
        stepMm.push_back(mm);
      }
  std::vector<double> sorted = far;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double bg = sorted[sorted.size() / 2];
  const double t = 0.5 * (centre + bg);
  const bool brighter = centre >= bg;
  std::vector<double> radii;
  for (size_t k = 0; k < profiles.size(); ++k) {
    const auto& p = profiles[k];
    double r = static_cast<double>(p.size() - 1) * stepMm[k];
    for (size_t s = 1; s < p.size(); ++s) {
      const bool out = brighter ? p[s] < t : p[s] > t;
      if (out) {
        const double a = p[s - 1] - t, b = p[s] - t;
        const double frac = (a - b) != 0 ? std::clamp(a / (a - b), 0.0, 1.0) : 0.5;
        r = (static_cast<double>(s - 1) + frac) * stepMm[k];
        break;
      }
    }
    radii.push_back(r);
  }
  std::sort(radii.begin(), radii.end());
  const double r = radii[static_cast<size_t>(0.3 * static_cast<double>(radii.size() - 1))];
  return std::max(0.5 * minSp, r);
}

Tree VesselTracker::toTree() const {
  Tree t;
  const Impl& m = *impl_;
  bool any = false;
  for (const auto& p : paths_) any = any || p.reached;
  if (!any) return t;
  for (size_t i = 0; i < m.treeVoxel.size(); ++i) {
    const Index3& v = m.treeVoxel[i];
    t.points.push_back(
        geom_.indexToWorld(Vec3(static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2]))));
    t.parent.push_back(m.treeParent[i]);
    t.radii.push_back(radiusAt(v));
    t.types.push_back(i == 0 ? 1 : 3);
  }
  return t;
}

CentrelineTree VesselTracker::centrelineTree() const {
  CentrelineTree t;
  const Impl& m = *impl_;
  for (size_t i = 0; i < m.treeVoxel.size(); ++i) {
    const Index3& v = m.treeVoxel[i];
    t.points.emplace_back(static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2]));
    t.parent.push_back(m.treeParent[i]);
  }
  return t;
}

const std::vector<int32_t>& VesselTracker::pathTreePoints(size_t path) const {
  VS_REQUIRE(path < pathTreePoints_.size(), "pathTreePoints: no path " + std::to_string(path));
  return pathTreePoints_[path];
}

Tree VesselTracker::toTree(const RefinedCentreline& refined) const {
  const Impl& m = *impl_;
  // Where forks were re-branched (splitForks) the refined tree has more points than this one.
  const size_t n = refined.points.size();
  const bool ownTree = refined.parent.size() == n && refined.source.size() == n;
  VS_REQUIRE(refined.radiiMm.size() == n && (n == m.treeVoxel.size() || (ownTree && n > m.treeVoxel.size())),
             "toTree: the refined centreline is not of this tracker's tree");
  Tree t;
  bool any = false;
  for (const auto& p : paths_) any = any || p.reached;
  if (!any) return t;
  for (size_t i = 0; i < n; ++i) {
    t.points.push_back(geom_.indexToWorld(refined.points[i]));
    t.parent.push_back(ownTree ? refined.parent[i] : m.treeParent[i]);
    t.radii.push_back(refined.radiiMm[i]);
    t.types.push_back(i == 0 ? 1 : 3);
  }
  return t;
}

size_t VesselTracker::confineToLumen(RefinedCentreline& refined, double maxNodeCost, double lumenNodeCost,
                                     double imageUpper, const std::vector<uint8_t>* readsLumen) const {
  const Impl& m = *impl_;
  const size_t n = refined.points.size();
  const bool copies = refined.source.size() == n && n > m.treeVoxel.size();
  VS_REQUIRE(n == m.treeVoxel.size() || copies, "confineToLumen: the refined centreline is not of this tracker's tree");
  // Node cost at a continuous voxel position (clamped to the volume): trilinear, the fraction
  // along an axis of spacing s narrowed to the finest spacing around the slabs' boundary (the
  // same on an isotropic grid).
  const double finest = geom_.spacing.minCoeff();
  auto costAt = [&](const Vec3& p) {
    int64_t i0[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      const double c = std::clamp(p[a], 0.0, static_cast<double>(geom_.dims[a] - 1));
      i0[a] = std::min<int64_t>(static_cast<int64_t>(c), std::max<int64_t>(0, geom_.dims[a] - 2));
      f[a] = geom_.dims[a] > 1 ? c - static_cast<double>(i0[a]) : 0.0;
      f[a] = std::clamp(0.5 + (f[a] - 0.5) * geom_.spacing[a] / finest, 0.0, 1.0);
    }
    double v = 0;
    for (int k = 0; k < 8; ++k) {
      const int dx = k & 1, dy = (k >> 1) & 1, dz = k >> 2;
      const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
      if (w == 0) continue;
      v += w * m.cost.node[static_cast<size_t>(geom_.linear(i0[0] + dx, i0[1] + dy, i0[2] + dz))];
    }
    return m.cost.nodeWeight * v;
  };
  // A kept wide point (centreline.h: wideTrunk 2) lies on its trunk's axis by its own rays; where the
  // cost there is above the limit (a faded trunk's far end, whose whole section lies above the lumen
  // level: 525, 535, 514), the pull back to its path voxel would take it to the wall. It moves instead
  // to the most lumen-like position within half the finest spacing (26 directions, two radii): a
  // wide air lumen's noise (the 4D-CT trachea's centre reads -800..-1024 HU voxel to voxel) is left
  // where the path's own voxels are, without leaving the axis by more than the localisation's grain.
  auto lumenMostNear = [&](const Vec3& p) {
    Vec3 best = p;
    double bestCost = costAt(p);
    for (const double r : {0.25 * finest, 0.5 * finest})
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0 && dz == 0) continue;
            const Vec3 o = (r * Vec3(dx, dy, dz).normalized()).cwiseQuotient(geom_.spacing);
            const double c = costAt(p + o);
            if (c < bestCost) bestCost = c, best = p + o;
          }
    return best;
  };
  const TrilinearSampler image(m.vol);
  const double sign = refined.polarity > 0 ? 1.0 : -1.0;
  const std::vector<int32_t> ownVoxel = ownPathVoxels(refined, m.treeVoxel.size());
  size_t moved = 0;
  for (size_t i = 1; i < n; ++i) {
    const Index3& v = m.treeVoxel[static_cast<size_t>(ownVoxel[i])];
    const Vec3 from(static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2]));
    // The pull goes towards the voxel because it is more lumen-like than the point; where the image itself reads
    // the point at least as lumen-like, the cost's shallow reading is the cost's (smoothing, contrast terms), not the
    // vessel's: the head CTA's pulled points ended 0.7 mm shallower (docs/notes/tracking.md, session 28 net11).
    // Beyond the upper edge the image is no longer lumen-like (a stent or bone: the chest CTA aorta's 615..827).
    const double atImage = sign * image.at(refined.points[i]);
    // The route picks a noisy lumen's darkest (brightest) voxels, so a point between voxels never reads as lumen-like
    // as its own voxel: where the lumen model reads the point as lumen at its place (`readsLumen`), the reference is
    // the voxel's value averaged with its six face neighbours (11407's kissing tube, docs/notes/tracking.md, session
    // 33 kiss37). Elsewhere the voxel's own value: the chest CT airway's points the centring put at -470..-895 HU,
    // brighter than their lung background, are kept in the air only by the pull (kiss19).
    double ref = sign * image.at(from);
    if (readsLumen && i < readsLumen->size() && (*readsLumen)[i]) {
      double sum = ref;
      int count = 1;
      for (int a = 0; a < 3; ++a)
        for (int d = -1; d <= 1; d += 2) {
          Vec3 nb = from;
          nb[a] += d;
          if (nb[a] < 0 || nb[a] > static_cast<double>(geom_.dims[a] - 1)) continue;
          sum += sign * image.at(nb), ++count;
        }
      ref = sum / count;
    }
    if (refined.polarity != 0 && atImage >= ref && !(atImage > sign * imageUpper)) continue;
    const double atVoxel = costAt(from);
    if (atVoxel > lumenNodeCost) continue;
    // A point pulled back goes to where the cost marks lumen half as deep as at its voxel (half-way between
    // the voxel's cost and the lumen level; from a deep voxel the half level). The voxel's own cost as the
    // limit (before session 27) took a point whose voxel lies just inside the level - a dim thin lumen's
    // route through its brightest partial-volume voxels, often at the wall - back onto that voxel itself
    // (10403 / 10503 / 10529's far points at their path voxels; docs/notes/tracking.md, thin20).
    const double limit = std::max(maxNodeCost, 0.5 * (atVoxel + lumenNodeCost));
    Vec3& p = refined.points[i];
    const uint8_t wide = i < refined.wideTrunk.size() ? refined.wideTrunk[i] : 0;
    const double atPoint = costAt(p);
    if (wide == 1 || atPoint <= limit) continue;
    if (wide == 2) {
      const Vec3 before = p;
      p = lumenMostNear(p);
      moved += p != before;
      continue;
    }
    // Within the lumen level the point is in the lumen (hysteresis: one pulled back goes to the limit).
    // Without this stay 104 of 745 moves on the family made a point better, 469 worse; the chest CT
    // airway's points the centring put at -470..-895 HU read 0.24-1.0 against its level 0.2
    // (docs/notes/tracking.md, session 25 kiss19).
    if (atPoint <= lumenNodeCost) continue;
    // A point the lumen model reads as lumen at its place whose voxel lies within half its section's radius of it,
    // where the image half-way back reads no more lumen-like than the point: the way back runs through the lumen's
    // core, at least half a radius from any wall, and the image rises to the voxel only at the voxel itself, so the
    // voxel's better reading is its own noise, not a wall the point crossed (15326: a dark 3.7-voxel trunk's axis
    // point pulled 1.4 voxels back to the route's darkest voxel near its wall). Where the image rises along the way
    // the pull follows it (the 4D-CT trachea's axis point at -898 HU, -939 half-way; docs/notes/tracking.md, session
    // 46 forkG).
    const bool pointReadsLumen = readsLumen && i < readsLumen->size() && (*readsLumen)[i];
    if (pointReadsLumen && i < refined.radiiMm.size() &&
        (p - from).cwiseProduct(geom_.spacing).norm() <= 0.5 * refined.radiiMm[i] &&
        sign * image.at(0.5 * (p + from)) <= atImage)
      continue;
    double inside = 0, outside = 1;  // fractions of the way from the voxel to the refined point
    for (int k = 0; k < 20; ++k) {
      const double t = 0.5 * (inside + outside);
      (costAt(from + t * (p - from)) <= limit ? inside : outside) = t;
    }
    p = from + inside * (p - from);
    ++moved;
  }
  return moved;
}

VolumeU16 VesselTracker::labelVolume() const {
  VolumeU16 lab(geom_, 0);
  for (size_t i = 0; i < paths_.size(); ++i)
    for (const auto& v : paths_[i].voxels) {
      uint16_t& l = lab(v[0], v[1], v[2]);
      if (l == 0) l = static_cast<uint16_t>(std::min<size_t>(i + 1, 65535));
    }
  return lab;
}

double lumenCostThreshold(const NodeCost3D& cost) { return 0.2 * cost.nodeWeight * percentileOf(cost.node, 90.0); }

LumenSnap snapToLumen(const NodeCost3D& cost, const Index3& v, double radiusMm, double maxNodeCost) {
  const Geometry& g = cost.geometry;
  VS_REQUIRE(g.contains(v), "snap: voxel " + str(v) + " is outside the volume " + g.describe());
  VS_REQUIRE(radiusMm >= 0, "snap radius must be >= 0 mm");
  LumenSnap best;
  best.voxel = v;
  best.distanceMm = std::numeric_limits<double>::infinity();
  // The box's extra layer over floor(radius / spacing) only holds voxels beyond the radius.
  forEachVoxelNear(g, v, radiusMm, [&](int64_t x, int64_t y, int64_t z, double d) {
    if (d > radiusMm || d >= best.distanceMm) return;
    if (cost.nodeWeight * cost.node[static_cast<size_t>(g.linear(x, y, z))] <= maxNodeCost) {
      best.voxel = {x, y, z};
      best.distanceMm = d;
      best.found = true;
    }
  });
  if (!best.found) best.distanceMm = 0;
  return best;
}

}  // namespace vs
