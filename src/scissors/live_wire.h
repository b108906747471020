// Interactive 2D live-wire (Intelligent Scissors; thesis 2.1-2.3, Mortensen & Barrett 1995)
// on one slice: the small stateful API shared by the viewer and the CLI.
//
// Three phases, each amortised over the next:
//   1. construction: features (features/features2d.h) and the per-direction edge costs
//      (cost/live_wire_cost.h) once per slice - O(N * K);
//   2. setSeed(p) / commit(p): one Dijkstra search from the seed (graph/shortest_path.h),
//      started lazily and grown only as far as the queries need;
//   3. pathTo(p) per cursor move: the seed's search is resumed (never restarted while the
//      seed is unchanged) until p is settled, then the path is read from the back pointers -
//      O(1) + path length when p was already settled.
//
// Coordinates are slice pixels (u, v), 0-based, u fastest (see SliceView in volume/volume.h);
// lengths in mm from the pixel spacing; costs in the units of live_wire_cost.h (cost per mm
// integrated along the path). Paths are 8-connected (or 4-connected) pixel chains that start
// at the seed and end at the requested point, both included.
//
// Path cooling (Mortensen & Barrett 1995, sec. 3.3): with options.coolingMoves = N > 0, the
// part of the live path that stayed identical over the last N pathTo() calls (their common
// prefix from the seed) is frozen as soon as it is at least coolingMinPixels long: it becomes
// a committed segment and its end the new seed, automatically.
//
// Failures: a point outside the slice, or a commit to the current seed (consecutive duplicate
// points), throws InvalidArgument naming the point; operations that need a seed throw
// InvalidArgument without one. An unreachable point (impossible on a full grid) gives an empty
// path from pathTo and InvalidArgument from commit. Not thread-safe (one per view).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "cost/live_wire_cost.h"
#include "features/features2d.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

using PixelUV = std::array<int64_t, 2>;  // (u, v) slice pixel

struct LiveWireOptions {
  Features2DOptions features;  // smoothing sigma (mm)
  LiveWireCostOptions cost;    // cost kind and weights (0.43 / 0.43 / 0.14)
  int connectivity = 8;        // 8 (default) or 4
  int coolingMoves = 0;        // path cooling: freeze what stayed stable over this many moves (0 = off)
  int coolingMinPixels = 8;    // ... once the stable part is at least this many steps long
};

// One committed piece of the contour: the path from `from` to `to`, both included.
struct LiveWireSegment {
  PixelUV from{}, to{};
  std::vector<PixelUV> pixels;
  double cost = 0;      // sum of edge costs along the segment
  double lengthMm = 0;  // physical length
  bool cooled = false;  // created by path cooling rather than by commit()/close()
};

// The contour so far. For a closed contour the first pixel is not repeated at the end, but the
// closing step (last -> first) is counted in lengthMm and cost.
struct LiveWireContour {
  std::vector<PixelUV> pixels;
  bool closed = false;
  double lengthMm = 0;
  double cost = 0;
  std::vector<PixelUV> anchors;  // the seed points: first point, then the end of every segment
};

class LiveWire {
 public:
  // From precomputed features (e.g. to try several cost options on one slice).
  explicit LiveWire(Features2D features, const LiveWireOptions& options = {});
  // From a slice of a volume; `what` names it in errors (default "slice z=40").
  template <class T>
  static LiveWire fromSlice(const SliceView<T>& slice, const LiveWireOptions& options = {},
                            const std::string& what = {});
  // From a 2D image stored as a 1-slice volume (InvalidArgument if dims.z != 1).
  static LiveWire fromImage(const AnyVolume& image2d, const LiveWireOptions& options = {});

  ~LiveWire();
  LiveWire(LiveWire&&) noexcept;
  LiveWire& operator=(LiveWire&&) noexcept;

