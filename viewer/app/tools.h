// The viewer's tools, GL-free so they are unit-tested without a window: the live-wire on one
// slice and vessel/airway tracking. Both keep their own undo/redo history of at least
// kUndoDepth steps (actions, not snapshots); navigation (slices shown, camera, window/level)
// never touches it. The computations are the core's (scissors/live_wire.h,
// tracking/tracker.h) with the CLI's defaults, so the same points give the same results as
// `volscissors livewire` / `volscissors trace`.
#pragma once
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/tool_common.h"
#include "cost/cost3d.h"
#include "scissors/live_wire.h"
#include "surface/surface.h"
#include "tracking/trace_options.h"
#include "tracking/trace_session.h"
#include "tracking/tracker.h"
#include "util/progress.h"
#include "volume/contour_document.h"
#include "volume/volume.h"

namespace vs::viewer {

// Live-wire on one slice (thesis ch. 2-3): the first point seeds, each further point commits
// the live path to it, close() joins back to the first point.
class LiveWireTool : public Tool {
 public:
  const char* name() const override { return "livewire"; }
  WaitFor waitFor() const override { return WaitFor::Nothing; }
  // A new volume: drops the contour and the history. `source` names the volume in the result.
  void reset(const AnyVolume* volume, std::string source);
  // The slice the tool works on. Changing it while a contour exists is an InvalidArgument
  // (undo it or save it first): a contour lives on one slice.
  void setSlice(int axis, int64_t index);
  int axis() const { return axis_; }
  int64_t index() const { return index_; }
  bool hasContour() const { return !done_.empty(); }
  // Snap radius in pixels (0 = off), applied to every point and to the hover position.
  void setSnapRadius(double px);
  double snapRadius() const { return snap_; }
  PixelUV snap(PixelUV p);
  // Mouse move: the live path from the last anchor to p (snapped); empty without a seed.
  const std::vector<PixelUV>& hover(PixelUV p);
  const std::vector<PixelUV>& livePath() const { return live_; }
  // A click. InvalidArgument outside the slice, on the current anchor, or after close().
  void click(PixelUV p);
  // Joins the last anchor to the first point (needs >= 3 anchors).
  void close();
  bool undo() override;
  bool redo() override;
  size_t undoSteps() const override { return done_.size(); }
  size_t redoSteps() const { return undone_.size(); }
  LiveWireContour contour() const;
  // The contour's anchors (clicked, inserted, moved or cooled), in order: clicking them again
  // rebuilds the contour (the session does so).
  const std::vector<PixelUV>& clicks() const { return clicks_; }

  // Anchor editing (thesis 5.2; app/livewire_edit.cpp), each one undo step; the contour is
  // re-wired between the edited anchor's neighbours (LiveWire::insertAnchor etc.). Points are
  // snapped as clicks are. InvalidArgument for an anchor or segment that does not exist, a
  // point outside the slice or on a neighbouring anchor.
  void insertAnchor(size_t segment, PixelUV p);
  // Into the segment passing nearest to p.
  void insertAnchor(PixelUV p);
  void moveAnchor(size_t anchor, PixelUV p);
  void removeAnchor(size_t anchor);
  // The anchor nearest to p within radiusPx (slice pixels), if any.
  std::optional<size_t> anchorNear(PixelUV p, double radiusPx) const;
  // The segment whose path passes nearest to p within radiusPx, if any.
  std::optional<size_t> segmentNear(PixelUV p, double radiusPx) const;
  // Path cooling (Mortensen & Barrett; LiveWireOptions::coolingMoves): the part of the live path
  // that stayed the same over this many mouse moves becomes a segment by itself (an anchor that
  // undo removes). 0 = off (the default, as the CLI).
  void setCooling(int moves);
  int cooling() const { return options_.coolingMoves; }
  // The contour's document (the CLI's `livewire --out` JSON). InvalidArgument without a contour.
  ContourDocument document() const;
  // .json: contour JSON; .nii/.nii.gz/.nrrd/.mha: uint8 label volume with the filled closed contour.
  void save(const std::string& path) const override;
  const LiveWireOptions& options() const { return options_; }
  int64_t width() const;
  int64_t height() const;

