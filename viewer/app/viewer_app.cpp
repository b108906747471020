#include "app/viewer_app.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/mesh_io.h"
#include "io/overlay_io.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "render/slice_render.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "volume/slice.h"

namespace vs::viewer {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kPhantomSource = "phantom:head";
constexpr const char* kCutContourJob = "cut contour";
constexpr const char* kEditedTf = "edited";

std::string readText(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(what + " " + path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

float trilinear(const VolumeF32& v, double x, double y, double z) {
  const Index3& d = v.dims();
  x = std::clamp(x, 0.0, double(d[0] - 1));
  y = std::clamp(y, 0.0, double(d[1] - 1));
  z = std::clamp(z, 0.0, double(d[2] - 1));
  const int64_t x0 = std::min<int64_t>(int64_t(x), std::max<int64_t>(d[0] - 2, 0));
  const int64_t y0 = std::min<int64_t>(int64_t(y), std::max<int64_t>(d[1] - 2, 0));
  const int64_t z0 = std::min<int64_t>(int64_t(z), std::max<int64_t>(d[2] - 2, 0));
  const int64_t x1 = std::min(x0 + 1, d[0] - 1), y1 = std::min(y0 + 1, d[1] - 1), z1 = std::min(z0 + 1, d[2] - 1);
  const double fx = x - double(x0), fy = y - double(y0), fz = z - double(z0);
  auto lerp = [](double a, double b, double f) { return a + (b - a) * f; };
  const double c00 = lerp(v(x0, y0, z0), v(x1, y0, z0), fx), c10 = lerp(v(x0, y1, z0), v(x1, y1, z0), fx);
  const double c01 = lerp(v(x0, y0, z1), v(x1, y0, z1), fx), c11 = lerp(v(x0, y1, z1), v(x1, y1, z1), fx);
  return static_cast<float>(lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz));
}

// Ray-box intersection in index space; false if the ray misses [lo, hi].
bool intersect(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi, double& t0, double& t1) {
  t0 = 0;
  t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t1 >= t0;
}

}  // namespace

std::string toolName(ToolKind t) {
  switch (t) {
    case ToolKind::LiveWire:
      return "livewire";
    case ToolKind::Trace:
      return "trace";
    case ToolKind::Surface:
      return "surface";
    case ToolKind::Cut:
      return "cut";
    default:
      return "none";
  }
}

ToolKind toolFromName(const std::string& s) {
  if (s == "livewire") return ToolKind::LiveWire;
  if (s == "trace") return ToolKind::Trace;
  if (s == "surface") return ToolKind::Surface;
  if (s == "cut") return ToolKind::Cut;
  if (s == "none") return ToolKind::None;
  throw UsageError("unknown tool '" + s + "' (tools: livewire, trace, surface, cut, none)");
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

std::string stereoName(StereoMode m) {
  switch (m) {
    case StereoMode::Anaglyph:
      return "anaglyph";
    case StereoMode::SideBySide:
      return "side-by-side";
    case StereoMode::Quad:
      return "quad";
    default:
      return "off";
  }
}

StereoMode stereoFromName(const std::string& s) {
  if (s == "off") return StereoMode::Off;
  if (s == "anaglyph") return StereoMode::Anaglyph;
  if (s == "side-by-side") return StereoMode::SideBySide;
  if (s == "quad") return StereoMode::Quad;
  throw UsageError("unknown stereo mode '" + s + "' (off, anaglyph, side-by-side, quad)");
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
    loadHeadPhantom(rest.empty() ? 128 : std::stoi(rest.substr(1)));
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
    tf = TransferFunction::fromJson(readText(presetOrFile, "transfer function"), presetOrFile);
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
  const Index3 q = snap_ > 0 ? snapToGradient(p, snap_) : p;
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

bool ViewerApp::undo() {
  if (tool_ == ToolKind::LiveWire) return liveWire_.undo();
  if (tool_ == ToolKind::Trace) {
    VS_REQUIRE(!job_.running(), "a computation is running; wait for it or cancel it");
    return trace_.undo();
  }
  if (tool_ == ToolKind::Surface) {
    VS_REQUIRE(!job_.running(), "a computation is running; wait for it or cancel it");
    return surface_.undo();
  }
  if (tool_ == ToolKind::Cut) {
    requireNoComputation();
    return cut_.undo();
  }
  return false;
}

bool ViewerApp::redo() {
  if (tool_ == ToolKind::LiveWire) return liveWire_.redo();
  if (tool_ == ToolKind::Trace) {
    VS_REQUIRE(!job_.running(), "a computation is running; wait for it or cancel it");
    return trace_.redo();
  }
  if (tool_ == ToolKind::Surface) {
    VS_REQUIRE(!job_.running(), "a computation is running; wait for it or cancel it");
    return surface_.redo();
  }
  if (tool_ == ToolKind::Cut) {
    requireNoComputation();
    return cut_.redo();
  }
  return false;
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
  if (tool_ == ToolKind::LiveWire) return liveWire_.save(path);
  if (tool_ == ToolKind::Trace) {
    VS_REQUIRE(!job_.running(), "the trace is still running; wait for it before saving");
    return trace_.save(path);
  }
  if (tool_ == ToolKind::Surface) {
    VS_REQUIRE(!job_.running(), "the extraction is still running; wait for it before saving");
    return surface_.save(path);
  }
  if (tool_ == ToolKind::Cut) {
    requireNoComputation();
    return cut_.save(path);
  }
  throw InvalidArgument("save: choose a tool first (tool livewire|trace|surface|cut)");
}

Index3 ViewerApp::snapToGradient(const Index3& p, double radius) const {
  const VolumeF32& v = *floatVolume_;
  const Geometry& g = v.geometry();
  if (radius <= 0) return p;
  const int r = static_cast<int>(std::floor(radius));
  auto at = [&](int64_t x, int64_t y, int64_t z) {
    return v(std::clamp<int64_t>(x, 0, g.dims[0] - 1), std::clamp<int64_t>(y, 0, g.dims[1] - 1),
             std::clamp<int64_t>(z, 0, g.dims[2] - 1));
  };
  Index3 best = p;
  double bestG = -1, bestD = 0;
  for (int dz = -r; dz <= r; ++dz)
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const double d2 = double(dx * dx + dy * dy + dz * dz);
        if (d2 > radius * radius) continue;
        const int64_t x = p[0] + dx, y = p[1] + dy, z = p[2] + dz;
        if (!g.contains(x, y, z)) continue;
        const double gx = (at(x + 1, y, z) - at(x - 1, y, z)) / (2 * g.spacing.x());
        const double gy = (at(x, y + 1, z) - at(x, y - 1, z)) / (2 * g.spacing.y());
        const double gz = (at(x, y, z + 1) - at(x, y, z - 1)) / (2 * g.spacing.z());
        const double gm = gx * gx + gy * gy + gz * gz;
        if (gm > bestG || (gm == bestG && d2 < bestD)) best = {x, y, z}, bestG = gm, bestD = d2;
      }
  return best;
}

StylusPick ViewerApp::stylusPick(double px, double py, int width, int height) const {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  VS_REQUIRE(width > 0 && height > 0, "stylus: the 3D view's size must be positive");
  VS_REQUIRE(px >= 0 && py >= 0 && px < width && py < height,
             "stylus: pixel " + std::to_string(px) + "," + std::to_string(py) + " is outside the 3D view (" +
                 std::to_string(width) + "x" + std::to_string(height) + ")");
  const CameraFrame cf(camera(), width, height);
  Vec3 o, d;
  cf.ray(px - 0.5, py - 0.5, o, d);
  return pick(o, d);
}

StylusPick ViewerApp::stylusClick(double px, double py, int width, int height) {
  VS_REQUIRE(tool_ == ToolKind::Cut || tool_ == ToolKind::Trace || tool_ == ToolKind::Surface,
             "stylus: the " + toolName(tool_) + " tool takes no 3D points (use trace, surface or cut)");
  const StylusPick p = stylusPick(px, py, width, height);
  VS_REQUIRE(p.hit, "stylus: nothing visible under pixel " + std::to_string(px) + "," + std::to_string(py));
  if (tool_ == ToolKind::Cut)
    cutPoint(p.surface);
  else
    point3(p.voxel);
  return p;
}

StylusPick ViewerApp::pick(const Vec3& originWorld, const Vec3& dirWorld) const {
  StylusPick res;
  const Geometry& g = geometry();
  const Eigen::Matrix3d Minv = (g.direction * g.spacing.asDiagonal()).inverse();
  const Vec3 o = Minv * (originWorld - g.origin), d = Minv * dirWorld.normalized();  // index per mm
  const Vec3 lo(0, 0, 0), hi(double(g.dims[0] - 1), double(g.dims[1] - 1), double(g.dims[2] - 1));
  double t0 = 0, t1 = 0;
  if (!intersect(o, d, lo, hi, t0, t1)) return res;
  auto finish = [&](const Vec3& c) {
    res.hit = true;
    res.surface = c;
    res.voxel = snapToGradient(roundIndex(c), snap_);
    return res;
  };
  const RenderMode mode = view_.mode;
  if (mode == RenderMode::Triplanar || mode == RenderMode::Monoplanar) {
    double best = 1e300;
    for (int a = 0; a < 3; ++a) {
      if (mode == RenderMode::Monoplanar && a != view_.monoAxis) continue;
      if (std::abs(d[a]) < 1e-15) continue;
      const double t = (double(view_.cursor[static_cast<size_t>(a)]) - o[a]) / d[a];
      if (t <= 0 || t >= best) continue;
      const Vec3 q = o + t * d;
      bool inside = true;
      for (int b = 0; b < 3; ++b) inside = inside && q[b] >= lo[b] - 1e-6 && q[b] <= hi[b] + 1e-6;
      if (inside) best = t;
    }
    if (best < 1e300) return finish(o + best * d);
    return res;
  }
  if (mode == RenderMode::CutBox) {
    const auto b = cutBox();
    if (!intersect(o, d, Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5]), t0, t1)) return res;
    return finish(o + t0 * d);  // the box's entry face is shown opaque
  }
  const double dt = 0.5 * g.spacing.minCoeff();
  if (mode == RenderMode::Mip) {
    float vmax = -1e30f;
    double tmax = t0;
    for (double t = t0; t <= t1; t += dt) {
      const Vec3 q = o + t * d;
      const float v = trilinear(*floatVolume_, q.x(), q.y(), q.z());
      if (v > vmax) vmax = v, tmax = t;
    }
    return finish(o + tmax * d);
  }
  const TfTable table(tf_, range_.min, range_.max, dt);
  double A = 0;
  for (double t = t0; t <= t1; t += dt) {
    const Vec3 q = o + t * d;
    const float a = table(trilinear(*floatVolume_, q.x(), q.y(), q.z())).a;
    A += (1 - A) * a;
    if (A >= 0.5) return finish(q);
  }
  return res;
}

