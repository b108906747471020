// A trace kept between calls: the one home of the `trace` pipeline's steps (node cost and its
// auto estimate at the root, roots and targets snapped into the lumen with the messages of a
// refusal, one search from the root resumed for every target, automatic terminals, sub-voxel
// centrelines confined to the lumen). `runTrace` (trace_run.h: the CLI, Python) runs them once;
// the viewer's trace tool keeps a session and resumes it as the user adds targets.
// Coordinates are 0-based voxel indices (x,y,z) of the session's volume; messages add the
// request's messageOffset (a crop's corner).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tracking/trace_run.h"

namespace vs {

class TraceSession {
 public:
  // Takes options, cost, smoothMm, volumeName and messageOffset of `config` (not its points).
  // The volume must outlive the session. DataError for NaN voxels (and, but for cost "given",
  // infinite ones), InvalidArgument for a negative smoothing sigma.
  TraceSession(const VolumeF32& volume, const TraceRequest& config);
  ~TraceSession();
  TraceSession(const TraceSession&) = delete;
  TraceSession& operator=(const TraceSession&) = delete;

  const TraceOptions& options() const { return config_.options; }
  // The smoothing sigma of the cost and the refinement (the request's, else the options').
  double smoothMm() const { return smoothMm_; }
  // "(x,y,z)" with the message offset added.
  std::string text(const Index3& v) const;

  // The node cost for this root (cost "auto" is estimated at it; the other kinds do not depend on
  // it) and, with refine, the intensities the refinement centres in. Computed again only when
  // the auto cost's root moves (the search then restarts).
  void prepare(const Index3& root, bool refine, Progress& progress = Progress::none());
  const NodeCost3D& cost() const;
  const std::optional<LumenEstimate>& estimate() const { return estimate_; }
  // The phases of the last prepare() that computed something (the auto cost's, trace_run.h), else empty.
  const std::vector<PhaseTime>& featurePhases() const { return featurePhases_; }
  // The auto cost's smoothed intensities and local background (after prepare() with cost "auto"; the path support's
  // notes read them, path_support.h).
  const VolumeF32& smoothed() const { return lumen_; }
  const LocalBackground& background() const { return background_; }

  // A point moved into the lumen (costs that mark one and a snap radius > 0), else unchanged.
  // DataError naming `what` (e.g. "root", "target #2") when no lumen voxel lies within the snap
  // radius; a note in `notes` (when given) when the point moved.
  Index3 snap(const Index3& v, const std::string& what, std::vector<std::string>* notes) const;
  // Root and targets snapped (in that order); DataError for an impassable root or a target that
  // snaps onto the root.
  std::vector<Index3> snapPoints(const Index3& root, const std::vector<Index3>& targets,
                                 std::vector<std::string>* notes) const;

  // The search from usedRoot: the current one when it has this root, else a new one.
  VesselTracker& search(const Index3& usedRoot, Progress& progress = Progress::none());
  VesselTracker* tracker() { return tracker_.get(); }
  void restart() { tracker_.reset(); }  // the next search() starts afresh

  // Up to `count` automatic terminals (0: as many as the minimum length allows) added to the
  // search; DataError when none is found. Returns the note saying how many were found.
  std::string addAutoTerminals(int count, Progress& progress = Progress::none());
  // Sub-voxel centrelines and radii of the paths so far, confined to the lumen for costs that
  // mark one. Needs prepare(..., refine = true).
  RefinedCentreline refine(Progress& progress = Progress::none()) const;

  // The resumable run of an interactive front end: root and targets (as given), automatic
  // terminals (< 0: none). The search is resumed when the root and the earlier targets are
  // unchanged and no terminals are asked for, else restarted; onPaths (when set) sees the paths
  // kept (none on a fresh search), then the paths after each new one. UnreachableTarget / DataError as runTrace.
  struct Outcome {
    std::vector<Index3> used;  // root and targets after snapping
    std::vector<TracedPath> paths;
    Tree tree;  // refined when the options refine
    VolumeU16 labels;
  };
  Outcome resume(const Index3& root, const std::vector<Index3>& targets, int autoTerminals, Progress& progress,
                 const std::function<void(const std::vector<TracedPath>&)>& onPaths = {});

 private:
  const VolumeF32& volume_;
  TraceRequest config_;
  double smoothMm_ = 0;
  std::unique_ptr<NodeCost3D> cost_;
  // lumenCostThreshold(*cost_), a percentile over the whole volume: computed once per cost, not
  // per snapped point (it was ~9 % of a chest CTA trace's instructions, three times over).
  mutable std::optional<double> lumenCost_;
  double lumenCost() const;
  // snap's test of a target against the tissue beyond its own lumen's wall (trace_session.cpp).
  struct BeyondWall {
    bool taken = false;
    std::string text;  // the figures, for the note or the refusal
  };
  BeyondWall beyondOwnWall(const Index3& v, double noise, double sigmas) const;
  Index3 costRoot_{-1, -1, -1};
  bool refineReady_ = false;
  VolumeF32 lumen_;
  LocalBackground background_;
  std::optional<LumenEstimate> estimate_;
  std::vector<PhaseTime> featurePhases_;
  std::unique_ptr<VesselTracker> tracker_;
};

}  // namespace vs
