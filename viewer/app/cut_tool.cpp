#include "app/cut_tool.h"

#include <cstdio>

#include "app/tool_common.h"
#include "cutting/cut.h"
#include "cutting/cut_contour_session.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "meshops/isosurface.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vs::viewer {

namespace {

std::string str(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g,%g,%g)", p.x(), p.y(), p.z());
  return buf;
}

// The iso-surface the live contour runs on, every component of it (built once per iso-value on a
// worker): the points decide which component the cut uses, as in cutVolume.
struct Preview {
  TriMesh mesh;
  double iso = 0;
  MeshCostOptions cost;
};

struct Action {
  bool cut = false;
  Vec3 point{0, 0, 0};
  std::shared_ptr<const CutOutcome> result;
};

}  // namespace

struct CutTool::Impl {
  const VolumeF32* volume = nullptr;
  std::string source;
  CutOptions options;
  bool isoAutomatic = true;
  std::vector<Action> done, undone;
  mutable std::mutex mutex;  // guards the actions, the options' iso and the preview
  std::shared_ptr<const Preview> preview;
  // UI-thread cache of the live contour: the component the points choose, prepared as the cut
  // prepares it, the core's incremental contour on it (cutContour's loop per hover), the last loop.
  std::shared_ptr<const Preview> searched;
  std::shared_ptr<const CutMesh> component;
  std::vector<Vec3> componentPoints;
  std::unique_ptr<CutContourSession> session;
  std::vector<Vec3> loopPoints;
  int64_t loopHover = -2;
  LiveContour loop;
  std::shared_ptr<const Preview> currentPreview() const {
    std::lock_guard<std::mutex> lock(mutex);
    return preview;
  }
  std::shared_ptr<const CutMesh> componentFor(const Preview& p, const std::vector<Vec3>& pts);
  void push(Action a) {
    done.push_back(std::move(a));
    if (done.size() > kUndoDepth) done.erase(done.begin());
    undone.clear();
  }
};

CutTool::CutTool() : impl_(std::make_unique<Impl>()) {}
CutTool::~CutTool() = default;

void CutTool::reset(const VolumeF32* volume, std::string source) {
  Impl& I = *impl_;
  std::lock_guard<std::mutex> lock(I.mutex);
  I.volume = volume;
  I.source = std::move(source);
  I.done.clear();
  I.undone.clear();
  I.preview.reset();
  I.searched.reset();
  I.session.reset();
  I.component.reset();
}

void CutTool::setIso(double iso, bool automatic) {
  VS_REQUIRE(std::isfinite(iso), "cut: the iso-value must be finite");
  Impl& I = *impl_;
  std::lock_guard<std::mutex> lock(I.mutex);
  I.isoAutomatic = automatic;
  if (iso == I.options.iso) return;
  I.options.iso = iso;
  I.preview.reset();
}

double CutTool::iso() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->options.iso;
}

bool CutTool::isoAutomatic() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->isoAutomatic;
}

double CutTool::snapRadiusMm() const { return impl_->options.snapRadiusMm; }

namespace {
CutWeights weightsOf(const CutOptions& o) {
  return {o.surface.wg, o.surface.wc, o.surface.wp, o.surface.wd, o.cost.wg, o.cost.wn, o.cost.wl};
}
}  // namespace

CutWeights defaultCutWeights() { return weightsOf(CutOptions{}); }

const std::vector<CutWeightName>& cutWeightNames() {
  static const std::vector<CutWeightName> names = {
      {"wg", "cutting surface: image term (eq. 15), >= 0", &CutWeights::wg},
      {"wc", "cutting surface: continuity (eq. 15-18), > 0", &CutWeights::wc},
      {"wp", "cutting surface: part depth below the surface's continuation, >= 0", &CutWeights::wp},
      {"wd", "cutting surface: direction share of the image term (eq. 16), 0..1", &CutWeights::wd},
      {"contour-wg", "contour on the mesh: gradient (eq. 13), >= 0", &CutWeights::contourWg},
      {"contour-wn", "contour on the mesh: normal change (eq. 13), >= 0", &CutWeights::contourWn},
      {"contour-wl", "contour on the mesh: length (eq. 13), > 0", &CutWeights::contourWl},
  };
  return names;
}

