#include "app/viewer_app.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/viewer_app_internal.h"
#include "features/features3d.h"
#include "io/mesh_io.h"
#include "io/overlay_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "render/slice_render.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/names.h"
#include "util/text.h"
#include "volume/slice.h"

namespace vs::viewer {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kCutContourJob = "cut contour";
constexpr std::pair<ToolKind, const char*> kToolNames[] = {{ToolKind::LiveWire, "livewire"},
                                                           {ToolKind::Trace, "trace"},
                                                           {ToolKind::Surface, "surface"},
                                                           {ToolKind::Cut, "cut"},
                                                           {ToolKind::None, "none"}};
constexpr std::pair<StereoMode, const char*> kStereoNames[] = {{StereoMode::Off, "off"},
                                                               {StereoMode::Anaglyph, "anaglyph"},
                                                               {StereoMode::SideBySide, "side-by-side"},
                                                               {StereoMode::Quad, "quad"}};

}  // namespace

std::string toolName(ToolKind t) { return nameOf(kToolNames, t, "none"); }

ToolKind toolFromName(const std::string& s) {
  if (const auto t = valueOf(kToolNames, s)) return *t;
  throw UsageError("unknown tool '" + s + "' (tools: " + namesText(kToolNames) + ")");
}

double visibleIso(const TransferFunction& tf) {
  const auto& pts = tf.points();
  VS_REQUIRE(!pts.empty(), "visible iso-value: empty transfer function");
  double top = 0;
  for (const TfPoint& p : pts) top = std::max(top, p.opacity);
  const double half = 0.5 * top;
  if (top <= 0 || pts[0].opacity >= half) return pts[0].value;
  for (size_t i = 1; i < pts.size(); ++i)
    if (pts[i].opacity >= half) {
      const TfPoint &a = pts[i - 1], &b = pts[i];
      return a.value + (b.value - a.value) * (half - a.opacity) / (b.opacity - a.opacity);
    }
  return pts.back().value;
}

std::string stereoName(StereoMode m) { return nameOf(kStereoNames, m, "off"); }

StereoMode stereoFromName(const std::string& s) {
  if (const auto m = valueOf(kStereoNames, s)) return *m;
  throw UsageError("unknown stereo mode '" + s + "' (" + namesText(kStereoNames) + ")");
}

EyeView eyeView(const Camera& camera, double aspect, int eye, double separationMm, double convergenceMm) {
  camera.validate();
  VS_REQUIRE(aspect > 0 && std::isfinite(aspect), "eye view: aspect must be > 0");
  VS_REQUIRE(convergenceMm > 0, "eye view: convergence distance must be > 0");
  const CameraFrame cf(camera, 2, 2);
  const Vec3 f = cf.forward(), r = cf.right(), u = cf.up();
  const double offset = 0.5 * double(eye) * separationMm;
  const Vec3 eyePos = camera.eye + offset * r;
  EyeView ev;
  for (int c = 0; c < 3; ++c) {
    ev.view(0, c) = r[c];
    ev.view(1, c) = u[c];
    ev.view(2, c) = -f[c];
  }
  ev.view(0, 3) = -r.dot(eyePos);
  ev.view(1, 3) = -u.dot(eyePos);
  ev.view(2, 3) = f.dot(eyePos);
  Eigen::Matrix4d& P = ev.projection;
  P.setZero();
  if (camera.perspective) {
    const double n = 1.0, fa = 1e5;
    const double top = n * std::tan(camera.fovDeg * kPi / 360.0), right = top * aspect;
    const double shift = offset * n / convergenceMm;  // off-axis: both frusta meet at the convergence plane
    const double l = -right - shift, rr = right - shift;
    P(0, 0) = 2 * n / (rr - l);
    P(0, 2) = (rr + l) / (rr - l);
    P(1, 1) = 2 * n / (2 * top);
    P(2, 2) = -(fa + n) / (fa - n);
    P(2, 3) = -2 * fa * n / (fa - n);
    P(3, 2) = -1;
  } else {
    const double h = camera.orthoHeight / 2, w = h * aspect, n = 0, fa = 1e5;
    P(0, 0) = 1 / w;
    P(1, 1) = 1 / h;
    P(2, 2) = -2 / (fa - n);
    P(2, 3) = -(fa + n) / (fa - n);
    P(3, 3) = 1;
  }
  return ev;
}

ViewerApp::ViewerApp() = default;
ViewerApp::~ViewerApp() {
  job_.cancel();
  job_.wait();
}

