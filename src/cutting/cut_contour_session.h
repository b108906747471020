// The cut's contour while the user places points (the viewer's cut tool, issue 26): the loop
// cutContour gives for the placed points and the hovered one, kept between mouse moves so that a
// move costs two path read-outs instead of a search per segment.
//
// What is kept (closedContour's rules, mesh_livewire.h, make each piece reusable):
// - the segments between placed points (they depend on the later points only when a later point
//   lies on them: then every preview is computed from scratch);
// - one search from the last placed point (the segment to the hovered vertex is read from it)
//   and one from the first point (the closing segment, searched from the first point towards the
//   hovered one); only when the closing path touches the segment to the hovered vertex is it
//   searched again (one A* search), as closedContour does.
// Every answer is cutContour's for the same points, vertex for vertex, its errors included
// (tests/cutting/cut_contour_session_test.cpp checks it after random hovers, clicks and undos).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cutting/cut_contour.h"

namespace vs {

struct CutContourPreview {
  // closed: cutContour(points [+ hover]) exactly. Else (two points, the hovered one counted) the
  // open segment from the first point to the second: contour.vertices is the path, both ends in.
  CutContour loop;
  bool closed = false;
  bool withHover = false;  // the hovered point is the loop's last point (or the segment's end)
};

// How the previews with a hovered point were made (tests and the bench say how often each way).
struct CutContourSessionStats {
  int64_t previews = 0;        // previews with a hovered point that joined (>= 3 points)
  int64_t readOuts = 0;        // of them, read from the two kept searches alone
  int64_t closingRetries = 0;  // of them, the closing path searched again (it touched the hovered segment)
  int64_t fromScratch = 0;     // of them, cutContour from scratch (a point on the drawn contour, an error)
  int64_t cached = 0;          // of them, the same vertex as the previous hover (nothing searched)
};

class CutContourSession {
 public:
  // `mesh` (prepared as the cut prepares it) must outlive the session.
  CutContourSession(const CutMesh& mesh, const Geometry& geometry, double snapRadiusMm);
  ~CutContourSession();
  CutContourSession(const CutContourSession&) = delete;
  CutContourSession& operator=(const CutContourSession&) = delete;

  // The placed points (continuous voxel indices, loop order). One point appended to the previous
  // ones extends the kept searches (a click); anything else (an undo) starts them over.
  void setPoints(const std::vector<Vec3>& pointsIndex);
  const std::vector<Vec3>& points() const { return points_; }
  // The vertex a point snaps to (snapToMesh's), -1 when it lies farther than the snap radius.
  int64_t snapVertex(const Vec3& index) const;
  // With >= 3 points (the hovered one counted): cutContour(mesh, geometry, points [+ hover], snap
  // radius), throwing what it throws. With 2: the open segment (see CutContourPreview). Fewer: empty.
  CutContourPreview preview(const std::optional<Vec3>& hoverIndex);
  const CutContourSessionStats& stats() const { return stats_; }

 private:
  struct Searches;
  void restart();
  void addPoint(const Vec3& index);
  CutContourPreview fromScratch(const std::optional<Vec3>& hoverIndex);
  // The loop of the committed segments, `live` (last placed point -> `end`) and the closing path
  // read from `closing` (first point -> `end`), searched again when it touches `live`. Empty
  // optional when a path cannot be drawn (cutContour throws then).
  std::optional<CutContour> compose(const Path& live, Path closing, const MeshSnap& end, bool& retried);

  const CutMesh* mesh_;
  Geometry geometry_;
  double snapRadiusMm_;
  std::vector<Vec3> points_;
  std::vector<MeshSnap> snaps_;
  // false: the kept pieces do not give cutContour's loop (a point off the surface or on the drawn
  // contour, two points on one vertex, a segment that cannot be drawn): every preview from scratch.
  bool exact_ = true;
  std::vector<Path> segments_;           // placed point i -> i+1
  std::vector<uint8_t> onLoop_;          // their vertices, ends included
  std::optional<CutContour> committed_;  // cutContour(points) (>= 3 points, exact_); none: recompute
  std::unique_ptr<Searches> searches_;
  int64_t lastHover_ = -1;
  CutContourPreview last_;
  CutContourSessionStats stats_;
};

}  // namespace vs
