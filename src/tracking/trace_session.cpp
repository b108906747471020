#include "tracking/trace_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tracking/dim_points.h"
#include "util/text.h"
#include "volume/neighbourhood.h"
#include "volume/sample.h"

namespace vs {

namespace {

size_t linear(const Geometry& g, const Index3& v) { return static_cast<size_t>(g.linear(v[0], v[1], v[2])); }

template <typename... A>
std::string fmt(const char* f, A... a) {
  char buf[320];
  std::snprintf(buf, sizeof buf, f, a...);
  return buf;
}

std::string targetName(size_t i) { return "target #" + std::to_string(i + 1); }

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

// A point's contrast against its own surroundings (session 14): the most lumen-like smoothed
// value within `snapMm` of it (and where; 0: the point's own) against the median of the shell from innerMm to outerMm
// around that voxel, towards the lumen (bright: value - shell).
struct OwnContrast {
  Index3 voxel{0, 0, 0};
  double value = 0, shell = 0, contrast = 0;
};
OwnContrast ownContrast(const VolumeF32& lumen, const Index3& v, bool bright, double snapMm, double innerMm,
                        double outerMm) {
  const Geometry& g = lumen.geometry();
  OwnContrast c;
  c.voxel = v;
  c.value = lumen(v[0], v[1], v[2]);
  forEachVoxelNear(g, v, snapMm, [&](int64_t x, int64_t y, int64_t z, double d) {
    if (d > snapMm) return;
    const double val = lumen(x, y, z);
    if (bright ? val > c.value : val < c.value) c.value = val, c.voxel = {x, y, z};
  });
  std::vector<float> shell;
  forEachVoxelNear(g, c.voxel, outerMm, [&](int64_t x, int64_t y, int64_t z, double d) {
    if (d >= innerMm && d <= outerMm) shell.push_back(lumen(x, y, z));
  });
  if (shell.empty()) return c;
  std::nth_element(shell.begin(), shell.begin() + static_cast<std::ptrdiff_t>(shell.size() / 2), shell.end());
  c.shell = shell[shell.size() / 2];
  c.contrast = bright ? c.value - c.shell : c.shell - c.value;
  return c;
}

}  // namespace

TraceSession::TraceSession(const VolumeF32& volume, const TraceRequest& config) : volume_(volume), config_(config) {
  const TraceOptions& opt = config_.options;
  checkVoxels(volume_, config_.volumeName, opt.cost == "given");
  if (!std::isnan(config_.smoothMm) && !(config_.smoothMm >= 0))
    throw InvalidArgument("trace: the smoothing sigma must be >= 0 mm");
  smoothMm_ = std::isnan(config_.smoothMm) ? (opt.cost == "intensity" ? opt.intensitySmoothMm : opt.autoCost.smoothMm)
                                           : config_.smoothMm;
}

TraceSession::~TraceSession() = default;

std::string TraceSession::text(const Index3& v) const {
  const Index3& o = config_.messageOffset;
  return indexText(Index3{v[0] + o[0], v[1] + o[1], v[2] + o[2]});
}

const NodeCost3D& TraceSession::cost() const {
  VS_REQUIRE(cost_, "trace: no cost computed yet");
  return *cost_;
}

void TraceSession::prepare(const Index3& root, bool refine, Progress& progress) {
  const TraceOptions& opt = config_.options;
  if (!volume_.geometry().contains(root))
    throw InvalidArgument("root " + text(root) + " is outside the volume " + volume_.geometry().describe());
  const bool autoCost = opt.cost == "auto";
  PhaseTimer timer;
  const bool costNow = !cost_ || (autoCost && costRoot_ != root);
  if (costNow) {
    featurePhases_.clear();
    tracker_.reset();
    refineReady_ = false;
    if (autoCost) {
      AutoCostOptions ao = opt.autoCost;
      ao.smoothMm = smoothMm_;
      AutoCost ac = computeAutoCost(volume_, root, ao, progress);
      cost_ = std::make_unique<NodeCost3D>(std::move(ac.cost));
      lumen_ = std::move(ac.smoothed);
      background_ = std::move(ac.background);
      estimate_ = ac.estimate;
      featurePhases_ = std::move(ac.phases);
      refineReady_ = true;
    } else {
      Cost3DOptions co = config_.cost;
      co.kind = costKindFromName(opt.cost);
      co.smoothMm = co.kind == CostKind3D::Intensity ? smoothMm_ : 0.0;
      cost_ = std::make_unique<NodeCost3D>(computeNodeCost3D(volume_, co, nullptr, progress));
      timer.lap("cost", featurePhases_);
    }
    costRoot_ = root;
    lumenCost_.reset();
  }
  if (refine && !refineReady_) {
    if (!costNow) featurePhases_.clear();  // the cost was there already
    lumen_ = refinementIntensity(volume_, smoothMm_, opt.cost == "given", progress);
    refineReady_ = true;
    timer.lap("refine intensities", featurePhases_);
  }
}

double TraceSession::lumenCost() const {
  if (!lumenCost_) lumenCost_ = lumenCostThreshold(cost());
  return *lumenCost_;
}

// A target inside a lumen wider than its own surroundings' shell (a wide trunk's far end: both the local background
// and the shell lie in that lumen, session 19 wide10/wide11) measured like the root's contrast test: along rays to the
// tissue beyond the lumen's own wall (rootContrastBeyondWall, the target's smoothed value as its lumen). Taken where
// that contrast is `sigmas` noise spreads or more and the value is lumen-like by the root's own measure: on the
// lumen's side of the half-way between the root's lumen and the surroundings beyond the root's wall.
TraceSession::BeyondWall TraceSession::beyondOwnWall(const Index3& v, double noise, double sigmas) const {
  BeyondWall out;
  const WallContrastOptions& wo = config_.options.autoCost.wallContrast;
  if (!estimate_ || wo.rays <= 0 || !(noise > 0)) return out;
  const LumenEstimate& e = *estimate_;
  const double dir = e.polarity == TubePolarity::Dark ? 1.0 : -1.0;  // from the lumen towards the surroundings
  const double value = lumen_(v[0], v[1], v[2]);
  const WallContrast w = rootContrastBeyondWall(lumen_, v, value, dir, 3 * noise, wo);
  const double fromRoot = dir * (value - e.lumen), half = 0.5 * e.wall.contrast;
  const bool contrast = w.contrast >= sigmas * noise, lumenLike = fromRoot < half;
  out.taken = contrast && lumenLike;
  out.text =
      fmt("; beyond its own wall (median of %d rays, %d leave its value %.6g within %.3g mm) contrast %.3g = "
          "%.2g noise spreads",
          w.rays, w.leaving, value, wo.reachMm, w.contrast, w.contrast / noise) +
      (contrast ? std::string() : fmt(" (%.3g needed)", sigmas)) +
      fmt(", %.3g from the root's lumen %.6g towards its surroundings %.6g", fromRoot, e.lumen, e.wall.surround) +
      (lumenLike ? std::string() : fmt(" (under %.3g needed: not the root's lumen)", half));
  return out;
}

Index3 TraceSession::snap(const Index3& v, const std::string& what, std::vector<std::string>* notes) const {
  const TraceOptions& opt = config_.options;
  const NodeCost3D& cost = this->cost();
  const bool marksLumen = costMarksLumen(opt.cost);
  const bool snaps = opt.snapMm > 0 && marksLumen;
  const double lumenLevel = marksLumen ? lumenCost() : 0;
  const float c = cost.nodeWeight * cost.node[linear(volume_.geometry(), v)];
  if (!snaps || c <= lumenLevel) return v;
  const LumenSnap s = snapToLumen(cost, v, opt.snapMm, lumenLevel);
  // A target the lumen model leaves above its level but that stands out from its own surroundings
  // by ownContrastSigmas noise spreads (the root's or the local background's, the larger) is a
  // vessel the model misses (a thin, dim branch end): it goes to its most lumen-like voxel nearby.
  std::string own;
  if (!s.found && opt.cost == "auto" && estimate_ && what != "root") {
    constexpr double ownContrastSigmas = 5, innerVoxels = 3, shellVoxels = 2;
    const double sp = volume_.geometry().spacing.minCoeff();
    const double noise = std::max(estimate_->spread, localContrastAt(lumen_, background_, *estimate_, v, false).spread);
    // The target itself first (a neighbouring vessel within the snap radius may be brighter).
    const bool bright = estimate_->polarity == TubePolarity::Bright;
    OwnContrast oc = ownContrast(lumen_, v, bright, 0, innerVoxels * sp, (innerVoxels + shellVoxels) * sp);
    if (!(oc.contrast >= ownContrastSigmas * noise))
      oc = ownContrast(lumen_, v, bright, opt.snapMm, innerVoxels * sp, (innerVoxels + shellVoxels) * sp);
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "; against its own surroundings (%g-%g mm) contrast %.3g = %.2g noise spreads of %.3g",
                  innerVoxels * sp, (innerVoxels + shellVoxels) * sp, oc.contrast, oc.contrast / noise, noise);
    if (noise > 0 && oc.contrast >= ownContrastSigmas * noise) {
      if (notes)
        notes->push_back(what + " " + text(v) + " is above the lumen level but a vessel by its own contrast" + buf +
                         ": taken at " + text(oc.voxel));
      return oc.voxel;
    }
    own = std::string(buf) + " (" + numberText(ownContrastSigmas) + " needed)";
    const BeyondWall bw = beyondOwnWall(v, noise, ownContrastSigmas);
    if (bw.taken) {
      if (notes)
        notes->push_back(what + " " + text(v) + " is above the lumen level but a vessel by its contrast" + bw.text +
                         ": taken");
      return v;
    }
    own += bw.text;
  }
  if (!s.found) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  " has cost %.3g above the lumen's %.3g and no lumen voxel lies within the snap radius %g mm",
                  static_cast<double>(c), lumenLevel, opt.snapMm);
    std::string contrast;
    if (opt.cost == "auto" && estimate_)
      contrast = "; " + localContrastAt(lumen_, background_, *estimate_, v).describe(*estimate_) + own;
    throw DataError(what + " " + text(v) + buf + contrast +
                    " (move it into the vessel/airway or raise the snap radius)");
  }
  if (notes) notes->push_back(what + " " + text(v) + " is outside the lumen: snapped to " + text(s.voxel));
  return s.voxel;
}

