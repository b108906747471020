// The surface tool (thesis 4.3.1 and 5.2): extraction from three planes through the cursor, with
// the thesis's interface: corners moved, a side contour chosen and made to pass through via
// points, re-subdivided incrementally (surface/surface.h SurfaceExtraction::editSide).
#include <algorithm>
#include <limits>

#include "app/tools.h"
#include "io/mesh_io.h"
#include "util/error.h"

namespace vs::viewer {

namespace {

std::vector<Index3> viaOf(const std::vector<std::pair<std::string, std::vector<Index3>>>& via,
                          const std::string& side) {
  for (const auto& [name, pts] : via)
    if (name == side) return pts;
  return {};
}

// Everything but the via points: equal bases allow an incremental edit of the sides.
bool sameBase(const SurfaceOptions& a, const SurfaceOptions& b) {
  return a.planes == b.planes && a.level == b.level && a.closed == b.closed && a.octant == b.octant &&
         a.corners == b.corners;
}

}  // namespace

std::string SurfaceTool::halfLineName(int h) {
  VS_REQUIRE(h >= 0 && h < 6, "surface: half-line " + std::to_string(h) + " is not 0..5");
  return std::string(h % 2 ? "-" : "+") + "xyz"[h / 2];
}

int SurfaceTool::halfLineFromName(const std::string& name) {
  for (int h = 0; h < 6; ++h)
    if (name == halfLineName(h)) return h;
  throw UsageError("surface: corner '" + name + "' is not one of +x -x +y -y +z -z");
}

void SurfaceTool::reset(const VolumeF32* volume, std::string source) {
  std::lock_guard<std::mutex> lock(mutex_);
  volume_ = volume;
  source_ = std::move(source);
  done_.clear();
  undone_.clear();
  cornerOverrides_ = {};
  via_.clear();
  extraction_.reset();
}

void SurfaceTool::setLevel(int level) {
  VS_REQUIRE(level >= 0 && level <= 8, "surface: level must be in 0..8");
  level_ = level;
}

void SurfaceTool::setCorner(int halfLine, const Index3& p) {
  halfLineName(halfLine);  // validates
  std::lock_guard<std::mutex> lock(mutex_);
  cornerOverrides_[size_t(halfLine)] = p;
}

void SurfaceTool::clearCorners() {
  std::lock_guard<std::mutex> lock(mutex_);
  cornerOverrides_ = {};
}

void SurfaceTool::selectSide(const std::string& side) {
  for (int k = 0; k < 3; ++k)
    for (const int a : {1, -1})
      for (const int b : {1, -1})
        if (side == sideName(k, a, b)) {
          side_ = side;
          return;
        }
  throw UsageError("surface: side '" + side + "' is not a side contour such as z+x+y (plane z, x >= x0, y >= y0)");
}

void SurfaceTool::addVia(const Index3& p) {
  VS_REQUIRE(volume_ && volume_->geometry().contains(p), "surface: via point outside the volume");
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Index3> path = done_.empty() ? std::vector<Index3>{} : viaOf(done_.back().sides, side_);
  // Where along the side's current path a point lies: the index of its nearest path voxel.
  auto along = [&](const Index3& q) {
    size_t best = 0;
    double bestD = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < path.size(); ++i) {
      double d = 0;
      for (int a = 0; a < 3; ++a)
        d += double(path[i][size_t(a)] - q[size_t(a)]) * double(path[i][size_t(a)] - q[size_t(a)]);
      if (d < bestD) bestD = d, best = i;
    }
    return best;
  };
  auto it = std::find_if(via_.begin(), via_.end(), [&](const auto& e) { return e.first == side_; });
  if (it == via_.end()) it = via_.insert(via_.end(), {side_, {}});
  auto& pts = it->second;
  VS_REQUIRE(std::find(pts.begin(), pts.end(), p) == pts.end(), "surface: that via point is already on the side");
  pts.push_back(p);
  std::stable_sort(pts.begin(), pts.end(), [&](const Index3& a, const Index3& b) { return along(a) < along(b); });
}

void SurfaceTool::clearVia() {
  std::lock_guard<std::mutex> lock(mutex_);
  via_.erase(std::remove_if(via_.begin(), via_.end(), [&](const auto& e) { return e.first == side_; }), via_.end());
}

std::vector<Index3> SurfaceTool::via(const std::string& side) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return viaOf(via_, side);
}

