#include "tracking/trace_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "features/vesselness.h"

namespace vs {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string indexText(const Index3& v, const Index3& offset) {
  std::string s = "(";  // appended piece by piece: "(" + std::string trips GCC 12's -Wrestrict
  for (size_t a = 0; a < 3; ++a) {
    s += std::to_string(v[a] + offset[a]);
    s += a < 2 ? ',' : ')';
  }
  return s;
}

std::string targetName(size_t i) { return "target #" + std::to_string(i + 1); }

size_t linear(const Geometry& g, const Index3& v) { return static_cast<size_t>(g.linear(v[0], v[1], v[2])); }

// Given costs: +inf is impassable (scikit-image semantics), NaN an error; any other cost's
// volume: every voxel finite.
void checkVoxels(const VolumeF32& vol, const std::string& volumeName, bool given) {
  if (given) {
    for (float v : vol.voxels())
      if (std::isnan(v)) throw DataError(volumeName + ": NaN voxels cannot be costs (use +inf for impassable)");
  } else {
    int64_t nonFinite = 0;  // counted here: requireFinite takes an AnyVolume, i.e. a copy
    for (float v : vol.voxels()) nonFinite += std::isfinite(v) ? 0 : 1;
    if (nonFinite > 0) throw DataError(volumeName + ": " + std::to_string(nonFinite) + " voxel(s) are NaN or infinite");
  }
}

}  // namespace

bool costMarksLumen(const std::string& cost) { return cost == "auto" || cost == "intensity" || cost == "vesselness"; }