std::vector<Index3> TraceSession::snapPoints(const Index3& root, const std::vector<Index3>& targets,
                                             std::vector<std::string>* notes) const {
  const Geometry& g = volume_.geometry();
  for (size_t i = 0; i < targets.size(); ++i)
    if (!g.contains(targets[i]))
      throw InvalidArgument(targetName(i) + " " + text(targets[i]) + " is outside the volume " + g.describe());
  std::vector<Index3> used{snap(root, "root", notes)};
  if (!std::isfinite(cost().node[linear(g, used[0])]))
    throw DataError("root " + text(used[0]) + " lies in an impassable voxel (cost inf)");
  for (size_t i = 0; i < targets.size(); ++i) {
    used.push_back(snap(targets[i], targetName(i), notes));
    if (used.back() == used[0])
      throw DataError(targetName(i) + " " + text(targets[i]) + " snapped onto the root " + text(used[0]) +
                      "; move it or lower the snap radius");
  }
  return used;
}

VesselTracker& TraceSession::search(const Index3& usedRoot, Progress& progress) {
  if (!tracker_ || tracker_->requestedRoot() != usedRoot) {
    // The crossing re-trace needs a lumen: costs that mark one, at the snap's lumen level.
    TrackerOptions to = config_.options.tracker;
    if (!costMarksLumen(config_.options.cost)) to.crossing.enabled = false;
    if (to.crossing.enabled) to.crossing.lumenLevel = lumenCost();
    // The kissing-drift test reads the auto cost's smoothed intensities (none with other costs).
    if (to.crossing.enabled && !lumen_.empty() && estimate_ && lumen_.geometry().dims == volume_.geometry().dims) {
      to.crossing.smoothed = &lumen_;
      to.crossing.brightLumen = estimate_->polarity == TubePolarity::Bright;
      // The support re-search reads the auto cost's model (path_support.h), as the trace's notes do.
      if (config_.options.cost == "auto") {
        to.crossing.autoCost = &config_.options.autoCost;
        to.crossing.background = &background_;
        to.crossing.estimate = &*estimate_;
      }
    }
    tracker_ = std::make_unique<VesselTracker>(volume_, cost(), usedRoot, to, progress);
  }
  return *tracker_;
}

