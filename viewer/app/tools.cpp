#include "app/tools.h"

#include <algorithm>

#include "features/vesselness.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "tracking/trace_run.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vs::viewer {

bool isVolumePath(const std::string& path) {
  const std::string ext = fileExtension(path);
  return ext == ".nii" || ext == ".nii.gz" || ext == ".nrrd" || ext == ".nhdr" || ext == ".mha" || ext == ".mhd";
}

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
    wire_ = std::make_unique<LiveWire>(std::visit(
        [&](const auto& v) {
          return LiveWire::fromSlice(sliceView(v, axis_, index_), options_,
                                     describeSlice(axis_, index_) + " of " + source_);
        },
        *volume_));
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

nlohmann::json LiveWireTool::resultJson() const {
  VS_REQUIRE(wire_ && wire_->hasSeed() && !wire_->segments().empty(),
             "live-wire: nothing to save (the contour needs at least 2 points)");
  const LiveWire& w = *wire_;
  const Geometry& geom = geometryOf(*volume_);
  const LiveWireContour c = w.contour();
  auto uvList = [](const std::vector<PixelUV>& px) {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& p : px) arr.push_back({p[0], p[1]});
    return arr;
  };
  nlohmann::json j;
  j["file"] = source_;
  j["slice"] = {{"axis", std::string(1, "xyz"[axis_])},
                {"index", index_},
                {"width", w.width()},
                {"height", w.height()},
                {"spacing_mm", {w.features().spacingU, w.features().spacingV}}};
  j["cost_kind"] = liveWireCostKindName(options_.cost.kind);
  j["weights"] = {{"zero_crossing", options_.cost.weightZ},
                  {"gradient", options_.cost.weightG},
                  {"direction", options_.cost.weightD}};
  j["smooth_mm"] = options_.features.smoothSigmaMm;
  j["snap_px"] = snap_;
  j["closed"] = c.closed;
  j["points"] = uvList(c.pixels);
  nlohmann::json idx = nlohmann::json::array(), world = nlohmann::json::array();
  for (const auto& p : c.pixels) {
    const Index3 i = sliceToVolumeIndex(axis_, index_, p);
    idx.push_back({i[0], i[1], i[2]});
    const Vec3 wpt = geom.indexToWorld(Vec3(double(i[0]), double(i[1]), double(i[2])));
    world.push_back({wpt.x(), wpt.y(), wpt.z()});
  }
  j["points_index"] = std::move(idx);
  j["points_world"] = std::move(world);
  j["clicks"] = uvList(clicks_);
  j["length_mm"] = c.lengthMm;
  j["cost"] = c.cost;
  nlohmann::json segs = nlohmann::json::array();
  for (const auto& s : w.segments())
    segs.push_back({{"from", {s.from[0], s.from[1]}},
                    {"to", {s.to[0], s.to[1]}},
                    {"pixels", s.pixels.size()},
                    {"cost", s.cost},
                    {"length_mm", s.lengthMm}});
  j["segments"] = std::move(segs);
  if (c.closed) {
    const std::vector<uint8_t> mask = fillContour(c.pixels, w.width(), w.height());
    const int64_t area = std::count(mask.begin(), mask.end(), uint8_t{1});
    j["area_pixels"] = area;
    j["area_mm2"] = static_cast<double>(area) * w.features().spacingU * w.features().spacingV;
  }
  return j;
}

void LiveWireTool::save(const std::string& path) const {
  const nlohmann::json j = resultJson();  // validates that there is a contour
  if (fileExtension(path) == ".json") {
    writeFileAtomically(path, j.dump(1) + "\n");
    return;
  }
  VS_REQUIRE(isVolumePath(path), "live-wire: save " + path + ": use .json (contour) or .nii/.nii.gz/.nrrd/.mha (mask)");
  const LiveWireContour c = wire_->contour();
  VS_REQUIRE(c.closed, "live-wire: a mask needs a closed contour (close it first)");
  const std::vector<uint8_t> mask = fillContour(c.pixels, wire_->width(), wire_->height());
  VolumeU8 label(geometryOf(*volume_), 0);
  for (int64_t v = 0; v < wire_->height(); ++v)
    for (int64_t u = 0; u < wire_->width(); ++u)
      if (mask[static_cast<size_t>(u + wire_->width() * v)]) {
        const Index3 i = sliceToVolumeIndex(axis_, index_, {u, v});
        label(i[0], i[1], i[2]) = 1;
      }
  writeVolume(AnyVolume(std::move(label)), path);
}

// ---------------------------------------------------------------- tracking

void TraceTool::reset(const VolumeF32* volume, std::string source) {
  volume_ = volume;
  source_ = std::move(source);
  points_.clear();
  undone_.clear();
  autoTerminals_ = 0;
  cost_.reset();
  costRoot_ = {-1, -1, -1};
  lumen_ = VolumeF32();
  tracker_.reset();
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
  tracker_.reset();  // the next run starts a fresh search (the costs stay)
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
  cost_.reset();
  tracker_.reset();
}

std::vector<Index3> TraceTool::usedPoints() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return used_;
}

void TraceTool::run(Progress& progress) {
  try {
    runSearch(progress);
  } catch (...) {
    tracker_.reset();  // a search stopped half-way is not resumed
    throw;
  }
}