void CutTool::setWeights(const CutWeights& w) {
  Impl& I = *impl_;
  std::lock_guard<std::mutex> lock(I.mutex);
  CutOptions o = I.options;
  o.surface.wg = w.wg;
  o.surface.wc = w.wc;
  o.surface.wp = w.wp;
  o.surface.wd = w.wd;
  o.cost.wg = w.contourWg;
  o.cost.wn = w.contourWn;
  o.cost.wl = w.contourWl;
  checkCutWeights(o);
  const bool contourChanged =
      o.cost.wg != I.options.cost.wg || o.cost.wn != I.options.cost.wn || o.cost.wl != I.options.cost.wl;
  I.options = o;
  if (contourChanged) I.preview.reset();
}

CutWeights CutTool::weights() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return weightsOf(impl_->options);
}

void CutTool::click(const Vec3& index) {
  Impl& I = *impl_;
  VS_REQUIRE(I.volume, "cut: no volume loaded");
  VS_REQUIRE(I.volume->geometry().containsContinuous(index),
             "cut: point " + str(index) + " is outside the volume " + I.volume->geometry().describe());
  std::lock_guard<std::mutex> lock(I.mutex);
  for (auto it = I.done.rbegin(); it != I.done.rend(); ++it)
    if (!it->cut) {
      VS_REQUIRE(it->point != index, "cut: point " + str(index) + " is the last point");
      break;
    }
  I.push({false, index, nullptr});
}

bool CutTool::undo() {
  Impl& I = *impl_;
  std::lock_guard<std::mutex> lock(I.mutex);
  if (I.done.empty()) return false;
  I.undone.push_back(std::move(I.done.back()));
  I.done.pop_back();
  return true;
}

bool CutTool::redo() {
  Impl& I = *impl_;
  std::lock_guard<std::mutex> lock(I.mutex);
  if (I.undone.empty()) return false;
  I.done.push_back(std::move(I.undone.back()));
  I.undone.pop_back();
  return true;
}

size_t CutTool::undoSteps() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->done.size();
}

size_t CutTool::redoSteps() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->undone.size();
}

std::vector<Vec3> CutTool::points() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<Vec3> out;
  for (const Action& a : impl_->done)
    if (!a.cut) out.push_back(a.point);
  return out;
}

void CutTool::prepareLiveContour(Progress& progress) {
  Impl& I = *impl_;
  VS_REQUIRE(I.volume, "cut: no volume loaded");
  double iso = 0;
  MeshCostOptions cost;
  {
    std::lock_guard<std::mutex> lock(I.mutex);
    if (I.preview) return;
    iso = I.options.iso;
    cost = I.options.cost;
  }
  IsoSurfaceOptions io;
  io.iso = iso;
  io.largestComponentOnly = false;
  TriMesh mesh = extractIsoSurface(*I.volume, io, progress);
  if (mesh.triangles.empty())
    throw DataError("cut: no surface at iso-value " + std::to_string(iso) + " (choose another with cut-iso)");
  auto p = std::make_shared<Preview>();
  p->mesh = std::move(mesh);
  p->iso = iso;
  p->cost = cost;
  std::lock_guard<std::mutex> lock(I.mutex);
  const MeshCostOptions& now = I.options.cost;
  if (I.options.iso == iso && now.wg == cost.wg && now.wn == cost.wn && now.wl == cost.wl)
    I.preview = std::move(p);  // else the iso or the contour weights changed meanwhile: stale
}

bool CutTool::liveContourReady() const { return impl_->currentPreview() != nullptr; }

