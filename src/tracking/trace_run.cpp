#include "tracking/trace_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "features/vesselness.h"
#include "tracking/path_support.h"
#include "tracking/trace_session.h"

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

}  // namespace

bool costMarksLumen(const std::string& cost) { return cost == "auto" || cost == "intensity" || cost == "vesselness"; }

TraceResult runTrace(const VolumeF32& vol, const TraceRequest& rq, Progress& progress) {
  const TraceOptions& opt = rq.options;
  auto str = [&](const Index3& v) { return indexText(v, rq.messageOffset); };
  const Geometry& g = vol.geometry();
  TraceSession session(vol, rq);  // checks the voxels and the smoothing sigma (trace_session.h)
  if (!g.contains(rq.root)) throw InvalidArgument("root " + str(rq.root) + " is outside the volume " + g.describe());
  for (size_t i = 0; i < rq.targets.size(); ++i)
    if (!g.contains(rq.targets[i]))
      throw InvalidArgument("target #" + std::to_string(i + 1) + " " + str(rq.targets[i]) + " is outside the volume " +
                            g.describe());
  const bool mapOnly = rq.targets.empty() && rq.autoTerminals < 0;
  if (mapOnly && !rq.full) throw InvalidArgument("trace: give targets, automatic terminals or the full map");

  TraceResult r;
  r.requestedRoot = rq.root;
  r.smoothMm = session.smoothMm();
  const bool refine = opt.refine && !mapOnly;

  // Costs (and the intensities the centreline refinement centres in), then the root and the
  // targets snapped into the lumen (costs that mark a lumen: not gradient, not given).
  const auto tFeat = Clock::now();
  session.prepare(rq.root, refine, progress);
  r.estimate = session.estimate();
  r.featureSeconds = since(tFeat);
  r.phases = session.featurePhases();
  PhaseTimer timer;
  r.costDescription = session.cost().description;
  const std::vector<Index3> used = session.snapPoints(rq.root, rq.targets, &r.notes);
  const Index3& usedRoot = used[0];

  const std::clock_t cpuSearch = std::clock();
  VesselTracker& tr = session.search(usedRoot, progress);
  r.root = tr.root();
  if (tr.root() != usedRoot)
    r.notes.push_back("root " + str(usedRoot) + " was pruned; snapped to the nearest graph node " + str(tr.root()));
  // The complete map first: on a fresh search it runs on two threads; targets are then O(path).
  if (rq.full) tr.runToCompletion(progress);
  for (size_t i = 0; i < rq.targets.size(); ++i) {
    const std::string name = "target #" + std::to_string(i + 1);
    const TracedPath& p = tr.addTarget(used[i + 1], progress);
    if (!p.reached)
      throw UnreachableTarget(name + " " + str(rq.targets[i]) + " is not reachable from the root " + str(usedRoot) +
                              " (separate component: impassable costs or outside the region)");
    if (p.target != used[i + 1])
      r.notes.push_back(name + " " + str(used[i + 1]) + " was pruned; snapped to " + str(p.target));
  }
  // After every target: a later target's re-search may be given to an earlier path through the same stretch.
  for (size_t i = 0; i < rq.targets.size(); ++i) {
    const std::string name = "target #" + std::to_string(i + 1);
    const TracedPath& p = tr.paths()[i];
    if (p.retraced && p.neckCrossings > 0)
      r.notes.push_back(name + ": its path drifted across the contact into a touching tube (" +
                        std::to_string(p.neckCrossings) +
                        " place(s)); searched again from before it with the neck between the tubes blocked");
    else if (p.retraced)
      r.notes.push_back(name + ": its path stepped sideways into a touching tube (" + std::to_string(p.sidewaysSteps) +
                        " place(s)); searched again with the tube it left blocked there");
  }
  timer.lap("search", r.phases);
  if (rq.autoTerminals >= 0) {
    r.notes.push_back(session.addAutoTerminals(rq.autoTerminals, progress));
    timer.lap("terminals", r.phases);
  }
  r.stats = tr.stats();
  r.searchCpuSeconds = static_cast<double>(std::clock() - cpuSearch) / CLOCKS_PER_SEC;

  // Sub-voxel centrelines and radii (confined to the lumen).
  RefinedCentreline refined;
  if (refine) {
    const auto tRef = Clock::now();
    const std::clock_t cpuRefine = std::clock();
    refined = session.refine(progress);
    r.refineSeconds = since(tRef);
    r.refineCpuSeconds = static_cast<double>(std::clock() - cpuRefine) / CLOCKS_PER_SEC;
    r.phases.push_back({"refine", r.refineSeconds, r.refineCpuSeconds});
  }
  r.refined = refine;
  r.paths = tr.paths();
  for (size_t i = 0; i < r.paths.size(); ++i) {
    if (i < rq.targets.size()) r.paths[i].requested = rq.targets[i];
    std::vector<Vec3> pts;
    std::vector<double> radii;
    if (refine) {
      for (int32_t k : refinedChain(refined, tr.pathTreePoints(i))) {
        pts.push_back(refined.points[static_cast<size_t>(k)]);
        radii.push_back(refined.radiiMm[static_cast<size_t>(k)]);
      }
    } else {
      for (const auto& v : r.paths[i].voxels) radii.push_back(tr.radiusAt(v));
    }
    r.points.push_back(std::move(pts));
    r.radiiMm.push_back(std::move(radii));
  }
  // Stretches of a path with neither lumen in the model nor contrast in the image: said, never silent.
  if (opt.cost == "auto" && r.estimate) {
    for (std::string& n : pathSupportNotes(r.paths, rq.targets.size(), session.cost(), opt.autoCost, session.smoothed(),
                                           session.background(), *r.estimate, rq.messageOffset))
      r.notes.push_back(std::move(n));
  }
  r.branchPoints = tr.branchPoints();
  if (!mapOnly) r.tree = refine ? tr.toTree(refined) : tr.toTree();
  if (rq.labels) r.labels = tr.labelVolume();
  return r;
}

}  // namespace vs