void TraceTool::computeCosts(const Index3& root, Progress& progress) {
  progress.report(0.0, "costs");
  const TraceOptions& d = options_;
  if (d.cost == "auto") {
    AutoCost ac = computeAutoCost(*volume_, root, d.autoCost, progress);
    cost_ = std::make_unique<NodeCost3D>(std::move(ac.cost));
    lumen_ = std::move(ac.smoothed);
  } else {
    Cost3DOptions co;
    co.kind = costKindFromName(d.cost);
    co.polarity = polarity_;
    const double smoothMm = d.cost == "intensity" ? d.intensitySmoothMm : d.autoCost.smoothMm;
    co.smoothMm = co.kind == CostKind3D::Intensity ? smoothMm : 0.0;
    cost_ = std::make_unique<NodeCost3D>(computeNodeCost3D(*volume_, co, nullptr, progress));
    if (d.refine) lumen_ = smoothMm > 0 ? gaussianSmooth3D(*volume_, smoothMm, progress) : *volume_;
  }
  costRoot_ = root;
}

Index3 TraceTool::snapIntoLumen(const Index3& p, const std::string& what) const {
  // Costs that mark a lumen (not the gradient's walls) move points outside it into it.
  const bool snaps = options_.snapMm > 0 && options_.cost != "gradient";
  if (!snaps) return p;
  const double lumenCost = lumenCostThreshold(*cost_);
  const float c = cost_->nodeWeight * cost_->node[static_cast<size_t>(volume_->geometry().linear(p[0], p[1], p[2]))];
  if (c <= lumenCost) return p;
  const LumenSnap s = snapToLumen(*cost_, p, options_.snapMm, lumenCost);
  if (!s.found)
    throw DataError("trace: " + what + " " + str(p) + " is outside the lumen and no lumen voxel lies within " +
                    std::to_string(options_.snapMm) + " mm (move it into the vessel/airway)");
  return s.voxel;
}

void TraceTool::runSearch(Progress& progress) {
  VS_REQUIRE(volume_, "trace: no volume loaded");
  VS_REQUIRE(!points_.empty(), "trace: give the root first (point x,y,z)");
  VS_REQUIRE(points_.size() >= 2 || autoTerminals_ > 0, "trace: give at least one target or automatic terminals");
  const std::vector<Index3> requested = points_;
  if (!cost_ || (options_.cost == "auto" && costRoot_ != requested[0])) {
    tracker_.reset();
    computeCosts(requested[0], progress);
  }
  std::vector<Index3> points;
  for (size_t i = 0; i < requested.size(); ++i)
    points.push_back(snapIntoLumen(requested[i], i == 0 ? "root" : "target #" + std::to_string(i)));
  if (!std::isfinite(
          cost_->node[static_cast<size_t>(volume_->geometry().linear(points[0][0], points[0][1], points[0][2]))]))
    throw DataError("trace: root " + str(points[0]) + " lies in an impassable voxel");
  for (size_t i = 1; i < points.size(); ++i)
    if (points[i] == points[0])
      throw DataError("trace: target #" + std::to_string(i) + " " + str(requested[i]) + " snapped onto the root " +
                      str(points[0]) + "; move it");
  // The tracker's search is resumed for new targets of the same root, but its path list only
  // grows: a removed target (undo) or new automatic terminals need a fresh tracker.
  bool fresh = !tracker_ || tracker_->requestedRoot() != points[0] || autoTerminals_ > 0;
  if (!fresh) {
    const auto& old = tracker_->paths();
    fresh = old.size() > points.size() - 1;
    for (size_t i = 0; !fresh && i < old.size(); ++i) fresh = old[i].requested != points[i + 1];
  }
  if (fresh) {
    tracker_.reset();
    std::lock_guard<std::mutex> lock(mutex_);
    published_.clear();
    hasResult_ = false;
  }
  if (!tracker_) tracker_ = std::make_unique<VesselTracker>(*volume_, *cost_, points[0], options_.tracker, progress);
  auto publish = [&] {
    std::lock_guard<std::mutex> lock(mutex_);
    published_ = tracker_->paths();
  };
  for (size_t i = tracker_->paths().size() + 1; i < points.size(); ++i) {
    progress.report(double(i) / double(points.size()), "search");
    const TracedPath& p = tracker_->addTarget(points[i], progress);
    if (!p.reached)
      throw DataError("trace: target " + str(points[i]) + " is not reachable from the root " + str(points[0]));
    publish();
  }
  if (autoTerminals_ > 0) {
    AutoTerminalOptions ao = options_.autoTerminals;
    ao.count = autoTerminals_;
    if (tracker_->autoTerminals(ao, progress).empty())
      throw DataError("trace: no terminal found: no branch of the traced structure adds " +
                      std::to_string(ao.minLengthMm) +
                      " mm beyond the paths so far (check the root, give targets, or choose another cost)");
    publish();
  }
  if (tracker_->paths().empty())
    throw DataError(
        "trace: no path was extracted: the automatic terminals found no branch that stays inside the "
        "structure (try another cost, e.g. intensity for contrast-filled vessels, or give targets)");
  progress.report(0.95, "refine");
  Tree tree;
  if (options_.refine) {
    RefinedCentreline refined = refineCentreline(lumen_, tracker_->centrelineTree(), options_.centreline, progress);
    // As runTrace (the CLI): refined points stay in the lumen, as deep as half its cost level.
    if (costMarksLumen(options_.cost)) tracker_->confineToLumen(refined, 0.5 * lumenCostThreshold(*cost_));
    tree = tracker_->toTree(refined);
  } else {
    tree = tracker_->toTree();
  }
  VolumeU16 labels = tracker_->labelVolume();
  std::lock_guard<std::mutex> lock(mutex_);
  published_ = tracker_->paths();
  used_ = points;
  tree_ = std::move(tree);
  labels_ = std::move(labels);
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
