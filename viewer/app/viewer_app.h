// The viewer's state and actions without any GL (layer 1 of viewer/): the loaded volume, what
// the views show (display mode, transfer function, camera, window/level, linked cursor, stereo),
// the active tool and its history, the background job, the stylus pick and the session file.
// The window (viewer/window) and the script interpreter (app/script.h) call the same methods,
// so a script replays exactly what the mouse does.
#pragma once
#include <Eigen/Core>
#include <array>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "app/cut_tool.h"
#include "app/job.h"
#include "app/profile.h"
#include "app/slice_layout.h"
#include "app/tools.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/transfer_function.h"
#include "volume/volume.h"

namespace vs::viewer {

enum class ToolKind { None, LiveWire, Trace, Surface, Cut };
std::string toolName(ToolKind t);             // "none", "livewire", "trace", "surface", "cut"
ToolKind toolFromName(const std::string& s);  // throws UsageError listing the tools

enum class StereoMode { Off, Anaglyph, SideBySide, Quad };
std::string stereoName(StereoMode m);             // "off", "anaglyph", "side-by-side", "quad"
StereoMode stereoFromName(const std::string& s);  // throws UsageError

// The iso-value of the surface the 3D view shows: where the transfer function's opacity first
// reaches half of its largest value (the cut tool's default object threshold).
double visibleIso(const TransferFunction& tf);

// A mesh, tree or polyline file shown over the views (`overlay PATH`), in the palette colour of
// its position (render/slice_render.h overlayPaletteColor, as `volscissors render --overlay`).
struct LoadedOverlay {
  std::string path;
  TriMesh mesh;                 // .obj/.ply/.stl, or .vtk polydata with triangles
  std::vector<Polyline> lines;  // .swc/.json trees and polylines, .vtk lines (world mm)
};

struct ViewSettings {
  RenderMode mode = RenderMode::Full;
  std::string tf = "auto";  // preset name or a transfer-function JSON file
  double azimuthDeg = 30, elevationDeg = 20, zoom = 1;
  // Pan of the 3D view: the picture moved right and up on the screen by these mm at the look-at
  // point (the volume's centre); the orbit still turns about the volume's centre.
  std::array<double, 2> panMm{0, 0};
  WindowLevel window;      // slice views, planes, cut faces and MIP; set from the data on load
  Index3 cursor{0, 0, 0};  // linked crosshair: the slices shown and the triplanar planes
  int monoAxis = 2;        // monoplanar: the plane through the cursor along this axis
  StereoMode stereo = StereoMode::Off;
  double eyeSeparation = 0.03;  // fraction of the convergence distance (about 6.5 cm at 2 m)
  double convergence = 1.0;     // focus distance as a multiple of the camera-target distance
  bool jitter = true;           // jittered ray starts (no wood-grain artefacts)
  bool shading = true;
  double sampleStep = 0.5;  // voxels of the smallest spacing
  // Slice views (index = the fixed axis): zoom about the view's centre and pan (SliceFit units).
  std::array<double, 3> sliceZoom{1, 1, 1};
  std::array<std::array<double, 2>, 3> slicePan{};
  bool slicePlanesIn3D = true;  // the three slice planes' outlines in the 3D view (as Slicer)
  // The cut-box mode's box (index, inclusive: x0 y0 z0 x1 y1 z1) once moved with its handles or
  // `cut-box`; unset: the volume below the cursor's axial plane (app/cut_box.h).
  std::optional<std::array<double, 6>> cutBox;
};

// Per-eye view and projection matrices (OpenGL conventions: right-handed eye space looking down
// -z, clip space -1..1), so the ray caster and a later XR session take the same input. eye: -1
// left, 0 centre (mono), +1 right; the stereo pair is parallel cameras with off-axis frusta
// meeting at the convergence distance.
struct EyeView {
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d projection = Eigen::Matrix4d::Identity();
};
EyeView eyeView(const Camera& camera, double aspect, int eye = 0, double separationMm = 0, double convergenceMm = 1);

// A stylus hit: the first point where the transfer function's accumulated opacity reaches the
// threshold along the ray, and that point moved to the strongest gradient within the snap radius.
struct StylusPick {
  bool hit = false;
  Vec3 surface{0, 0, 0};  // continuous index of the first visible point
  Index3 voxel{0, 0, 0};  // after snapping (the voxel to use)
};

class ViewerApp {
 public:
  ViewerApp();
  ~ViewerApp();