nlohmann::json ViewerApp::sessionJson() const {
  VS_REQUIRE(hasVolume(), "session: no volume loaded");
  nlohmann::json j;
  j["volscissors_session"] = 1;
  j["volume"] = source_;
  if (!orientation_.empty()) j["orientation"] = orientation_;
  j["transfer_function"] = nlohmann::json::parse(tf_.toJson());
  j["view"] = {{"mode", renderModeName(view_.mode)},
               {"tf", view_.tf},
               {"azimuth_deg", view_.azimuthDeg},
               {"elevation_deg", view_.elevationDeg},
               {"zoom", view_.zoom},
               {"pan_mm", view_.panMm},
               {"window", view_.window.window},
               {"level", view_.window.level},
               {"cursor", view_.cursor},
               {"mono_axis", view_.monoAxis},
               {"stereo", stereoName(view_.stereo)},
               {"eye_separation", view_.eyeSeparation},
               {"convergence", view_.convergence},
               {"jitter", view_.jitter},
               {"shading", view_.shading},
               {"slice_zoom", view_.sliceZoom},
               {"slice_pan", view_.slicePan},
               {"slice_planes_3d", view_.slicePlanesIn3D}};
  j["tool"] = toolName(tool_);
  j["snap"] = snap_;
  nlohmann::json clicks = nlohmann::json::array();
  for (const auto& c : liveWire_.clicks()) clicks.push_back({c[0], c[1]});
  j["livewire"] = {{"axis", liveWire_.axis()},
                   {"index", liveWire_.index()},
                   {"clicks", clicks},
                   {"closed", liveWire_.contour().closed}};
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& p : trace_.points()) pts.push_back({p[0], p[1], p[2]});
  j["trace"] = {{"points", pts},
                {"auto_terminals", trace_.autoTerminals()},
                {"cost", trace_.costKind()},
                {"polarity", trace_.polarity() == TubePolarity::Dark ? "dark" : "bright"},
                {"has_result", trace_.hasResult()}};
  j["surface"] = {{"level", surface_.level()},
                  {"closed", surface_.closed()},
                  {"planes", surface_.planes()},
                  {"has_result", surface_.hasResult()}};
  nlohmann::json cutPts = nlohmann::json::array();
  for (const Vec3& p : cut_.points()) cutPts.push_back({p.x(), p.y(), p.z()});
  j["cut"] = {
      {"points", cutPts}, {"iso", cut_.iso()}, {"iso_auto", cut_.isoAutomatic()}, {"has_result", cut_.hasResult()}};
  nlohmann::json hidden = nlohmann::json::array();
  for (int l : overlays_.hiddenLabels) hidden.push_back(l);
  nlohmann::json overlayFiles = nlohmann::json::array();
  for (const LoadedOverlay& o : loadedOverlays_) overlayFiles.push_back(o.path);
  j["overlays"] = {{"files", overlayFiles},
                   {"labels", loadedLabelsPath_},
                   {"label_opacity", overlays_.labelOpacity},
                   {"overlay_opacity", overlays_.overlayOpacity},
                   {"hidden_labels", hidden}};
  return j;
}