SurfaceOptions SurfaceTool::options(const Index3& planes) const {
  SurfaceOptions o;
  o.planes = planes;
  o.level = level_;
  o.closed = closed_;
  o.corners = cornerOverrides_;
  for (const auto& [side, pts] : via_)
    if (!pts.empty()) o.via.push_back({side, pts});
  return o;
}

void SurfaceTool::run(const Index3& planes, Progress& progress) {
  VS_REQUIRE(volume_, "surface: no volume loaded");
  SurfaceOptions o;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    o = options(planes);
  }
  std::string what = "extracted";
  try {
    if (extraction_ && sameBase(extractionOptions_, o)) {
      // Only via points changed: re-wire those sides, re-subdivide only their octants.
      std::vector<std::string> changed;
      for (const auto* list : {&o.via, &extractionOptions_.via})
        for (const auto& [side, pts] : *list)
          if (viaOf(o.via, side) != viaOf(extractionOptions_.via, side) &&
              std::find(changed.begin(), changed.end(), side) == changed.end())
            changed.push_back(side);
      if (changed.empty()) what = "unchanged (nothing to re-compute)";
      int64_t octants = 0, paths = 0;
      for (const std::string& side : changed) {
        const SurfaceEditReport rep = extraction_->editSide(side, viaOf(o.via, side), progress);
        auto& via = extractionOptions_.via;
        via.erase(std::remove_if(via.begin(), via.end(), [&](const auto& e) { return e.first == side; }), via.end());
        if (!viaOf(o.via, side).empty()) via.push_back({side, viaOf(o.via, side)});
        octants += int64_t(rep.octants.size());
        paths += rep.paths;
      }
      if (!changed.empty())
        what = "side " + changed.front() + (changed.size() > 1 ? " and others" : "") +
               " edited: " + std::to_string(octants) + " octant" + (octants == 1 ? "" : "s") + " re-subdivided, " +
               std::to_string(paths) + " paths";
    } else {
      extraction_.reset();
      extraction_ = std::make_shared<SurfaceExtraction>(*volume_, o, progress);
      extractionOptions_ = o;
    }
  } catch (const DataError& e) {
    // The core names the CLI's remedy (--corners); say the viewer's own.
    std::string m = e.what();
    const std::string cli = "move the planes or give --corners";
    if (const auto at = m.find(cli); at != std::string::npos)
      m.replace(at, cli.size(), "move the crosshair (the three planes' common point) into the object");
    throw DataError("surface: " + m);
  }
  const SurfaceResult& res = extraction_->result();
  if (res.mesh.triangles.empty()) throw DataError("surface: the extraction gave no triangles");
  Result r{planes, res.mesh, res.corners, o.corners, res.sides, o.via, o.level, o.closed, what};
  std::lock_guard<std::mutex> lock(mutex_);
  done_.push_back(std::move(r));
  if (done_.size() > kUndoDepth) done_.erase(done_.begin());
  undone_.clear();
}

bool SurfaceTool::undo() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (done_.empty()) return false;
  undone_.push_back(std::move(done_.back()));
  done_.pop_back();
  // The corners and via points of what is shown now are those the next run starts from.
  cornerOverrides_ = done_.empty() ? std::array<std::optional<Index3>, 6>{} : done_.back().cornerOverrides;
  via_ = done_.empty() ? decltype(via_){} : done_.back().via;
  return true;
}

bool SurfaceTool::redo() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (undone_.empty()) return false;
  done_.push_back(std::move(undone_.back()));
  undone_.pop_back();
  cornerOverrides_ = done_.back().cornerOverrides;
  via_ = done_.back().via;
  return true;
}

size_t SurfaceTool::undoSteps() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.size();
}

bool SurfaceTool::hasResult() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !done_.empty();
}

TriMesh SurfaceTool::mesh() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.empty() ? TriMesh() : done_.back().mesh;
}

Index3 SurfaceTool::planes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.empty() ? Index3{-1, -1, -1} : done_.back().planes;
}

std::array<std::optional<Index3>, 6> SurfaceTool::corners() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.empty() ? std::array<std::optional<Index3>, 6>{} : done_.back().corners;
}

std::vector<std::pair<std::string, std::vector<Index3>>> SurfaceTool::sides() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.empty() ? decltype(done_.back().sides){} : done_.back().sides;
}

std::string SurfaceTool::lastRun() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_.empty() ? std::string() : done_.back().what;
}

void SurfaceTool::save(const std::string& path) const {
  const TriMesh m = mesh();
  VS_REQUIRE(!m.triangles.empty(), "surface: nothing to save (run the extraction first)");
  writeTriMesh(m, path);
}

}  // namespace vs::viewer
