#include "app/tools.h"

#include <algorithm>

#include "features/vesselness.h"
#include "io/contour_io.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "scissors/live_wire_document.h"
#include "tracking/trace_run.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "volume/slice.h"

namespace vs::viewer {

bool isVolumePath(const std::string& path) { return isVolumeWritePath(path); }  // io/volume_io.h's one list

namespace {

std::string str(const Index3& p) {
  return "(" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + ")";
}

std::string str(const PixelUV& p) { return "(" + std::to_string(p[0]) + "," + std::to_string(p[1]) + ")"; }

}  // namespace

// ---------------------------------------------------------------- live-wire

void LiveWireTool::reset(const AnyVolume* volume, std::string source) {
  volume_ = volume;
  source_ = std::move(source);
  wire_.reset();
  done_.clear();
  undone_.clear();
  clicks_.clear();
  live_.clear();
  axis_ = 2;
  index_ = volume ? geometryOf(*volume).dims[2] / 2 : 0;
}

void LiveWireTool::setSlice(int axis, int64_t index) {
  VS_REQUIRE(volume_, "live-wire: no volume loaded");
  VS_REQUIRE(axis >= 0 && axis <= 2, "live-wire: slice axis must be x, y or z");
  const Geometry& g = geometryOf(*volume_);
  VS_REQUIRE(index >= 0 && index < g.dims[axis],
             "live-wire: slice " + describeSlice(axis, index) + " is outside 0.." + std::to_string(g.dims[axis] - 1));
  if (axis == axis_ && index == index_) return;
  VS_REQUIRE(clicks_.empty(), "live-wire: a contour is in progress on " + describeSlice(axis_, index_) +
                                  "; save or undo it before moving the tool to another slice");
  axis_ = axis;
  index_ = index;
  wire_.reset();
  live_.clear();
  undone_.clear();  // redo would replay points of the old slice
}

void LiveWireTool::setSnapRadius(double px) {
  VS_REQUIRE(std::isfinite(px) && px >= 0 && px <= 50, "snap radius must be in 0..50 pixels");
  snap_ = px;
}

LiveWire& LiveWireTool::wire() {
  VS_REQUIRE(volume_, "live-wire: no volume loaded");
  if (!wire_)
    wire_ = std::make_unique<LiveWire>(
        liveWireOnSlice(*volume_, axis_, index_, options_, describeSlice(axis_, index_) + " of " + source_));
  return *wire_;
}

int64_t LiveWireTool::width() const {
  const Geometry& g = geometryOf(*volume_);
  return axis_ == 0 ? g.dims[1] : g.dims[0];
}

int64_t LiveWireTool::height() const {
  const Geometry& g = geometryOf(*volume_);
  return axis_ == 2 ? g.dims[1] : g.dims[2];
}

PixelUV LiveWireTool::snap(PixelUV p) {
  LiveWire& w = wire();
  VS_REQUIRE(w.contains(p), "live-wire: point " + str(p) + " is outside the " + std::to_string(w.width()) + "x" +
                                std::to_string(w.height()) + " " + describeSlice(axis_, index_));
  return snap_ > 0 ? w.snap(p, snap_) : p;
}

const std::vector<PixelUV>& LiveWireTool::hover(PixelUV p) {
  LiveWire& w = wire();
  if (!w.hasSeed() || w.closed() || !w.contains(p)) {
    live_.clear();
    return live_;
  }
  const size_t segments = w.segments().size();
  live_ = w.pathTo(snap(p));
  // Path cooling froze a stable part of the path: each frozen segment is an action of its own.
  for (size_t k = segments; k < w.segments().size(); ++k)
    record({Action::Kind::Cool, w.segments()[k].to, nullptr, nullptr});
  if (w.segments().size() != segments) refreshAnchors();
  return live_;
}

void LiveWireTool::apply(const Action& a) {
  LiveWire& w = wire();
  if (a.kind == Action::Kind::Close)
    w.close();
  else if (a.kind == Action::Kind::Edit)
    w.restore(*a.after);
  else if (!w.hasSeed())
    w.setSeed(a.p);
  else
    w.commit(a.p);
  live_.clear();
  refreshAnchors();
}

void LiveWireTool::record(Action a) {
  done_.push_back(std::move(a));
  if (done_.size() > kUndoDepth) {
    // Too deep to undo further: the oldest action stays applied, only its undo entry goes.
    done_.erase(done_.begin());
  }
  undone_.clear();
}

void LiveWireTool::refreshAnchors() { clicks_ = wire_ ? wire_->contour().anchors : std::vector<PixelUV>{}; }

void LiveWireTool::click(PixelUV p) {
  LiveWire& w = wire();
  VS_REQUIRE(!w.closed(), "live-wire: the contour is closed; undo the close to add points");
  const PixelUV q = snap(p);
  VS_REQUIRE(!w.hasSeed() || q != w.seed(),
             "live-wire: point " + str(p) + (q != p ? " (snapped to " + str(q) + ")" : "") + " is the current anchor");
  const Action a{Action::Kind::Click, q, nullptr, nullptr};
  apply(a);
  record(a);
}

void LiveWireTool::close() {
  LiveWire& w = wire();
  VS_REQUIRE(!w.closed(), "live-wire: the contour is already closed");
  VS_REQUIRE(clicks_.size() >= 3,
             "live-wire: closing needs at least 3 points, the contour has " + std::to_string(clicks_.size()));
  const Action a{Action::Kind::Close, {}, nullptr, nullptr};
  apply(a);
  record(a);
}

bool LiveWireTool::undo() {
  if (done_.empty()) return false;
  const Action a = done_.back();
  done_.pop_back();
  if (a.kind == Action::Kind::Edit)
    wire().restore(*a.before);
  else
    wire().undo();
  undone_.push_back(a);
  live_.clear();
  refreshAnchors();
  return true;
}

bool LiveWireTool::redo() {
  if (undone_.empty()) return false;
  const Action a = undone_.back();
  undone_.pop_back();
  apply(a);
  done_.push_back(a);
  return true;
}

LiveWireContour LiveWireTool::contour() const {
  if (!wire_) return {};
  return wire_->contour();
}

ContourDocument LiveWireTool::document() const {
  VS_REQUIRE(wire_ && wire_->hasSeed() && !wire_->segments().empty(),
             "live-wire: nothing to save (the contour needs at least 2 points)");
  // The CLI's and Python's document (scissors/live_wire_document.h), every key of io/contour_io's schema.
  return contourDocument(*wire_, geometryOf(*volume_), axis_, index_, {clicks_, {}, snap_}, source_);
}

void LiveWireTool::save(const std::string& path) const {
  const ContourDocument doc = document();  // validates that there is a contour
  if (fileExtension(path) == ".json") {
    writeContour(doc, path);  // io/contour_io.h
    return;
  }
  VS_REQUIRE(isVolumePath(path), "live-wire: save " + path + ": use .json (contour) or .nii/.nii.gz/.nrrd/.mha (mask)");
  const LiveWireContour c = wire_->contour();
  VS_REQUIRE(c.closed, "live-wire: a mask needs a closed contour (close it first)");
  const std::vector<uint8_t> mask = fillContour(c.pixels, wire_->width(), wire_->height());
  writeVolume(AnyVolume(sliceMaskVolume(geometryOf(*volume_), axis_, index_, mask, wire_->width(), wire_->height())),
              path);  // volume/slice.h's paste of a slice mask
}

// ---------------------------------------------------------------- tracking

void TraceTool::reset(const VolumeF32* volume, std::string source) {
  volume_ = volume;
  source_ = std::move(source);
  points_.clear();
  undone_.clear();
  autoTerminals_ = 0;
  session_.reset();
  std::lock_guard<std::mutex> lock(mutex_);
  published_.clear();
  used_.clear();
  tree_ = Tree();
  labels_ = VolumeU16();
  hasResult_ = false;
}

void TraceTool::click(const Index3& p) {
  VS_REQUIRE(volume_, "trace: no volume loaded");
  VS_REQUIRE(volume_->geometry().contains(p),
             "trace: point " + str(p) + " is outside the volume " + volume_->geometry().describe());
  for (size_t i = 0; i < points_.size(); ++i)
    VS_REQUIRE(points_[i] != p, "trace: point " + str(p) + (i == 0 ? " is the root" : " is already a target"));
  points_.push_back(p);
  undone_.clear();
}

bool TraceTool::undo() {
  if (points_.empty()) return false;
  undone_.push_back(points_.back());
  points_.pop_back();
  clearResult();  // the tree was traced with the point just removed: run again for the new one
  return true;
}

void TraceTool::clearResult() {
  if (session_) session_->restart();  // the next run starts a fresh search (the costs stay)
  std::lock_guard<std::mutex> lock(mutex_);
  published_.clear();
  used_.clear();
  tree_ = Tree();
  labels_ = VolumeU16();
  hasResult_ = false;
}

bool TraceTool::redo() {
  if (undone_.empty()) return false;
  points_.push_back(undone_.back());
  undone_.pop_back();
  return true;
}

void TraceTool::setAutoTerminals(int count) {
  VS_REQUIRE(count >= 0 && count <= 1000, "trace: automatic terminals must be in 0..1000");
  autoTerminals_ = count;
}

void TraceTool::setCost(const std::string& kind, TubePolarity polarity) {
  VS_REQUIRE(kind == "auto" || kind == "gradient" || kind == "vesselness" || kind == "intensity",
             "trace: cost '" + kind + "' is not one the viewer computes (auto, gradient, vesselness, intensity)");
  if (kind == options_.cost && polarity == polarity_) return;
  options_.cost = kind;
  polarity_ = polarity;
  session_.reset();
}

std::vector<Index3> TraceTool::usedPoints() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return used_;
}