  // Starts a new contour at p (drops the previous one). O(1); the search grows on demand.
  void setSeed(PixelUV p);
  // Live path seed -> p. Resumes the seed's search until p is settled. With path cooling on,
  // may freeze a stable prefix first (the returned path then starts at the new seed).
  // `progress` reports the search ("search") and cancels it (vs::Cancelled; the search stays
  // valid and resumes on the next call), here and in buildMap, commit and close.
  const std::vector<PixelUV>& pathTo(PixelUV p, Progress& progress = Progress::none());
  // Settles every pixel from the current seed (the full single-source map, e.g. while the
  // user is idle); later pathTo calls are then O(path length). O(N log C).
  void buildMap(Progress& progress = Progress::none());
  // Commits the path seed -> p as a segment; p becomes the seed. Returns the new segment.
  const LiveWireSegment& commit(PixelUV p, Progress& progress = Progress::none());
  // Commits the path from the seed back to the first point and marks the contour closed.
  // Needs at least one committed segment (the seed differs from the first point).
  const LiveWireSegment& close(Progress& progress = Progress::none());
  // Removes the last segment (re-opening a closed contour first, i.e. dropping its closing
  // segment); the seed goes back to that segment's start. With no segment left, clears the
  // seed. Returns false if there was nothing to undo.
  bool undo();
  // Anchor editing (thesis 5.2: "a node p can be inserted between u and v such that a new
  // contour u -> p -> v can be formed"). The anchors are contour().anchors: the first point, then
  // the end of every segment (a closed contour's closing end is the first point again). Each edit
  // re-wires only the segments that touch the edited anchor, each by a search from its start
  // pixel, so the result equals the contour clicked through the new anchors in order; the other
  // segments are kept as they are. InvalidArgument for an index out of range, a point outside
  // the slice, or a point equal to a neighbouring anchor.
  // Splits segment k (0 .. segments().size()-1) at p: from -> p -> to.
  void insertAnchor(size_t segment, PixelUV p, Progress& progress = Progress::none());
  // Moves anchor k to p: the segments into and out of it are re-wired (the seed follows when k is
  // the last anchor of an open contour).
  void moveAnchor(size_t anchor, PixelUV p, Progress& progress = Progress::none());
  // Removes anchor k: its two segments become one path between its neighbours; the first or
  // last anchor of an open contour drops its one segment; the only anchor clears the seed. A
  // closed contour keeps at least 3 anchors.
  void removeAnchor(size_t anchor, Progress& progress = Progress::none());
  // Path cooling (options().coolingMoves) switched on or off for the following pathTo calls.
  void setCoolingMoves(int moves);

  // The editable state (seed, segments, closed), for undo of the edits above: restore() puts a
  // state of this wire back exactly (the live path and the cooling history are dropped).
  struct Snapshot {
    bool hasSeed = false;
    PixelUV seed{};
    bool closed = false, closeAddedSegment = false;
    std::vector<LiveWireSegment> segments;
  };
  Snapshot snapshot() const;
  void restore(const Snapshot& snapshot);

  // The pixel of largest gradient magnitude within `radiusPx` (Euclidean, in pixels) of p;
  // ties go to the one nearest to p, then the first in row order. radius 0 returns p.
  PixelUV snap(PixelUV p, double radiusPx) const;

  bool hasSeed() const;
  PixelUV seed() const;
  bool closed() const;
  const std::vector<LiveWireSegment>& segments() const;
  LiveWireContour contour() const;
  // The path last returned by pathTo (empty after a seed change or commit).
  const std::vector<PixelUV>& livePath() const;

  const Features2D& features() const;
  const LiveWireOptions& options() const;
  int64_t width() const;
  int64_t height() const;
  bool contains(PixelUV p) const;
  // Cost of the directed edge p -> p + step k in the engine's direction order.
  const std::vector<float>& edgeCosts() const;
  // Searches started since construction (tests: resumption instead of restarts).
  int64_t searchStarts() const;
  // Nodes settled by the current seed's search.
  int64_t settledCount() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

// Physical length (mm) of a pixel chain, closed = true adds the step back to the first pixel.
double contourLengthMm(const std::vector<PixelUV>& pixels, bool closed, double spacingU, double spacingV);

// Scanline polygon fill of a closed pixel contour, boundary pixels included: a width*height
// byte mask (u fastest), 1 inside. The polygon's vertices are the pixel centres; a pixel is
// inside when its centre is (even-odd rule, so a self-crossing contour gives holes where it
// overlaps itself). Contour pixels outside the image are an InvalidArgument. O(N + P log P).
std::vector<uint8_t> fillContour(const std::vector<PixelUV>& contour, int64_t width, int64_t height);

// Volume index (x, y, z) of slice pixel (u, v) on slice `index` along `axis` (SliceView order).
Index3 sliceToVolumeIndex(int axis, int64_t index, PixelUV p);

}  // namespace vs