void ViewerApp::adopt(std::unique_ptr<AnyVolume> volume, std::string source) {
  job_.cancel();
  job_.wait();
  orientation_.clear();
  orientationWarning_.clear();
  auto fv = std::make_unique<VolumeF32>(toFloat(*volume));
  const ValueRange r = valueRange(*volume);
  const WindowLevel wl = percentileWindow(*volume);
  volume_ = std::move(volume);
  floatVolume_ = std::move(fv);
  source_ = std::move(source);
  range_ = r;
  ++volumeRevision_;
  const Index3& d = geometryOf(*volume_).dims;
  view_.window = wl;
  view_.cursor = {d[0] / 2, d[1] / 2, d[2] / 2};
  view_.panMm = {0, 0};  // the new volume centred (a pan in mm of the old one could lose it)
  view_.cutBox.reset();  // the cursor's box of the new volume
  // Keep the chosen transfer function if it applies to the new data, else fall back to "auto".
  try {
    setTransferFunction(view_.tf);
  } catch (const Error&) {
    setTransferFunction("auto");
  }
  liveWire_.reset(volume_.get(), source_);
  trace_.reset(floatVolume_.get(), source_);
  profile_.clear();
  surface_.reset(floatVolume_.get(), source_);
  cut_.reset(floatVolume_.get(), source_);
  cut_.setIso(visibleIso(tf_), true);
  loadedLabels_.reset();
  loadedLabelsPath_.clear();
  loadedOverlays_.clear();
  overlays_.hiddenLabels.clear();
}

void ViewerApp::loadHeadPhantom(int size) {
  VS_REQUIRE(size >= 32 && size <= 512, "head phantom size must be in 32..512");
  HeadPhantomOptions o;
  o.dims = {size, size, size};
  HeadPhantom h = makeHeadPhantom(o);
  // The CT presets are in HU, which the phantom is.
  if (!hasVolume()) view_.tf = "ct-skin";
  adopt(std::make_unique<AnyVolume>(std::move(h.volume)),
        size == 128 ? kPhantomSource : std::string(kPhantomSource) + ":" + std::to_string(size));
}

void ViewerApp::load(const std::string& path, const std::string& orientation) {
  if (!orientation.empty()) directionFromOrientationCode(orientation);  // a bad code before reading
  if (path.rfind(kPhantomSource, 0) == 0) {
    const std::string rest = path.substr(std::string(kPhantomSource).size());
    int64_t size = 128;
    if (!rest.empty() && (rest[0] != ':' || !parseInteger(rest.substr(1), size) || size < 1 || size > 4096))
      throw UsageError("load " + path + ": give phantom:head or phantom:head:SIZE (an integer side in voxels)");
    loadHeadPhantom(static_cast<int>(size));
    return;
  }
  ReadInfo info;
  auto v = std::make_unique<AnyVolume>(readVolume(path, {}, &info));
  requireFinite(*v, path);
  std::string warning;
  if (!orientation.empty())
    setOrientation(*v, orientation);
  else if (!info.orientationInHeader)
    warning = path +
              " states no orientation: LPS assumed, so the anatomical labels and the 3D view may be wrong "
              "(state it: view --orientation CODE, e.g. LAS)";
  adopt(std::move(v), path);
  orientation_ = orientation;
  orientationWarning_ = warning;
}

void ViewerApp::setTransferFunction(const std::string& presetOrFile) {
  VS_REQUIRE(hasVolume(), "transfer function: no volume loaded");
  const auto names = TransferFunction::presetNames();
  TransferFunction tf;
  if (std::find(names.begin(), names.end(), presetOrFile) != names.end())
    tf = TransferFunction::preset(presetOrFile, range_);
  else if (std::filesystem::exists(presetOrFile))
    tf = TransferFunction::fromFile(presetOrFile);
  else
    tf = TransferFunction::preset(presetOrFile, range_);  // throws UsageError listing the presets
  tf_ = std::move(tf);
  ++tfRevision_;
  view_.tf = presetOrFile;
  if (cut_.isoAutomatic()) cut_.setIso(visibleIso(tf_), true);
}

void ViewerApp::setEditedTransferFunction(const TransferFunction& tf) {
  VS_REQUIRE(!tf.empty(), "transfer function: no points");
  tf_ = tf;
  ++tfRevision_;
  view_.tf = kEditedTf;
  if (cut_.isoAutomatic()) cut_.setIso(visibleIso(tf_), true);
}