TraceResult runTrace(const VolumeF32& vol, const TraceRequest& rq, Progress& progress) {
  const TraceOptions& opt = rq.options;
  auto str = [&](const Index3& v) { return indexText(v, rq.messageOffset); };
  const Geometry& g = vol.geometry();
  const bool autoCost = opt.cost == "auto";
  const bool given = opt.cost == "given";
  checkVoxels(vol, rq.volumeName, given);
  if (!g.contains(rq.root)) throw InvalidArgument("root " + str(rq.root) + " is outside the volume " + g.describe());
  for (size_t i = 0; i < rq.targets.size(); ++i)
    if (!g.contains(rq.targets[i]))
      throw InvalidArgument(targetName(i) + " " + str(rq.targets[i]) + " is outside the volume " + g.describe());
  const bool mapOnly = rq.targets.empty() && rq.autoTerminals < 0;
  if (mapOnly && !rq.full) throw InvalidArgument("trace: give targets, automatic terminals or the full map");
  if (!std::isnan(rq.smoothMm) && !(rq.smoothMm >= 0))
    throw InvalidArgument("trace: the smoothing sigma must be >= 0 mm");

  TraceResult r;
  r.requestedRoot = rq.root;
  r.smoothMm =
      std::isnan(rq.smoothMm) ? (opt.cost == "intensity" ? opt.intensitySmoothMm : opt.autoCost.smoothMm) : rq.smoothMm;
  const bool refine = opt.refine && !mapOnly;

  // Costs; `lumen` holds the (smoothed) intensities the centreline refinement centres in.
  const auto tFeat = Clock::now();
  NodeCost3D cost;
  VolumeF32 lumen;
  LocalBackground background;  // cost "auto": names the local contrast of a refused point
  if (autoCost) {
    AutoCostOptions ao = opt.autoCost;
    ao.smoothMm = r.smoothMm;
    AutoCost ac = computeAutoCost(vol, rq.root, ao, progress);
    cost = std::move(ac.cost);
    lumen = std::move(ac.smoothed);
    background = std::move(ac.background);
    r.estimate = ac.estimate;
  } else {
    Cost3DOptions co = rq.cost;
    co.kind = costKindFromName(opt.cost);
    co.smoothMm = co.kind == CostKind3D::Intensity ? r.smoothMm : 0.0;
    cost = computeNodeCost3D(vol, co, nullptr, progress);
    if (refine) lumen = refinementIntensity(vol, r.smoothMm, given, progress);
  }
  r.featureSeconds = since(tFeat);
  r.costDescription = cost.description;

  // Snap the root and the targets into the lumen (costs that mark a lumen: not gradient, not given).
  const bool marksLumen = costMarksLumen(opt.cost);
  const bool snaps = opt.snapMm > 0 && marksLumen;
  const double lumenCost = marksLumen ? lumenCostThreshold(cost) : 0;
  auto snap = [&](const Index3& v, const std::string& what) {
    const float c = cost.nodeWeight * cost.node[linear(g, v)];
    if (!snaps || c <= lumenCost) return v;
    const LumenSnap s = snapToLumen(cost, v, opt.snapMm, lumenCost);
    if (!s.found) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    " has cost %.3g above the lumen's %.3g and no lumen voxel lies within the snap radius %g mm",
                    static_cast<double>(c), lumenCost, opt.snapMm);
      std::string contrast;
      if (autoCost && r.estimate)
        contrast = "; " + localContrastAt(lumen, background, *r.estimate, v).describe(*r.estimate);
      throw DataError(what + " " + str(v) + buf + contrast +
                      " (move it into the vessel/airway or raise the snap radius)");
    }
    r.notes.push_back(what + " " + str(v) + " is outside the lumen: snapped to " + str(s.voxel));
    return s.voxel;
  };
  const Index3 usedRoot = snap(rq.root, "root");
  if (!std::isfinite(cost.node[linear(g, usedRoot)]))
    throw DataError("root " + str(usedRoot) + " lies in an impassable voxel (cost inf)");
  std::vector<Index3> usedTargets;
  for (size_t i = 0; i < rq.targets.size(); ++i) {
    usedTargets.push_back(snap(rq.targets[i], targetName(i)));
    if (usedTargets.back() == usedRoot)
      throw DataError(targetName(i) + " " + str(rq.targets[i]) + " snapped onto the root " + str(usedRoot) +
                      "; move it or lower the snap radius");
  }

  const std::clock_t cpuSearch = std::clock();
  VesselTracker tr(vol, cost, usedRoot, opt.tracker, progress);
  r.root = tr.root();
  if (tr.root() != usedRoot)
    r.notes.push_back("root " + str(usedRoot) + " was pruned; snapped to the nearest graph node " + str(tr.root()));
  // The complete map first: on a fresh search it runs on two threads; targets are then O(path).
  if (rq.full) tr.runToCompletion(progress);
  for (size_t i = 0; i < usedTargets.size(); ++i) {
    const TracedPath& p = tr.addTarget(usedTargets[i], progress);
    if (!p.reached)
      throw UnreachableTarget(targetName(i) + " " + str(rq.targets[i]) + " is not reachable from the root " +
                              str(usedRoot) + " (separate component: impassable costs or outside the region)");
    if (p.target != usedTargets[i])
      r.notes.push_back(targetName(i) + " " + str(usedTargets[i]) + " was pruned; snapped to " + str(p.target));
  }
  if (rq.autoTerminals >= 0) {
    AutoTerminalOptions ao = opt.autoTerminals;
    ao.count = rq.autoTerminals;
    const auto added = tr.autoTerminals(ao, progress);
    if (added.empty()) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%g", ao.minLengthMm);
      throw DataError(std::string("no terminal found: no branch of the traced structure adds the minimum length ") +
                      buf + " mm beyond the paths so far (check the root, lower the minimum length, or choose a cost)");
    }
    r.notes.push_back("automatic terminals: " + std::to_string(added.size()) + " found" +
                      (ao.count > 0 && static_cast<int>(added.size()) < ao.count
                           ? " of " + std::to_string(ao.count) + " asked for: " + tr.lastTerminalStop()
                           : std::string()));
  }
  r.stats = tr.stats();
  r.searchCpuSeconds = static_cast<double>(std::clock() - cpuSearch) / CLOCKS_PER_SEC;

  // Sub-voxel centrelines and radii.
  RefinedCentreline refined;
  if (refine) {
    const auto tRef = Clock::now();
    const std::clock_t cpuRefine = std::clock();
    refined = refineCentreline(lumen, tr.centrelineTree(), opt.centreline, progress);
    // Refined points stay in the lumen, at least as deep as half its cost level (the voxel paths
    // themselves may graze the wall: on the chest CT the lumen level allowed -897 HU points).
    if (marksLumen) tr.confineToLumen(refined, 0.5 * lumenCost);
    r.refineSeconds = since(tRef);
    r.refineCpuSeconds = static_cast<double>(std::clock() - cpuRefine) / CLOCKS_PER_SEC;
  }
  r.refined = refine;
  r.paths = tr.paths();
  for (size_t i = 0; i < r.paths.size(); ++i) {
    if (i < rq.targets.size()) r.paths[i].requested = rq.targets[i];
    std::vector<Vec3> pts;
    std::vector<double> radii;
    if (refine) {
      for (int32_t k : tr.pathTreePoints(i)) {
        pts.push_back(refined.points[static_cast<size_t>(k)]);
        radii.push_back(refined.radiiMm[static_cast<size_t>(k)]);
      }
    } else {
      for (const auto& v : r.paths[i].voxels) radii.push_back(tr.radiusAt(v));
    }
    r.points.push_back(std::move(pts));
    r.radiiMm.push_back(std::move(radii));
  }
  r.branchPoints = tr.branchPoints();
  if (!mapOnly) r.tree = refine ? tr.toTree(refined) : tr.toTree();
  if (rq.labels) r.labels = tr.labelVolume();
  return r;
}

}  // namespace vs