void ViewerApp::saveSession(const std::string& path) const { writeFileAtomically(path, sessionJson().dump(1) + "\n"); }

void ViewerApp::loadSession(const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readText(path, "session"));
  } catch (const nlohmann::json::exception& e) {
    throw IoError("session " + path + ": not valid JSON (" + e.what() + ")");
  }
  try {
    if (!j.contains("volscissors_session")) throw IoError("session " + path + ": not a volscissors session file");
    std::string vol = j.at("volume").get<std::string>();
    if (vol.rfind(kPhantomSource, 0) != 0 && !std::filesystem::exists(vol)) {
      // A relative volume path is also tried next to the session file.
      const auto beside = std::filesystem::path(path).parent_path() / vol;
      if (std::filesystem::exists(beside)) vol = beside.string();
    }
    load(vol, j.value("orientation", std::string()));
    const auto& v = j.at("view");
    setMode(renderModeFromName(v.at("mode").get<std::string>()));
    if (v.at("tf").get<std::string>() == kEditedTf)
      setEditedTransferFunction(TransferFunction::fromJson(j.at("transfer_function").dump(), path));
    else
      setTransferFunction(v.at("tf").get<std::string>());
    setOrbit(v.at("azimuth_deg").get<double>(), v.at("elevation_deg").get<double>());
    setZoom(v.at("zoom").get<double>());
    const auto pan = v.value("pan_mm", std::array<double, 2>{0, 0});  // sessions before the pan have none
    setPan(pan[0], pan[1]);
    setWindow(v.at("window").get<double>(), v.at("level").get<double>());
    setCursor(v.at("cursor").get<Index3>());
    setMonoAxis(v.at("mono_axis").get<int>());
    setStereo(stereoFromName(v.at("stereo").get<std::string>()));
    setStereoParameters(v.at("eye_separation").get<double>(), v.at("convergence").get<double>());
    setJitter(v.at("jitter").get<bool>());
    setShading(v.at("shading").get<bool>());
    const auto zooms = v.at("slice_zoom").get<std::array<double, 3>>();
    setSlicePlanesIn3D(v.value("slice_planes_3d", true));  // older sessions have none
    const auto pans = v.at("slice_pan").get<std::array<std::array<double, 2>, 3>>();
    for (int a = 0; a < 3; ++a) setSliceView(a, zooms[size_t(a)], pans[size_t(a)]);
    // Points were stored after snapping: replay them without snapping.
    const auto& lw = j.at("livewire");
    liveWire_.setSlice(lw.at("axis").get<int>(), lw.at("index").get<int64_t>());
    liveWire_.setSnapRadius(0);
    for (const auto& c : lw.at("clicks")) liveWire_.click({c.at(0).get<int64_t>(), c.at(1).get<int64_t>()});
    if (lw.at("closed").get<bool>()) liveWire_.close();
    const auto& tr = j.at("trace");
    for (const auto& p : tr.at("points")) trace_.click(p.get<Index3>());
    trace_.setAutoTerminals(tr.at("auto_terminals").get<int>());
    trace_.setCost(tr.at("cost").get<std::string>(),
                   tr.at("polarity").get<std::string>() == "dark" ? TubePolarity::Dark : TubePolarity::Bright);
    setSnap(j.at("snap").get<double>());
    tool_ = toolFromName(j.at("tool").get<std::string>());
    const auto& sf = j.at("surface");
    surface_.setLevel(sf.at("level").get<int>());
    surface_.setClosed(sf.at("closed").get<bool>());
    const ToolKind keep = tool_;
    const auto& ov = j.at("overlays");
    if (!ov.at("labels").get<std::string>().empty()) loadLabels(ov.at("labels").get<std::string>());
    setLabelOpacity(ov.at("label_opacity").get<double>());
    setOverlayOpacity(ov.at("overlay_opacity").get<double>());
    for (const auto& l : ov.at("hidden_labels")) setLabelVisible(l.get<int>(), false);
    for (const auto& f : ov.at("files")) addOverlay(f.get<std::string>());
    const auto& ct = j.at("cut");
    if (ct.at("iso_auto").get<bool>())
      setCutIso(std::nullopt);
    else
      setCutIso(ct.at("iso").get<double>());
    for (const auto& p : ct.at("points"))
      cut_.click(Vec3(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>()));
    if (ct.at("has_result").get<bool>()) {
      tool_ = ToolKind::Cut;
      run(/*wait=*/true);
    }
    if (tr.at("has_result").get<bool>()) {
      tool_ = ToolKind::Trace;
      run(/*wait=*/true);
    }
    if (sf.at("has_result").get<bool>()) {
      // The mesh is recomputed at its planes; the cursor goes back to where the session had it.
      const Index3 cursor = view_.cursor;
      setCursor(sf.at("planes").get<Index3>());
      tool_ = ToolKind::Surface;
      run(/*wait=*/true);
      setCursor(cursor);
    }
    tool_ = keep;
  } catch (const nlohmann::json::exception& e) {
    throw IoError("session " + path + ": missing or ill-typed field (" + e.what() + ")");
  }
}

}  // namespace vs::viewer