void ViewerApp::saveTransferFunction(const std::string& path) const {
  VS_REQUIRE(hasVolume(), "transfer function: no volume loaded");
  writeFileAtomically(path, tf_.toJson() + "\n");
}

void ViewerApp::setCutIso(const std::optional<double>& iso) {
  VS_REQUIRE(hasVolume(), "cut: no volume loaded");
  requireNoComputation();
  cut_.setIso(iso ? *iso : visibleIso(tf_), !iso);
}

void ViewerApp::cutPoint(const Vec3& index) {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  VS_REQUIRE(tool_ == ToolKind::Cut, "a cut point needs the cut tool (tool cut)");
  requireNoComputation();
  cut_.click(index);
}

bool ViewerApp::computing() const { return job_.running() && job_.name() != kCutContourJob; }

void ViewerApp::requireNoComputation() const {
  // The live contour's mesh may still be building: points, undo and saving do not need it.
  VS_REQUIRE(!computing(), "a computation is running; wait for it or cancel it");
}

void ViewerApp::prepareCutContour() {
  if (!hasVolume() || job_.running() || cut_.liveContourReady()) return;
  job_.start(kCutContourJob, [this](Progress& p) { cut_.prepareLiveContour(p); });
}

void ViewerApp::loadLabels(const std::string& path) {
  VS_REQUIRE(hasVolume(), "labels: load a volume first");
  const AnyVolume v = readVolume(path);
  const Geometry& g = geometryOf(v);
  if (g.dims != geometry().dims)
    throw DataError("labels " + path + ": " + g.describe() + " does not match the volume " + geometry().describe());
  auto labels = std::make_shared<VolumeU16>(g, 0);
  std::visit(
      [&](const auto& vol) {
        const auto& in = vol.voxels();
        for (size_t i = 0; i < in.size(); ++i) {
          const double x = double(in[i]);
          if (!(x >= 0 && x <= 65535 && x == std::floor(x)))
            throw DataError("labels " + path + ": voxel " + std::to_string(i) + " holds " + std::to_string(x) +
                            ", not a label (integers 0..65535)");
          labels->voxels()[i] = static_cast<uint16_t>(x);
        }
      },
      v);
  loadedLabels_ = std::move(labels);
  loadedLabelsPath_ = path;
  loadedLabelsStamp_ = ++stampCounter_;
}

std::shared_ptr<const VolumeU16> ViewerApp::labels() const {
  const std::shared_ptr<const CutOutcome> r = cut_.result();
  if (r != seenCut_) {
    seenCut_ = r;
    cutLabels_.reset();
    cutLabelsStamp_ = 0;
    if (r) {
      auto l = std::make_shared<VolumeU16>(r->labels.geometry(), 0);
      std::copy(r->labels.voxels().begin(), r->labels.voxels().end(), l->voxels().begin());
      cutLabels_ = std::move(l);
      cutLabelsStamp_ = ++stampCounter_;
    }
  }
  return cutLabelsStamp_ > loadedLabelsStamp_ ? cutLabels_ : loadedLabels_;
}

uint64_t ViewerApp::labelsRevision() const {
  labels();
  return std::max(cutLabelsStamp_, loadedLabelsStamp_);
}

void ViewerApp::addOverlay(const std::string& path) {
  VS_REQUIRE(hasVolume(), "overlay: load a volume first");
  // The core's one overlay reader (io/overlay_io.h): meshes, trees, polylines, tracking reports
  // and the live-wire's own contour JSON, mapped to world mm through this volume's geometry.
  Overlay read;
  try {
    read = readOverlay(path, geometry());
  } catch (const InvalidArgument& e) {
    throw IoError(std::string(e.what()));
  }
  if (read.empty()) throw IoError("overlay " + path + ": nothing to draw in it");
  LoadedOverlay o;
  o.path = path;
  o.mesh = std::move(read.mesh);
  o.lines = std::move(read.lines);
  loadedOverlays_.push_back(std::move(o));
}

bool ViewerApp::labelsFromCut() const {
  labels();
  return cutLabels_ && cutLabelsStamp_ > loadedLabelsStamp_;
}

void ViewerApp::setLabelOpacity(double opacity) {
  VS_REQUIRE(opacity >= 0 && opacity <= 1, "label opacity must be in 0..1");
  overlays_.labelOpacity = opacity;
}

void ViewerApp::setOverlayOpacity(double opacity) {
  VS_REQUIRE(opacity >= 0 && opacity <= 1, "overlay opacity must be in 0..1");
  overlays_.overlayOpacity = opacity;
}