 private:
  struct Action {
    enum class Kind { Click, Close, Cool, Edit } kind = Kind::Click;
    PixelUV p{};
    // Edit: the wire before and after (undo and redo restore them).
    std::shared_ptr<const LiveWire::Snapshot> before, after;
  };
  LiveWire& wire();
  void apply(const Action& a);
  void record(Action a);  // a new undoable action (drops the redo list)
  template <class F>
  void edit(F&& change);  // an Edit action around change(wire)
  void refreshAnchors();
  const AnyVolume* volume_ = nullptr;
  std::string source_;
  int axis_ = 2;
  int64_t index_ = 0;
  double snap_ = 0;
  LiveWireOptions options_;
  std::unique_ptr<LiveWire> wire_;
  std::vector<Action> done_, undone_;
  std::vector<PixelUV> clicks_, live_;
};

// Tracking (thesis 4.3.2, 6.2): the first point is the root, the others targets; run()
// computes the tree off the UI thread, publishing each path as soon as it is extracted. The
// options are the CLI's (tracking/trace_options.h TraceOptions, read, never copied): the auto
// cost estimated at the root, roots and targets snapped into the lumen, sub-voxel refined
// centrelines; so the same points give the tree of `volscissors trace` at its defaults.
class TraceTool : public Tool {
 public:
  const char* name() const override { return "trace"; }
  WaitFor waitFor() const override { return WaitFor::AnyJob; }
  const char* jobName() const override { return "the trace"; }
  void reset(const VolumeF32* volume, std::string source);
  // Root first, then targets. InvalidArgument outside the volume, on the root or a duplicate target.
  void click(const Index3& p);
  bool undo() override;
  bool redo() override;
  size_t undoSteps() const override { return points_.size(); }
  size_t redoSteps() const { return undone_.size(); }
  bool hasRoot() const { return !points_.empty(); }
  const std::vector<Index3>& points() const { return points_; }
  // Node costs as `volscissors trace --cost KIND --polarity P` with the CLI's other defaults:
  // auto (the default: polarity and window estimated at the root), gradient, vesselness or
  // intensity (the polarity applies to the last two). InvalidArgument for another kind.
  void setCost(const std::string& kind, TubePolarity polarity);
  const std::string& costKind() const { return options_.cost; }
  TubePolarity polarity() const { return polarity_; }
  const TraceOptions& options() const { return options_; }
  // The root and targets the search used (snapped into the lumen), after a run.
  std::vector<Index3> usedPoints() const;
  // Automatic terminals added after the given targets (thesis 6.2); 0 = none.
  void setAutoTerminals(int count);
  int autoTerminals() const { return autoTerminals_; }
  // The search; call on a worker thread (BackgroundJob). Resumes the previous search when the
  // root is unchanged. Throws DataError for an unreachable target, as the CLI.
  void run(Progress& progress);
  // Thread-safe snapshots of the published result.
  std::vector<TracedPath> paths() const;
  Tree tree() const;
  bool hasResult() const;
  // .swc/.vtk/.json tree (vs::writeTree), .nii/.nii.gz/.nrrd/.mha label volume (path index + 1).
  void save(const std::string& path) const override;