  // The embedded default: the project's head phantom (src/phantom), int16 HU.
  void loadHeadPhantom(int size = 128);
  // Loads a volume file; on failure throws and keeps the current volume and session.
  // orientation: a code (volume/slice.h directionFromOrientationCode, e.g. "LAS") stating how the
  // axes point when the header does not say; "" keeps what the file says (or LPS assumed, with
  // orientationWarning() set).
  void load(const std::string& path, const std::string& orientation = "");
  // The orientation code given to load ("" when the file's own is used).
  const std::string& orientationOverride() const { return orientation_; }
  // Non-empty when the loaded file's header states no orientation and none was given: the
  // viewer shows it (labels and the 3D view's anatomy may be wrong).
  const std::string& orientationWarning() const { return orientationWarning_; }
  bool hasVolume() const { return volume_ != nullptr; }
  const AnyVolume& volume() const { return *volume_; }
  // The same volume, for a worker that must keep it alive across a later load (the CPU 3D view).
  std::shared_ptr<const AnyVolume> sharedVolume() const { return volume_; }
  const VolumeF32& floatVolume() const { return *floatVolume_; }
  const Geometry& geometry() const { return geometryOf(*volume_); }
  const std::string& source() const { return source_; }
  uint64_t volumeRevision() const { return volumeRevision_; }
  ValueRange range() const { return range_; }

  // View settings; setters validate (InvalidArgument/UsageError) and leave the state unchanged on error.
  const ViewSettings& view() const { return view_; }
  void setMode(RenderMode m) { view_.mode = m; }
  void setTransferFunction(const std::string& presetOrFile);
  // A transfer function from the editor (view().tf becomes "edited"; the session keeps its points).
  void setEditedTransferFunction(const TransferFunction& tf);
  // The current transfer function in its JSON file format (`tf FILE` and `volscissors render --tf` read it).
  void saveTransferFunction(const std::string& path) const;
  const TransferFunction& transferFunction() const { return tf_; }
  uint64_t transferFunctionRevision() const { return tfRevision_; }  // changes with every new TF
  void setOrbit(double azimuthDeg, double elevationDeg);
  void setZoom(double zoom);
  // Pans the 3D view (ViewSettings::panMm); at most 10 times the volume's bounding diameter.
  void setPan(double rightMm, double upMm);
  void setWindow(double window, double level);
  void setCursor(const Index3& voxel);
  void setMonoAxis(int axis);
  // Zoom 0.25..40 and pan of the slice view across `axis` (what it shows; picking follows, SliceFit).
  void setSliceView(int axis, double zoom, std::array<double, 2> pan);
  void setStereo(StereoMode m) { view_.stereo = m; }
  void setStereoParameters(double eyeSeparation, double convergence);
  void setJitter(bool on) { view_.jitter = on; }
  void setShading(bool on) { view_.shading = on; }
  void setSlicePlanesIn3D(bool on) { view_.slicePlanesIn3D = on; }
  // Perspective orbit camera of the 3D view (render/camera.h orbitCamera), moved by the pan:
  // both renderers and the stylus use it, so a pick after a pan hits the point under the mouse.
  Camera camera() const;
  // The cut box of the cut-box mode (index, inclusive): view().cutBox, else the volume below the
  // cursor's axial plane. setCutBox: each face inside the volume and x0 < x1, y0 < y1, z0 < z1
  // (InvalidArgument otherwise, nothing changed); nullopt returns to the cursor's box.
  std::array<double, 6> cutBox() const;
  void setCutBox(const std::optional<std::array<double, 6>>& box);

  // Tools.
  ToolKind tool() const { return tool_; }
  void setTool(ToolKind t) { tool_ = t; }
  LiveWireTool& liveWire() { return liveWire_; }
  const LiveWireTool& liveWire() const { return liveWire_; }
  TraceTool& trace() { return trace_; }
  const TraceTool& trace() const { return trace_; }
  SurfaceTool& surface() { return surface_; }
  const SurfaceTool& surface() const { return surface_; }
  CutTool& cut() { return cut_; }
  // The current tool behind the one tool interface (app/tool_common.h); null for ToolKind::None.
  Tool* currentTool();
  const Tool* currentTool() const;
  const CutTool& cut() const { return cut_; }
  // The traced tree's measured profile (app/profile.h); dropped with the volume.
  ProfileView& profile() { return profile_; }
  const ProfileView& profile() const { return profile_; }
  // The cut's object threshold; "auto" follows the transfer function (visibleIso).
  void setCutIso(const std::optional<double>& iso);
  // A cut point at a continuous voxel index (the stylus' first visible point; the core snaps it
  // onto the surface mesh).
  void cutPoint(const Vec3& index);
  // Starts building the cut's live-contour mesh in the background if it is missing and no job runs.
  void prepareCutContour();
  // A computation the user waits for runs (not the live contour's mesh, which never blocks).
  bool computing() const;