void ViewerApp::setLabelVisible(int label, bool visible) {
  VS_REQUIRE(label >= 1 && label <= 65535, "label must be in 1..65535");
  if (visible)
    overlays_.hiddenLabels.erase(label);
  else
    overlays_.hiddenLabels.insert(label);
}

void ViewerApp::setOrbit(double az, double el) {
  VS_REQUIRE(std::isfinite(az) && std::isfinite(el) && el > -90 && el < 90,
             "view: azimuth must be finite and elevation within (-90, 90) degrees");
  view_.azimuthDeg = std::fmod(az, 360.0);
  view_.elevationDeg = el;
}

void ViewerApp::setZoom(double zoom) {
  VS_REQUIRE(std::isfinite(zoom) && zoom >= 0.1 && zoom <= 20, "zoom must be in 0.1..20");
  view_.zoom = zoom;
}

void ViewerApp::setWindow(double window, double level) {
  VS_REQUIRE(std::isfinite(window) && std::isfinite(level) && window > 0, "window: width must be > 0 and finite");
  view_.window = {window, level};
}

void ViewerApp::setCursor(const Index3& v) {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  VS_REQUIRE(geometry().contains(v), "cursor (" + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," +
                                         std::to_string(v[2]) + ") is outside the volume " + geometry().describe());
  view_.cursor = v;
}

void ViewerApp::setMonoAxis(int axis) {
  VS_REQUIRE(axis >= 0 && axis <= 2, "monoplanar axis must be 0 (x), 1 (y) or 2 (z)");
  view_.monoAxis = axis;
}

void ViewerApp::setSliceView(int axis, double zoom, std::array<double, 2> pan) {
  VS_REQUIRE(axis >= 0 && axis <= 2, "slice view axis must be 0 (x), 1 (y) or 2 (z)");
  VS_REQUIRE(std::isfinite(zoom) && zoom >= 0.25 && zoom <= 40, "slice zoom must be in 0.25..40");
  VS_REQUIRE(std::isfinite(pan[0]) && std::isfinite(pan[1]) && std::abs(pan[0]) <= 50 && std::abs(pan[1]) <= 50,
             "slice pan must be finite (within 50 image sizes)");
  view_.sliceZoom[size_t(axis)] = zoom;
  view_.slicePan[size_t(axis)] = pan;
}

void ViewerApp::setStereoParameters(double sep, double conv) {
  VS_REQUIRE(sep >= 0 && sep <= 0.2, "eye separation must be in 0..0.2 of the convergence distance");
  VS_REQUIRE(conv >= 0.2 && conv <= 5, "convergence must be in 0.2..5 times the camera distance");
  view_.eyeSeparation = sep;
  view_.convergence = conv;
}

void ViewerApp::setPan(double rightMm, double upMm) {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  const Geometry& g = geometry();
  const double diameter = (g.indexToWorld(Vec3(double(g.dims[0] - 1), double(g.dims[1] - 1), double(g.dims[2] - 1))) -
                           g.indexToWorld(Vec3(0, 0, 0)))
                              .norm();
  const double limit = 10 * std::max(diameter, 1.0);
  VS_REQUIRE(std::isfinite(rightMm) && std::isfinite(upMm) && std::abs(rightMm) <= limit && std::abs(upMm) <= limit,
             "pan: give finite mm within " + std::to_string(int(limit)) + " (10 times the volume's diameter)");
  view_.panMm = {rightMm, upMm};
}

Camera ViewerApp::camera() const {
  Camera c = orbitCamera(geometry(), view_.azimuthDeg, view_.elevationDeg, view_.zoom, /*perspective=*/true);
  // Moving the camera left moves the picture right: eye and look-at point shift together.
  const CameraFrame cf(c, 2, 2);
  const Vec3 shift = -view_.panMm[0] * cf.right() - view_.panMm[1] * cf.up();
  c.eye += shift;
  c.target += shift;
  return c;
}

std::array<double, 6> ViewerApp::cutBox() const {
  if (view_.cutBox) return *view_.cutBox;
  const Index3& d = geometry().dims;
  const double z1 = std::max<double>(double(view_.cursor[2]), d[2] > 1 ? 1.0 : 0.0);
  return {0, 0, 0, double(d[0] - 1), double(d[1] - 1), z1};
}