std::string TraceSession::addAutoTerminals(int count, Progress& progress) {
  VS_REQUIRE(tracker_, "trace: automatic terminals need a search (give the root first)");
  AutoTerminalOptions ao = config_.options.autoTerminals;
  ao.count = count;
  if (std::isnan(ao.maxNodeCost)) ao.maxNodeCost = lumenCost();
  const auto added = tracker_->autoTerminals(ao, progress);
  if (added.empty())
    throw DataError("no terminal found: no branch of the traced structure adds the minimum length " +
                    numberText(ao.minLengthMm) +
                    " mm beyond the paths so far (check the root, lower the minimum length, or choose a cost)");
  return "automatic terminals: " + std::to_string(added.size()) + " found" +
         (ao.count > 0 && static_cast<int>(added.size()) < ao.count
              ? " of " + std::to_string(ao.count) + " asked for: " + tracker_->lastTerminalStop()
              : std::string()) +
         " (" + tracker_->lastTerminalScan() + ")";
}

RefinedCentreline TraceSession::refine(Progress& progress) const {
  VS_REQUIRE(tracker_ && refineReady_, "trace: refine needs a search and prepare(..., refine = true)");
  RefinedCentreline refined =
      refineCentreline(lumen_, tracker_->centrelineTree(), config_.options.centreline, progress);
  // Refined points stay in the lumen, at least as deep as half its cost level (the voxel paths
  // themselves may graze the wall: on the chest CT the lumen level allowed -897 HU points); where
  // the path leaves what the cost marks as lumen there is none to keep them in.
  // The image's upper edge (the lumen model's, where it has one): a point beyond it is pulled back whatever it reads.
  const double upper = estimate_ && estimate_->hasUpperEdge() ? estimate_->upperLo : std::nan("");
  // Per point: whether the lumen model reads it as lumen at its place (the smoothed intensity there at least the local
  // contrast's lower end t0 beyond the local background): confineToLumen's image test then takes the path voxel's
  // value averaged with its face neighbours as the reference (VesselTracker::confineToLumen).
  std::vector<uint8_t> readsLumen;
  if (estimate_ && !background_.scales.empty() && lumen_.geometry().dims == volume_.geometry().dims) {
    const Geometry& g = lumen_.geometry();
    const bool bright = estimate_->polarity == TubePolarity::Bright;
    const TrilinearSampler smoothed(lumen_);
    for (const Vec3& p : refined.points) {
      Index3 v;
      for (int a = 0; a < 3; ++a) v[a] = std::clamp<int64_t>(static_cast<int64_t>(std::lround(p[a])), 0, g.dims[a] - 1);
      const LocalContrast c = localContrastAt(lumen_, background_, *estimate_, v, false);
      const double at = smoothed.at(p);
      const double contrast = bright ? at - c.background : c.background - at;
      readsLumen.push_back(contrast >= c.lo);
    }
  }
  if (costMarksLumen(config_.options.cost))
    tracker_->confineToLumen(refined, 0.5 * lumenCost(), lumenCost(), upper,
                             readsLumen.empty() ? nullptr : &readsLumen);
  // After the confinement, which pulls points back towards their path voxels: a point on a grazed voxel of a thin
  // vessel reads outside it by the half-maximum (the head 3DRA's 12 of 1851, docs/notes/tracking.md, session 27).
  ridgeDimPoints(volume_, refined, refined.polarity);
  return refined;
}