 private:
  void runSearch(Progress& progress);
  void clearResult();  // no tree, paths or labels shown
  const VolumeF32* volume_ = nullptr;
  std::string source_;
  std::vector<Index3> points_;
  std::vector<Index3> undone_;  // undone clicks, for redo
  int autoTerminals_ = 0;
  TraceOptions options_;
  TubePolarity polarity_ = TubePolarity::Bright;
  // The core's resumable trace (tracking/trace_session.h): costs, snapping, search, refinement.
  std::unique_ptr<TraceSession> session_;
  mutable std::mutex mutex_;
  std::vector<TracedPath> published_;
  std::vector<Index3> used_;
  Tree tree_;
  VolumeU16 labels_;
  bool hasResult_ = false;
};

// Surface extraction from three orthogonal planes through a centre (thesis 4.3.1 and 5.2,
// surface/surface.h): the planes are the viewer's linked cursor; run() computes the mesh off the
// UI thread (app/surface_tool.cpp). The thesis's interface: the corners (one per half-line from
// the centre, three per octant) can be moved, and a chosen side contour can be made to pass
// through via points; a run after a via edit re-subdivides only the octants that share the side
// (SurfaceExtraction::editSide), any other change extracts anew. Every finished run is one undo
// step (undo shows the previous mesh and its corners and via points).
class SurfaceTool : public Tool {
 public:
  const char* name() const override { return "surface"; }
  WaitFor waitFor() const override { return WaitFor::AnyJob; }
  const char* jobName() const override { return "the extraction"; }
  void reset(const VolumeF32* volume, std::string source);
  // Subdivision level (level of detail) 0..8 and closed (all eight octants) or one octant.
  void setLevel(int level);
  int level() const { return level_; }
  void setClosed(bool closed) { closed_ = closed; }
  bool closed() const { return closed_; }
  // Call on a worker thread. Throws the core's errors (e.g. no crossing on a half-line, a corner
  // off its half-line, a via point outside its side's quadrant).
  void run(const Index3& planes, Progress& progress);
  bool undo() override;
  bool redo() override;
  size_t undoSteps() const override;
  bool hasResult() const;
  TriMesh mesh() const;  // thread-safe snapshot (empty without a result)
  Index3 planes() const;
  // .obj/.ply/.stl/.vtk (vs::writeTriMesh).
  void save(const std::string& path) const override;

  // Half-line h = 2 * axis + (sign < 0): +x, -x, +y, -y, +z, -z (SurfaceOptions::corners).
  static std::string halfLineName(int h);
  static int halfLineFromName(const std::string& name);  // "+x" ... "-z"; UsageError otherwise
  // Moves corner h to p for the next run (the core checks that p lies on its half-line).
  void setCorner(int halfLine, const Index3& p);
  void clearCorners();
  // The corners of the shown result (empty for half-lines it does not use) and its side contours.
  std::array<std::optional<Index3>, 6> corners() const;
  std::vector<std::pair<std::string, std::vector<Index3>>> sides() const;
  // The side contour that via points go to ("z+x+y": plane z, quadrant x >= x0, y >= y0;
  // surface/surface.h sideName). InvalidArgument for a name that is no side.
  void selectSide(const std::string& side);
  const std::string& selectedSide() const { return side_; }
  // A via point of the selected side for the next run, ordered along the side's current path.
  void addVia(const Index3& p);
  void clearVia();  // the selected side's
  std::vector<Index3> via(const std::string& side) const;
  const std::vector<std::pair<std::string, std::vector<Index3>>>& allVia() const { return via_; }
  const std::array<std::optional<Index3>, 6>& cornerOverrides() const { return cornerOverrides_; }
  // What the last run did ("extracted", or "side z+x+y edited: 1 octant re-subdivided, 12 paths").
  std::string lastRun() const;

 private:
  struct Result {
    Index3 planes{0, 0, 0};
    TriMesh mesh;
    std::array<std::optional<Index3>, 6> corners, cornerOverrides;
    std::vector<std::pair<std::string, std::vector<Index3>>> sides, via;
    int level = 0;
    bool closed = false;
    std::string what;
  };
  SurfaceOptions options(const Index3& planes) const;
  const VolumeF32* volume_ = nullptr;
  std::string source_;
  // The CLI's defaults (surface/surface.h SurfaceOptions, read, never copied): one octant.
  int level_ = SurfaceOptions{}.level;
  bool closed_ = SurfaceOptions{}.closed;
  std::array<std::optional<Index3>, 6> cornerOverrides_;
  std::vector<std::pair<std::string, std::vector<Index3>>> via_;
  std::string side_ = "z+x+y";
  // The extraction of the last run, kept for incremental side edits, and the options it has now.
  std::shared_ptr<SurfaceExtraction> extraction_;
  SurfaceOptions extractionOptions_;
  mutable std::mutex mutex_;
  std::vector<Result> done_, undone_;
};

}  // namespace vs::viewer