void ViewerApp::setSnap(double radius) {
  VS_REQUIRE(std::isfinite(radius) && radius >= 0 && radius <= 50, "snap radius must be in 0..50");
  liveWire_.setSnapRadius(radius);
  snap_ = radius;
}

void ViewerApp::point2(const PixelUV& p) {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  VS_REQUIRE(tool_ == ToolKind::LiveWire, "a 2D point (u,v) needs the live-wire tool (tool livewire)");
  liveWire_.click(p);
}

Index3 ViewerApp::point3(const Index3& p) {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  VS_REQUIRE(tool_ == ToolKind::Trace || tool_ == ToolKind::Surface || tool_ == ToolKind::Cut,
             "a 3D point (x,y,z) needs a 3D tool (tool trace|surface|cut)");
  VS_REQUIRE(geometry().contains(p), "point (" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," +
                                         std::to_string(p[2]) + ") is outside the volume " + geometry().describe());
  if (tool_ == ToolKind::Cut) {
    cutPoint(Vec3(double(p[0]), double(p[1]), double(p[2])));
    return p;
  }
  VS_REQUIRE(!job_.running(), "a computation is running; wait for it or cancel it");
  const Index3 q = strongestGradientVoxel(*floatVolume_, p, snap_);  // features/features3d.h
  if (tool_ == ToolKind::Surface)
    setCursor(q);
  else
    trace_.click(q);
  return q;
}

void ViewerApp::closeContour() {
  VS_REQUIRE(tool_ == ToolKind::LiveWire, "close needs the live-wire tool");
  liveWire_.close();
}

void ViewerApp::setLiveWireSlice(int axis, int64_t index) {
  liveWire_.setSlice(axis, index);  // validates axis and index
  Index3 c = view_.cursor;
  c[static_cast<size_t>(axis)] = index;
  setCursor(c);
}

Tool* ViewerApp::currentTool() {
  switch (tool_) {
    case ToolKind::LiveWire:
      return &liveWire_;
    case ToolKind::Trace:
      return &trace_;
    case ToolKind::Surface:
      return &surface_;
    case ToolKind::Cut:
      return &cut_;
    default:
      return nullptr;
  }
}

const Tool* ViewerApp::currentTool() const { return const_cast<ViewerApp*>(this)->currentTool(); }

void ViewerApp::requireToolIdle(const Tool& t) const {
  if (t.waitFor() == Tool::WaitFor::AnyJob)
    VS_REQUIRE(!job_.running(), "a computation is running; wait for it or cancel it");
  else if (t.waitFor() == Tool::WaitFor::Computation)
    requireNoComputation();
}

bool ViewerApp::undo() {
  Tool* t = currentTool();
  if (!t) return false;
  requireToolIdle(*t);
  return t->undo();
}

bool ViewerApp::redo() {
  Tool* t = currentTool();
  if (!t) return false;
  requireToolIdle(*t);
  return t->redo();
}

void ViewerApp::run(bool wait) {
  VS_REQUIRE(tool_ == ToolKind::Trace || tool_ == ToolKind::Surface || tool_ == ToolKind::Cut,
             "run needs a tool that computes (trace, surface, cut); the live-wire runs as you click");
  if (job_.running() && job_.name() == kCutContourJob) job_.wait();  // the live contour's mesh: seconds at most
  VS_REQUIRE(!job_.running(), "a computation is already running");
  if (tool_ == ToolKind::Trace) {
    job_.start("trace", [this](Progress& p) { trace_.run(p); });
  } else if (tool_ == ToolKind::Cut) {
    job_.start("cut", [this](Progress& p) { cut_.run(p); });
  } else {
    const Index3 planes = view_.cursor;
    job_.start("surface", [this, planes](Progress& p) { surface_.run(planes, p); });
  }
  if (wait) {
    job_.wait();
    finishJob();
  }
}

void ViewerApp::finishJob() {
  if (job_.state() == BackgroundJob::State::Failed) throw DataError(job_.error());
  if (job_.state() == BackgroundJob::State::Cancelled) throw Cancelled();
}

void ViewerApp::save(const std::string& path) const {
  const Tool* t = currentTool();
  if (!t) throw InvalidArgument("save: choose a tool first (tool livewire|trace|surface|cut)");
  if (t->waitFor() == Tool::WaitFor::AnyJob)
    VS_REQUIRE(!job_.running(), std::string(t->jobName()) + " is still running; wait for it before saving");
  else if (t->waitFor() == Tool::WaitFor::Computation)
    requireNoComputation();
  t->save(path);
}

}  // namespace vs::viewer