  // Labels shown over the views: the latest of a loaded label map and the cut's parts.
  // loadLabels: integer volume 0..65535 with the volume's dimensions (IoError/DataError otherwise).
  void loadLabels(const std::string& path);
  std::shared_ptr<const VolumeU16> labels() const;
  uint64_t labelsRevision() const;  // changes whenever labels() shows other data
  bool labelsFromCut() const;       // labels() shows the cut's parts (1 kept, 2 cut away)
  const OverlaySettings& overlays() const { return overlays_; }
  void setLabelOpacity(double opacity);
  void setOverlayOpacity(double opacity);
  void setLabelVisible(int label, bool visible);
  // Adds a mesh (.obj/.ply/.stl/.vtk) or a tree/polyline file (.swc/.json/.vtk) to the overlays;
  // IoError naming the file when it is none of these or holds nothing to draw.
  void addOverlay(const std::string& path);
  void clearOverlays() { loadedOverlays_.clear(); }
  const std::vector<LoadedOverlay>& loadedOverlays() const { return loadedOverlays_; }
  BackgroundJob& job() { return job_; }
  // Snap radius for points: pixels on the live-wire slice, voxels for 3D points.
  void setSnap(double radius);
  double snap() const { return snap_; }
  // Moves the live-wire tool to slice `index` across `axis` and the linked cursor with it, so
  // the slice view across that axis shows the wire's slice (script `slice z=K`).
  void setLiveWireSlice(int axis, int64_t index);
  // A point on the live-wire slice (pixels u,v) for the live-wire tool.
  void point2(const PixelUV& p);
  // A 3D point (voxel index) for the current 3D tool, snapped to the strongest gradient within
  // the snap radius: trace adds it (root, then targets); surface centres its three planes there
  // (the linked cursor). Returns the voxel used.
  // cut adds it as a cut point (without the gradient snap: the cut snaps onto its surface mesh).
  Index3 point3(const Index3& p);
  void closeContour();
  bool undo();
  bool redo();
  // Starts the current tool's computation in the background (trace); wait = block until done
  // and then finishJob().
  void run(bool wait);
  // After the job ended: throws its error (DataError) or Cancelled if it did not succeed.
  void finishJob();
  // Saves the current tool's result; the format follows the extension.
  void save(const std::string& path) const;

  // Stylus: ray in world mm (origin, unit direction). Opacity threshold 0.5.
  StylusPick pick(const Vec3& originWorld, const Vec3& dirWorld) const;
  // The stylus at pixel (px, py) of a 3D view of width x height pixels (pixel centres at +0.5);
  // side-by-side stereo: with the camera of the eye whose half holds px (app/stereo.h).
  StylusPick stylusPick(double px, double py, int width, int height) const;
  // A click of the stylus there: the pick given to the current tool (cut: a cut point on the
  // surface; trace, surface: point3 of the snapped voxel). InvalidArgument when nothing visible
  // is under it or the tool takes no 3D points.
  StylusPick stylusClick(double px, double py, int width, int height);
  // The point a click of this pick gives the current tool (continuous index): the cut's point
  // (the first visible point, the cut snaps it onto its mesh) or the snapped voxel (trace,
  // surface). The window draws the stylus sphere there.
  Vec3 stylusTarget(const StylusPick& p) const;

  // Session: volume (path or "phantom:head"), view settings, tool states (points), to one JSON.
  nlohmann::json sessionJson() const;
  void saveSession(const std::string& path) const;
  // Reopens a session: loads its volume, restores the view and replays the tools' points
  // (running the trace again when it had a result).
  void loadSession(const std::string& path);

 private:
  void adopt(std::unique_ptr<AnyVolume> volume, std::string source);
  void requireNoComputation() const;
  void requireToolIdle(const Tool& t) const;  // what the tool's waitFor() asks of the running job
  std::shared_ptr<const AnyVolume> volume_;
  std::unique_ptr<VolumeF32> floatVolume_;
  std::string source_;
  std::string orientation_, orientationWarning_;
  uint64_t volumeRevision_ = 0;
  ValueRange range_;
  ViewSettings view_;
  TransferFunction tf_;
  uint64_t tfRevision_ = 0;
  ToolKind tool_ = ToolKind::None;
  LiveWireTool liveWire_;
  TraceTool trace_;
  SurfaceTool surface_;
  CutTool cut_;
  ProfileView profile_;
  BackgroundJob job_;
  OverlaySettings overlays_;
  std::shared_ptr<const VolumeU16> loadedLabels_;
  std::vector<LoadedOverlay> loadedOverlays_;
  std::string loadedLabelsPath_;
  uint64_t loadedLabelsStamp_ = 0;
  // labels(): the cut's labels converted once per result, stamped when first seen.
  mutable std::shared_ptr<const CutOutcome> seenCut_;
  mutable std::shared_ptr<const VolumeU16> cutLabels_;
  mutable uint64_t cutLabelsStamp_ = 0;
  mutable uint64_t stampCounter_ = 0;
  double snap_ = 0;
};

}  // namespace vs::viewer