TraceSession::Outcome TraceSession::resume(const Index3& root, const std::vector<Index3>& targets, int autoTerminals,
                                           Progress& progress,
                                           const std::function<void(const std::vector<TracedPath>&)>& onPaths) {
  const bool refine = config_.options.refine;
  prepare(root, refine, progress);
  Outcome out;
  out.used = snapPoints(root, targets, nullptr);
  // The search is resumed for new targets of the same root, but its path list only grows: a
  // removed or changed target, or automatic terminals, need a fresh search.
  bool fresh = !tracker_ || tracker_->requestedRoot() != out.used[0] || autoTerminals >= 0;
  if (!fresh) {
    const auto& old = tracker_->paths();
    fresh = old.size() > targets.size();
    for (size_t i = 0; !fresh && i < old.size(); ++i) fresh = old[i].requested != out.used[i + 1];
  }
  if (fresh) tracker_.reset();
  try {
    VesselTracker& tr = search(out.used[0], progress);
    if (onPaths) onPaths(tr.paths());
    for (size_t i = tr.paths().size(); i < targets.size(); ++i) {
      progress.report(double(i + 1) / double(targets.size() + 1), "search");
      const TracedPath& p = tr.addTarget(out.used[i + 1], progress);
      if (!p.reached)
        throw UnreachableTarget(targetName(i) + " " + text(targets[i]) + " is not reachable from the root " +
                                text(out.used[0]) + " (separate component: impassable costs or outside the region)");
      if (onPaths) onPaths(tr.paths());
    }
    if (autoTerminals >= 0) {
      addAutoTerminals(autoTerminals, progress);
      if (onPaths) onPaths(tr.paths());
    }
    progress.report(0.95, "refine");
    out.tree = refine ? tr.toTree(this->refine(progress)) : tr.toTree();
    out.labels = tr.labelVolume();
    out.paths = tr.paths();
  } catch (...) {
    tracker_.reset();  // a search stopped half-way is not resumed
    throw;
  }
  return out;
}

}  // namespace vs
