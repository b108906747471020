#include "cutting/cut_contour_session.h"

#include <algorithm>

#include "util/error.h"

namespace vs {

// The masks are referenced by the searches (spans): they live here, at fixed addresses, and change
// only right before the search that reads them restarts.
struct CutContourSession::Searches {
  MeshSnapper snapper;
  std::vector<uint8_t> liveMask, closingMask, retryMask;
  std::optional<ShortestPathSearch> live;     // from the last placed point (its segment's first search)
  std::optional<ShortestPathSearch> closing;  // from the first point (the closing segment's first search)
  std::vector<uint8_t> onLive;                // scratch: the hovered segment's vertices
  Searches(const CutMesh& m, double radiusMm)
      : snapper(m.mesh, m.features, radiusMm),
        liveMask(m.mesh.positions.size()),
        closingMask(m.mesh.positions.size()),
        retryMask(m.mesh.positions.size()),
        onLive(m.mesh.positions.size(), 0) {}
};

CutContourSession::CutContourSession(const CutMesh& mesh, const Geometry& geometry, double snapRadiusMm)
    : mesh_(&mesh), geometry_(geometry), snapRadiusMm_(snapRadiusMm) {
  VS_REQUIRE(mesh.graph.nodeCount() == int64_t(mesh.mesh.positions.size()) && mesh.graph.nodeCount() > 0,
             "cut contour: the mesh is not prepared (prepareCutMesh)");
  searches_ = std::make_unique<Searches>(mesh, snapRadiusMm);
  onLoop_.assign(mesh.mesh.positions.size(), 0);
}

CutContourSession::~CutContourSession() = default;

int64_t CutContourSession::snapVertex(const Vec3& index) const {
  return searches_->snapper.vertexNear(geometry_.indexToWorld(index));
}

void CutContourSession::restart() {
  points_.clear();
  snaps_.clear();
  segments_.clear();
  std::fill(onLoop_.begin(), onLoop_.end(), 0);
  committed_.reset();
  exact_ = true;
  lastHover_ = -1;
  last_ = {};
}

void CutContourSession::setPoints(const std::vector<Vec3>& pts) {
  const bool appended = pts.size() == points_.size() + 1 && std::equal(points_.begin(), points_.end(), pts.begin());
  if (pts == points_) return;
  if (!appended) {
    restart();
    for (const Vec3& p : pts) addPoint(p);
    return;
  }
  addPoint(pts.back());
}

void CutContourSession::addPoint(const Vec3& index) {
  Searches& S = *searches_;
  const size_t k = points_.size();  // the new point's number - 1
  points_.push_back(index);
  lastHover_ = -1;
  committed_.reset();
  if (!exact_) return;
  const int64_t a = S.snapper.vertexNear(geometry_.indexToWorld(index));
  const bool repeated = std::any_of(snaps_.begin(), snaps_.end(), [a](const MeshSnap& s) { return s.vertex == a; });
  if (a < 0 || repeated || onLoop_[size_t(a)]) {  // cutContour's errors, or a point on the drawn contour
    exact_ = false;
    return;
  }
  const MeshSnap snap{a, (mesh_->mesh.positions[size_t(a)] - geometry_.indexToWorld(index)).norm()};
  if (k > 0) {
    const Path segment = S.live->pathTo(a);
    if (segment.empty()) {
      exact_ = false;
      return;
    }
    if (k >= 2) {  // the placed points' own loop: its closing segment is read from the closing search kept so far
      bool retried = false;
      committed_ = compose(segment, S.closing->pathTo(a), snap, retried);
    }
    segments_.push_back(segment);
    for (int64_t v : segment.nodes) onLoop_[size_t(v)] = 1;
  }
  snaps_.push_back(snap);
  // The searches for the next point: from this point and from the first, around the drawn segments.
  for (size_t v = 0; v < onLoop_.size(); ++v) S.liveMask[v] = S.closingMask[v] = uint8_t(!onLoop_[v]);
  S.liveMask[size_t(a)] = 1;
  if (S.live)
    S.live->restart({a});
  else
    S.live.emplace(contourSegmentSearch(mesh_->graph, a, S.liveMask));
  if (k >= 1) {
    const int64_t first = snaps_.front().vertex;
    S.closingMask[size_t(first)] = 1;
    if (S.closing)
      S.closing->restart({first});
    else
      S.closing.emplace(contourSegmentSearch(mesh_->graph, first, S.closingMask));
    // The next hover lies near this point: settle the closing search that far now (a click may
    // take longer than a move). Settling until a node is what a read-out does, so the search
    // stays the one closedContour runs.
    if (committed_) {
      const std::vector<int64_t>& loop = committed_->contour.vertices;  // ..., this point, the closing path
      for (auto it = std::find(loop.begin(), loop.end(), a); it != loop.end(); ++it)
        if (S.closingMask[size_t(*it)]) {
          S.closing->settleUntil(*it);
          break;
        }
    }
  }
}

std::optional<CutContour> CutContourSession::compose(const Path& live, Path closing, const MeshSnap& end,
                                                     bool& retried) {
  Searches& S = *searches_;
  if (closing.empty()) return std::nullopt;
  // Does the closing path (first point -> end) touch the segment to the end (last point -> end)?
  for (int64_t v : live.nodes) S.onLive[size_t(v)] = 1;
  bool touches = false;
  for (size_t k = 1; k + 1 < closing.nodes.size(); ++k) touches |= S.onLive[size_t(closing.nodes[k])] != 0;
  for (int64_t v : live.nodes) S.onLive[size_t(v)] = 0;
  retried = touches;
  if (touches) {
    S.retryMask = S.closingMask;
    for (int64_t v : live.nodes) S.retryMask[size_t(v)] = 0;
    S.retryMask[size_t(end.vertex)] = 1;
    closing = contourSegmentRetry(mesh_->graph, snaps_.front().vertex, end.vertex, S.retryMask);
    if (closing.empty()) return std::nullopt;
  }
  std::reverse(closing.nodes.begin(), closing.nodes.end());
  CutContour out;
  MeshContour& c = out.contour;
  for (const MeshSnap& s : snaps_) c.anchors.push_back(s.vertex), out.snapDistanceMm.push_back(s.distanceMm);
  c.anchors.push_back(end.vertex);
  out.snapDistanceMm.push_back(end.distanceMm);
  auto append = [&c](const Path& p) {  // each segment but its end, which the next one starts from
    c.vertices.insert(c.vertices.end(), p.nodes.begin(), p.nodes.end() - 1);
    c.lengthMm += p.lengthMm;
    c.cost += p.cost;
  };
  for (const Path& p : segments_) append(p);
  append(live);
  append(closing);
  for (int64_t v : c.vertices) out.contourMm.push_back(mesh_->mesh.positions[size_t(v)]);
  return out;
}

CutContourPreview CutContourSession::fromScratch(const std::optional<Vec3>& hoverIndex) {
  // cutContour's steps with the session's snaps (MeshSnapper answers as snapToMesh, the same
  // errors in the same order): the points' snaps, then closedContour.
  std::vector<MeshSnap> snaps = snaps_;
  for (size_t i = snaps.size(); i < points_.size(); ++i)
    snaps.push_back(searches_->snapper.snap(geometry_.indexToWorld(points_[i]), "point " + std::to_string(i + 1)));
  if (hoverIndex)
    snaps.push_back(
        searches_->snapper.snap(geometry_.indexToWorld(*hoverIndex), "point " + std::to_string(snaps.size() + 1)));
  CutContourPreview out;
  out.loop = cutContourOfSnaps(*mesh_, snaps);
  out.closed = true;
  out.withHover = hoverIndex.has_value();
  return out;
}

CutContourPreview CutContourSession::preview(const std::optional<Vec3>& hoverIndex) {
  Searches& S = *searches_;
  const size_t n = points_.size() + (hoverIndex ? 1 : 0);
  if (n < 2) return {};
  if (n == 2) {  // one open segment: the first search from the first point
    CutContourPreview out;
    out.withHover = hoverIndex.has_value();
    const Vec3 endIndex = hoverIndex ? *hoverIndex : points_.back();
    const int64_t from = S.snapper.vertexNear(geometry_.indexToWorld(points_.front()));
    const int64_t to = S.snapper.vertexNear(geometry_.indexToWorld(endIndex));
    if (from < 0 || to < 0) return {};
    if (!exact_) return out;
    const Path path = hoverIndex ? S.live->pathTo(to) : segments_.front();  // (the live search is from the first point)
    out.loop.contour.vertices = path.nodes;
    out.loop.contour.lengthMm = path.lengthMm;
    out.loop.contour.cost = path.cost;
    for (int64_t v : path.nodes) out.loop.contourMm.push_back(mesh_->mesh.positions[size_t(v)]);
    return out;
  }
  if (!hoverIndex) {
    if (exact_ && committed_) return {*committed_, true, false};
    return fromScratch(std::nullopt);
  }
  ++stats_.previews;
  if (!exact_) {
    ++stats_.fromScratch;
    return fromScratch(hoverIndex);
  }
  // cutContour snaps the points in order; the placed ones snapped, so the hovered one's error is
  // the first it would throw.
  const MeshSnap end = S.snapper.snap(geometry_.indexToWorld(*hoverIndex), "point " + std::to_string(n));
  if (end.vertex == lastHover_) {
    ++stats_.cached;
    last_.loop.snapDistanceMm.back() = end.distanceMm;
    return last_;
  }
  const int64_t h = end.vertex;
  for (size_t j = 0; j < snaps_.size(); ++j)  // closedContour's first check (the placed points differ)
    if (snaps_[j].vertex == h) throw DataError(contourSameVertexError(j, snaps_.size()));
  std::optional<CutContour> loop;
  bool retried = false;
  if (!onLoop_[size_t(h)]) {  // (a hover on the drawn contour changes the segments it lies on)
    const Path live = S.live->pathTo(h);
    if (!live.empty()) loop = compose(live, S.closing->pathTo(h), end, retried);
  }
  if (!loop) {
    ++stats_.fromScratch;
    return fromScratch(hoverIndex);  // throws closedContour's error, or (a point on the contour) draws its loop
  }
  ++(retried ? stats_.closingRetries : stats_.readOuts);
  lastHover_ = h;
  last_ = {std::move(*loop), true, true};
  return last_;
}

}  // namespace vs
