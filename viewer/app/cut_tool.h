// Volume cutting in the viewer (thesis ch. 3, 5.1; the core is cutting/cut.h): points on the
// object's surface (the stylus' first visible point), a live contour on the surface mesh while the
// mouse moves, and run() cuts off the UI thread with the core's cutVolume, so the same points and
// iso-value give the labels of `volscissors cut`. Undo steps are the points and the cuts (undoing
// a cut shows the one before). The core's types stay in cut_tool.cpp (pimpl), so this header
// can sit next to the tracking headers.
#pragma once
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "app/tool_common.h"
#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs::viewer {

// What a cut gives (copied from the core's CutResult).
struct CutOutcome {
  double iso = 0;
  VolumeU8 labels;              // 0 background (< iso), 1 kept, 2 cut away
  std::vector<Vec3> contourMm;  // the closed contour on the surface, world mm
  TriMesh cuttingSurface;       // world mm
  int64_t keptVoxels = 0, cutVoxels = 0;
};

// The cut's weights (issue 26), as `volscissors cut --wg --wc --wp --wd --contour-wg --contour-wn
// --contour-wl` and `vs.cut`: the cutting surface's image, continuity, part and direction weights
// (eq. 15-18) and the contour live-wire's gradient, normal-change and length weights (eq. 13).
struct CutWeights {
  double wg = 0, wc = 0, wp = 0, wd = 0;
  double contourWg = 0, contourWn = 0, contourWl = 0;
  bool operator==(const CutWeights&) const = default;
};
// The core's defaults (CutOptions{}: the CLI's and Python's defaults, read, not retyped).
CutWeights defaultCutWeights();
// The names the script and the panel use, in CutWeights' order, and their places in it.
struct CutWeightName {
  const char* key;          // script key: wg wc wp wd contour-wg contour-wn contour-wl
  const char* description;  // what it weighs
  double CutWeights::*field;
};
const std::vector<CutWeightName>& cutWeightNames();

class CutTool : public Tool {
 public:
  CutTool();
  ~CutTool() override;
  const char* name() const override { return "cut"; }
  WaitFor waitFor() const override { return WaitFor::Computation; }
  void reset(const VolumeF32* volume, std::string source);
  // The object is the voxels >= iso. `automatic`: the viewer chose it (follows the transfer
  // function); an explicit value stays until set again. A new value drops the live-contour mesh.
  void setIso(double iso, bool automatic);
  double iso() const;
  bool isoAutomatic() const;
  double snapRadiusMm() const;
  // The weights the next cut uses. InvalidArgument (the core's checkCutWeights) for a bad one,
  // nothing changed then; new contour weights drop the live-contour mesh (its eq. 13 graph).
  void setWeights(const CutWeights& w);
  CutWeights weights() const;  // the core's 3D snap radius (points farther from the surface are refused)
  // A point (continuous voxel index). InvalidArgument outside the volume or equal to the last point.
  void click(const Vec3& index);
  bool undo() override;
  bool redo() override;
  size_t undoSteps() const override;
  size_t redoSteps() const;
  std::vector<Vec3> points() const;

  // Live contour: the iso-surface (every component) built once per iso on a worker thread
  // (prepareLiveContour); then, on the UI thread, what the cut will use: the component the points
  // choose, prepared as cutVolume prepares it, and the core's cutContour through the points (and
  // the hovered point as the next one), self-avoiding and closed. So the previewed loop is, vertex
  // for vertex, the contour the cut reports for the same points.
  void prepareLiveContour(Progress& progress);
  bool liveContourReady() const;
  struct LiveContour {
    std::vector<Vec3> path;  // world mm: the loop (closed: the last vertex joins the first), or one open segment
    bool closed = false;     // the loop cutContour gives: the cut's contour for these points (+ hover)
    bool withHover = false;  // the hovered point is the loop's next point (or the segment's end)
    std::string problem;     // the core's reason why the points (+ hover) give no loop
  };
  // Empty before the mesh is ready or without points. hoverIndex: the stylus' point (continuous
  // index: what a click would give the cut), used when it lies within the snap radius of the surface.
  LiveContour liveContour(const std::optional<Vec3>& hoverIndex);

  // The cut; call on a worker thread. Throws the core's errors (DataError saying what to change).
  void run(Progress& progress);
  bool hasResult() const;
  // Thread-safe snapshot of the current result (null without one).
  std::shared_ptr<const CutOutcome> result() const;
  // .nii/.nii.gz/.nrrd/.mha: the label volume (as `volscissors cut --labels`); .vtk/.json: the
  // contour polyline; .obj/.ply/.stl: the cutting surface.
  void save(const std::string& path) const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vs::viewer