// The component of the iso-surface the points choose (cutVolume's keepComponentNearest), prepared
// as the cut prepares it (prepareCutMesh: features, eq. 13 graph); kept while the choice stays.
std::shared_ptr<const CutMesh> CutTool::Impl::componentFor(const Preview& p, const std::vector<Vec3>& pts) {
  if (component && pts == componentPoints) return component;
  std::vector<Vec3> mm;
  for (const Vec3& q : pts) mm.push_back(volume->geometry().indexToWorld(q));
  TriMesh chosen = keepComponentNearest(p.mesh, mm);
  componentPoints = pts;
  if (component && component->mesh.positions == chosen.positions && component->mesh.triangles == chosen.triangles)
    return component;
  session.reset();
  component = std::make_shared<const CutMesh>(prepareCutMesh(*volume, std::move(chosen), p.cost));
  session = std::make_unique<CutContourSession>(*component, volume->geometry(), options.snapRadiusMm);
  loopHover = -2;
  return component;
}

CutTool::LiveContour CutTool::liveContour(const std::optional<Vec3>& hoverIndex) {
  Impl& I = *impl_;
  const std::shared_ptr<const Preview> p = I.currentPreview();
  const std::vector<Vec3> pts = points();
  if (!p || pts.empty()) return {};
  if (p != I.searched) {
    I.searched = p;
    I.session.reset();
    I.component.reset();
  }
  I.componentFor(*p, pts);  // (a new component starts a new session)
  CutContourSession& session = *I.session;
  session.setPoints(pts);  // a click extends the kept searches
  const int64_t hover = hoverIndex ? session.snapVertex(*hoverIndex) : -1;
  if (pts == I.loopPoints && hover == I.loopHover) return I.loop;
  // The loop the cut would use (the core's cutContour, kept incrementally between moves) through
  // the points and, when the stylus is on the surface, the hovered point as the next one.
  LiveContour out;
  auto take = [&out](const CutContourPreview& r) {
    out.path = r.loop.contourMm;
    out.closed = r.closed;
    out.withHover = r.withHover;
  };
  try {
    take(session.preview(hover >= 0 ? hoverIndex : std::nullopt));
  } catch (const Error& e) {
    out.problem = e.what();
    if (hover >= 0 && pts.size() >= 3) {  // the hovered point cannot join: the points' own loop
      try {
        take(session.preview(std::nullopt));
      } catch (const Error&) {
      }
    }
  }
  I.loopPoints = pts;
  I.loopHover = hover;
  I.loop = out;
  return out;
}

void CutTool::run(Progress& progress) {
  Impl& I = *impl_;
  VS_REQUIRE(I.volume, "cut: no volume loaded");
  CutOptions o;
  {
    std::lock_guard<std::mutex> lock(I.mutex);
    o = I.options;
  }
  o.pointsIndex = points();
  CutResult r = cutVolume(*I.volume, o, progress);
  auto out = std::make_shared<CutOutcome>();
  out->iso = o.iso;
  out->labels = std::move(r.split.labels);
  out->contourMm = std::move(r.contourMm);
  out->cuttingSurface = r.surface.mesh();
  out->keptVoxels = r.split.keptVoxels;
  out->cutVoxels = r.split.cutVoxels;
  std::lock_guard<std::mutex> lock(I.mutex);
  I.push({true, {0, 0, 0}, std::move(out)});
}

std::shared_ptr<const CutOutcome> CutTool::result() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  for (auto it = impl_->done.rbegin(); it != impl_->done.rend(); ++it)
    if (it->cut) return it->result;
  return nullptr;
}

bool CutTool::hasResult() const { return result() != nullptr; }

void CutTool::save(const std::string& path) const {
  const std::shared_ptr<const CutOutcome> r = result();
  VS_REQUIRE(r, "cut: nothing to save (run the cut first)");
  const std::string ext = fileExtension(path);
  if (isVolumePath(path)) {
    writeVolume(AnyVolume(r->labels), path);
  } else if (ext == ".vtk" || ext == ".json") {
    Polyline loop;
    loop.points = r->contourMm;
    loop.closed = true;
    writePolylines({loop}, path);
  } else {
    VS_REQUIRE(ext == ".obj" || ext == ".ply" || ext == ".stl",
               "cut: save " + path +
                   ": use .nii/.nii.gz/.nrrd/.mha (labels), .vtk/.json (contour) or .obj/.ply/.stl (cutting surface)");
    writeTriMesh(r->cuttingSurface, path);
  }
}

}  // namespace vs::viewer