void TraceTool::run(Progress& progress) { runSearch(progress); }

void TraceTool::runSearch(Progress& progress) {
  VS_REQUIRE(volume_, "trace: no volume loaded");
  VS_REQUIRE(!points_.empty(), "trace: give the root first (point x,y,z)");
  VS_REQUIRE(points_.size() >= 2 || autoTerminals_ > 0, "trace: give at least one target or automatic terminals");
  if (!session_) {
    TraceRequest config;  // the CLI's defaults, with this tool's cost kind and polarity
    config.options = options_;
    config.cost.polarity = polarity_;
    config.volumeName = source_.empty() ? "trace volume" : source_;
    session_ = std::make_unique<TraceSession>(*volume_, config);
  }
  const std::vector<Index3> targets(points_.begin() + 1, points_.end());
  auto publish = [&](const std::vector<TracedPath>& paths) {  // first call: the paths kept (none: a fresh search)
    std::lock_guard<std::mutex> lock(mutex_);
    published_ = paths;
    if (paths.empty()) hasResult_ = false;
  };
  TraceSession::Outcome out =
      session_->resume(points_[0], targets, autoTerminals_ > 0 ? autoTerminals_ : -1, progress, publish);
  std::lock_guard<std::mutex> lock(mutex_);
  published_ = std::move(out.paths);
  used_ = std::move(out.used);
  tree_ = std::move(out.tree);
  labels_ = std::move(out.labels);
  hasResult_ = true;
}

std::vector<TracedPath> TraceTool::paths() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

Tree TraceTool::tree() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tree_;
}

bool TraceTool::hasResult() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return hasResult_;
}

void TraceTool::save(const std::string& path) const {
  std::lock_guard<std::mutex> lock(mutex_);
  VS_REQUIRE(hasResult_ && tree_.size() > 0, "trace: nothing to save (run the trace first)");
  const std::string ext = fileExtension(path);
  if (ext == ".swc" || ext == ".vtk" || ext == ".json") {
    writeTree(tree_, path);
  } else {
    VS_REQUIRE(isVolumePath(path),
               "trace: save " + path + ": use .swc/.vtk/.json (tree) or .nii/.nii.gz/.nrrd/.mha (labels)");
    writeVolume(AnyVolume(labels_), path);
  }
}

}  // namespace vs::viewer
