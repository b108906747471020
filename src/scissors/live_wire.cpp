#include "scissors/live_wire.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "graph/shortest_path.h"
#include "util/error.h"
#include "volume/slice.h"

namespace vs {

namespace {
std::string str(PixelUV p) { return "(" + std::to_string(p[0]) + "," + std::to_string(p[1]) + ")"; }
}  // namespace

struct LiveWire::State {
  Features2D f;
  LiveWireOptions o;
  GridGraph graph;
  std::vector<float> costs;
  std::unique_ptr<ShortestPathSearch> search;
  int64_t searchSource = -1;
  int64_t starts = 0;
  bool hasSeed = false;
  PixelUV seed{};
  bool closed = false;
  bool closeAddedSegment = false;  // close() committed a segment (undo removes it)
  std::vector<LiveWireSegment> segments;
  std::vector<PixelUV> live;
  std::deque<std::vector<PixelUV>> history;  // last live paths (path cooling)

  int64_t node(PixelUV p) const { return p[0] + f.width * p[1]; }
  PixelUV pixel(int64_t n) const { return {n % f.width, n / f.width}; }

  void requireInside(PixelUV p, const char* what) const {
    if (!f.contains(p[0], p[1]))
      throw InvalidArgument(std::string(what) + " " + str(p) + " is outside the " + std::to_string(f.width) + "x" +
                            std::to_string(f.height) + " slice");
  }
  void requireSeed(const char* op) const {
    if (!hasSeed) throw InvalidArgument(std::string("live-wire ") + op + ": no seed point set");
  }

  ShortestPathSearch& ensureSearch() {
    const int64_t src = node(seed);
    if (!search) {
      search = std::make_unique<ShortestPathSearch>(graph, GridCost::perEdge(costs), std::vector<int64_t>{src});
      ++starts;
    } else if (searchSource != src) {
      search->restart({src});
      ++starts;
    }
    searchSource = src;
    return *search;
  }

  std::vector<PixelUV> toPixels(const Path& path) const {
    std::vector<PixelUV> px;
    px.reserve(path.nodes.size());
    for (int64_t n : path.nodes) px.push_back(pixel(n));
    return px;
  }

  const LiveWireSegment& commitTo(PixelUV p, bool cooled, Progress& progress = Progress::none()) {
    ShortestPathSearch& s = ensureSearch();
    const Path path = s.pathTo(node(p), progress);
    if (path.empty())
      throw InvalidArgument("live-wire: point " + str(p) + " cannot be reached from the seed " + str(seed));
    LiveWireSegment seg;
    seg.from = seed;
    seg.to = p;
    seg.pixels = toPixels(path);
    seg.cost = path.cost;
    seg.lengthMm = contourLengthMm(seg.pixels, false, f.spacingU, f.spacingV);
    seg.cooled = cooled;
    segments.push_back(std::move(seg));
    seed = p;
    live.clear();
    history.clear();
    return segments.back();
  }

  // The path a -> b as a segment, by a search of its own from a (the seed's search is kept).
  std::unique_ptr<ShortestPathSearch> editSearch;
  LiveWireSegment wire(PixelUV a, PixelUV b, Progress& progress) {
    if (!editSearch)
      editSearch = std::make_unique<ShortestPathSearch>(graph, GridCost::perEdge(costs), std::vector<int64_t>{node(a)});
    else
      editSearch->restart({node(a)});
    const Path path = editSearch->pathTo(node(b), progress);
    if (path.empty()) throw InvalidArgument("live-wire: point " + str(b) + " cannot be reached from " + str(a));
    LiveWireSegment seg;
    seg.from = a;
    seg.to = b;
    seg.pixels = toPixels(path);
    seg.cost = path.cost;
    seg.lengthMm = contourLengthMm(seg.pixels, false, f.spacingU, f.spacingV);
    return seg;
  }

  // Anchor k of contour().anchors: the number of anchors, and the segments into and out of it.
  size_t anchorCount() const { return segments.empty() ? (hasSeed ? 1 : 0) : segments.size() + (closed ? 0 : 1); }
  void requireAnchor(size_t k, const char* op) const {
    if (k >= anchorCount())
      throw InvalidArgument(std::string("live-wire ") + op + ": anchor " + std::to_string(k) + " does not exist (" +
                            std::to_string(anchorCount()) + " anchors)");
  }
  void requireNew(PixelUV p, PixelUV neighbour) const {
    if (p == neighbour)
      throw InvalidArgument("live-wire: point " + str(p) +
                            " equals a neighbouring anchor (consecutive duplicate points)");
  }

  // Path cooling: freeze the common prefix of the last coolingMoves live paths.
  void cool() {
    const auto n = static_cast<size_t>(o.coolingMoves);
    if (n == 0) return;
    history.push_back(live);
    while (history.size() > n) history.pop_front();
    if (history.size() < n) return;
    size_t common = history.front().size();
    for (const auto& h : history) common = std::min(common, h.size() - 1);  // never the cursor pixel itself
    for (size_t i = 0; i < common; ++i)
      for (const auto& h : history)
        if (h[i] != history.front()[i]) {
          common = i;
          break;
        }
    if (common == 0 || common - 1 < static_cast<size_t>(std::max(1, o.coolingMinPixels))) return;
    const PixelUV freezeAt = history.front()[common - 1];
    const PixelUV cursor = live.back();
    commitTo(freezeAt, true);
    live = toPixels(ensureSearch().pathTo(node(cursor)));
    history.push_back(live);
  }
};

LiveWire::LiveWire(Features2D features, const LiveWireOptions& options) : s_(std::make_unique<State>()) {
  VS_REQUIRE(options.connectivity == 4 || options.connectivity == 8, "live-wire connectivity must be 4 or 8");
  VS_REQUIRE(options.coolingMoves >= 0, "live-wire path cooling moves must be >= 0");
  VS_REQUIRE(features.width > 0 && features.height > 0, "live-wire: empty image");
  s_->f = std::move(features);
  s_->o = options;
  s_->graph = GridGraph({s_->f.width, s_->f.height, 1}, {s_->f.spacingU, s_->f.spacingV, 1.0}, options.connectivity);
  std::vector<std::array<int, 2>> steps;
  for (int k = 0; k < s_->graph.directionCount(); ++k)
    steps.push_back({s_->graph.offset(k)[0], s_->graph.offset(k)[1]});
  s_->costs = liveWireEdgeCosts(s_->f, options.cost, steps);
}

template <class T>
LiveWire LiveWire::fromSlice(const SliceView<T>& slice, const LiveWireOptions& options, const std::string& what) {
  return LiveWire(computeFeatures2D(slice, options.features, what), options);
}

LiveWire LiveWire::fromImage(const AnyVolume& image2d, const LiveWireOptions& options) {
  return LiveWire(computeFeatures2D(image2d, options.features), options);
}

LiveWire::~LiveWire() = default;
LiveWire::LiveWire(LiveWire&&) noexcept = default;
LiveWire& LiveWire::operator=(LiveWire&&) noexcept = default;

void LiveWire::setSeed(PixelUV p) {
  s_->requireInside(p, "seed point");
  s_->hasSeed = true;
  s_->seed = p;
  s_->closed = false;
  s_->segments.clear();
  s_->live.clear();
  s_->history.clear();
}

const std::vector<PixelUV>& LiveWire::pathTo(PixelUV p, Progress& progress) {
  s_->requireSeed("pathTo");
  s_->requireInside(p, "point");
  if (s_->closed) throw InvalidArgument("live-wire pathTo: the contour is closed (undo() to reopen it)");
  s_->live = s_->toPixels(s_->ensureSearch().pathTo(s_->node(p), progress));
  if (!s_->live.empty()) s_->cool();
  return s_->live;
}

void LiveWire::buildMap(Progress& progress) {
  s_->requireSeed("buildMap");
  s_->ensureSearch().runToCompletion(progress);
}

const LiveWireSegment& LiveWire::commit(PixelUV p, Progress& progress) {
  s_->requireSeed("commit");
  s_->requireInside(p, "point");
  if (s_->closed) throw InvalidArgument("live-wire commit: the contour is closed (undo() to reopen it)");
  if (p == s_->seed)
    throw InvalidArgument("live-wire: point " + str(p) + " equals the current seed (consecutive duplicate points)");
  return s_->commitTo(p, false, progress);
}

const LiveWireSegment& LiveWire::close(Progress& progress) {
  s_->requireSeed("close");
  if (s_->closed) throw InvalidArgument("live-wire close: the contour is already closed");
  if (s_->segments.empty()) throw InvalidArgument("live-wire close: needs at least two points");
  const PixelUV first = s_->segments.front().from;
  if (s_->seed == first) {  // the last commit already returned to the first point
    s_->closed = true;
    s_->closeAddedSegment = false;
    return s_->segments.back();
  }
  const LiveWireSegment& seg = s_->commitTo(first, false, progress);
  s_->closed = true;
  s_->closeAddedSegment = true;
  return seg;
}

bool LiveWire::undo() {
  s_->live.clear();
  s_->history.clear();
  if (s_->closed) {
    s_->closed = false;
    if (!s_->closeAddedSegment) return true;  // only the flag was set
  }
  if (!s_->segments.empty()) {
    s_->seed = s_->segments.back().from;
    s_->segments.pop_back();
    return true;
  }
  if (s_->hasSeed) {
    s_->hasSeed = false;
    return true;
  }
  return false;
}

void LiveWire::insertAnchor(size_t k, PixelUV p, Progress& progress) {
  s_->requireInside(p, "point");
  if (k >= s_->segments.size())
    throw InvalidArgument("live-wire insertAnchor: segment " + std::to_string(k) + " does not exist (" +
                          std::to_string(s_->segments.size()) + " segments)");
  const LiveWireSegment& old = s_->segments[k];
  s_->requireNew(p, old.from);
  s_->requireNew(p, old.to);
  LiveWireSegment a = s_->wire(old.from, p, progress), b = s_->wire(p, old.to, progress);
  s_->segments[k] = std::move(a);
  s_->segments.insert(s_->segments.begin() + std::ptrdiff_t(k) + 1, std::move(b));
  s_->live.clear();
  s_->history.clear();
}

void LiveWire::moveAnchor(size_t k, PixelUV p, Progress& progress) {
  s_->requireInside(p, "point");
  s_->requireAnchor(k, "moveAnchor");
  auto& segs = s_->segments;
  const size_t n = segs.size();
  if (n == 0) {  // the seed alone
    s_->seed = p;
  } else {
    // The segment into anchor k (none for an open contour's first) and out of it (none for its last).
    const std::optional<size_t> in = k > 0        ? std::optional<size_t>(k - 1)
                                     : s_->closed ? std::optional<size_t>(n - 1)
                                                  : std::nullopt;
    const std::optional<size_t> out = k < n ? std::optional<size_t>(k) : std::nullopt;
    if (in) s_->requireNew(p, segs[*in].from);
    if (out) s_->requireNew(p, segs[*out].to);
    LiveWireSegment a, b;
    if (in) a = s_->wire(segs[*in].from, p, progress);
    if (out) b = s_->wire(p, segs[*out].to, progress);
    if (in) segs[*in] = std::move(a);
    if (out) segs[*out] = std::move(b);
    if (!out || (s_->closed && k == 0)) s_->seed = p;  // the open end, or a closed contour's first point
  }
  s_->live.clear();
  s_->history.clear();
}

void LiveWire::removeAnchor(size_t k, Progress& progress) {
  s_->requireAnchor(k, "removeAnchor");
  auto& segs = s_->segments;
  const size_t n = segs.size();
  if (s_->closed && n <= 3)
    throw InvalidArgument("live-wire removeAnchor: a closed contour keeps at least 3 anchors (it has " +
                          std::to_string(n) + ")");
  if (n == 0) {
    s_->hasSeed = false;
  } else if (!s_->closed && k == 0) {
    segs.erase(segs.begin());  // the seed (the open end) stays where it is
  } else if (!s_->closed && k == n) {
    s_->seed = segs.back().from;
    segs.pop_back();
  } else {
    const size_t in = k > 0 ? k - 1 : n - 1;  // closed: anchor 0's incoming is the closing segment
    LiveWireSegment merged = s_->wire(segs[in].from, segs[k].to, progress);
    segs[in] = std::move(merged);
    segs.erase(segs.begin() + std::ptrdiff_t(k));
    if (s_->closed) s_->seed = segs.front().from;
  }
  s_->live.clear();
  s_->history.clear();
}

void LiveWire::setCoolingMoves(int moves) {
  VS_REQUIRE(moves >= 0, "live-wire path cooling moves must be >= 0");
  s_->o.coolingMoves = moves;
  s_->history.clear();
}

LiveWire::Snapshot LiveWire::snapshot() const {
  return {s_->hasSeed, s_->seed, s_->closed, s_->closeAddedSegment, s_->segments};
}

void LiveWire::restore(const Snapshot& snap) {
  for (const auto& seg : snap.segments)
    for (const PixelUV& p : seg.pixels) s_->requireInside(p, "restored contour pixel");
  s_->hasSeed = snap.hasSeed;
  s_->seed = snap.seed;
  s_->closed = snap.closed;
  s_->closeAddedSegment = snap.closeAddedSegment;
  s_->segments = snap.segments;
  s_->live.clear();
  s_->history.clear();
}

PixelUV LiveWire::snap(PixelUV p, double radiusPx) const {
  s_->requireInside(p, "point");
  VS_REQUIRE(std::isfinite(radiusPx) && radiusPx >= 0, "live-wire snap radius must be finite and >= 0");
  const auto r = static_cast<int64_t>(std::floor(radiusPx));
  const double r2 = radiusPx * radiusPx;
  PixelUV best = p;
  float bestG = s_->f.magnitude[static_cast<size_t>(s_->node(p))];
  int64_t bestD = 0;
  for (int64_t v = std::max<int64_t>(0, p[1] - r); v <= std::min(s_->f.height - 1, p[1] + r); ++v)
    for (int64_t u = std::max<int64_t>(0, p[0] - r); u <= std::min(s_->f.width - 1, p[0] + r); ++u) {
      const int64_t d = (u - p[0]) * (u - p[0]) + (v - p[1]) * (v - p[1]);
      if (static_cast<double>(d) > r2) continue;
      const float g = s_->f.magnitude[static_cast<size_t>(u + s_->f.width * v)];
      if (g > bestG || (g == bestG && d < bestD)) {
        best = {u, v};
        bestG = g;
        bestD = d;
      }
    }
  return best;
}

bool LiveWire::hasSeed() const { return s_->hasSeed; }
PixelUV LiveWire::seed() const {
  s_->requireSeed("seed");
  return s_->seed;
}
bool LiveWire::closed() const { return s_->closed; }
const std::vector<LiveWireSegment>& LiveWire::segments() const { return s_->segments; }
const std::vector<PixelUV>& LiveWire::livePath() const { return s_->live; }
const Features2D& LiveWire::features() const { return s_->f; }
const LiveWireOptions& LiveWire::options() const { return s_->o; }
int64_t LiveWire::width() const { return s_->f.width; }
int64_t LiveWire::height() const { return s_->f.height; }
bool LiveWire::contains(PixelUV p) const { return s_->f.contains(p[0], p[1]); }
const std::vector<float>& LiveWire::edgeCosts() const { return s_->costs; }
int64_t LiveWire::searchStarts() const { return s_->starts; }
int64_t LiveWire::settledCount() const { return s_->search ? s_->search->settledCount() : 0; }

LiveWireContour LiveWire::contour() const {
  LiveWireContour c;
  c.closed = s_->closed;
  if (!s_->hasSeed) return c;
  c.anchors.push_back(s_->segments.empty() ? s_->seed : s_->segments.front().from);
  if (s_->segments.empty()) c.pixels.push_back(s_->seed);
  for (const auto& seg : s_->segments) {
    c.pixels.insert(c.pixels.end(), seg.pixels.begin() + (c.pixels.empty() ? 0 : 1), seg.pixels.end());
    c.anchors.push_back(seg.to);
    c.cost += seg.cost;
    c.lengthMm += seg.lengthMm;
  }
  if (c.closed) {
    if (c.pixels.size() > 1 && c.pixels.back() == c.pixels.front()) c.pixels.pop_back();
    c.anchors.pop_back();
  }
  return c;
}

double contourLengthMm(const std::vector<PixelUV>& pixels, bool closed, double spacingU, double spacingV) {
  double len = 0;
  const size_t n = pixels.size();
  if (n < 2) return 0;
  for (size_t i = 0; i + 1 < n + (closed ? 1 : 0); ++i) {
    const PixelUV& a = pixels[i];
    const PixelUV& b = pixels[(i + 1) % n];
    len += std::hypot(static_cast<double>(b[0] - a[0]) * spacingU, static_cast<double>(b[1] - a[1]) * spacingV);
  }
  return len;
}

std::vector<uint8_t> fillContour(const std::vector<PixelUV>& contour, int64_t width, int64_t height) {
  VS_REQUIRE(width > 0 && height > 0, "fillContour: empty image");
  std::vector<uint8_t> mask(static_cast<size_t>(width * height), 0);
  for (const auto& p : contour)
    if (p[0] < 0 || p[1] < 0 || p[0] >= width || p[1] >= height)
      throw InvalidArgument("fillContour: contour pixel " + str(p) + " is outside the image");
  const size_t n = contour.size();
  if (n == 0) return mask;
  // Edges bucketed by the scanlines they cross (half-open in v so a vertex on a scanline counts once).
  std::vector<std::vector<double>> xs(static_cast<size_t>(height));
  for (size_t i = 0; i < n; ++i) {
    const PixelUV& a = contour[i];
    const PixelUV& b = contour[(i + 1) % n];
    if (a[1] == b[1]) continue;
    const int64_t v0 = std::min(a[1], b[1]), v1 = std::max(a[1], b[1]);
    for (int64_t v = v0; v < v1; ++v) {
      const double t = static_cast<double>(v - a[1]) / static_cast<double>(b[1] - a[1]);
      xs[static_cast<size_t>(v)].push_back(static_cast<double>(a[0]) + t * static_cast<double>(b[0] - a[0]));
    }
  }
  for (int64_t v = 0; v < height; ++v) {
    auto& row = xs[static_cast<size_t>(v)];
    std::sort(row.begin(), row.end());
    for (size_t i = 0; i + 1 < row.size(); i += 2) {
      const int64_t u0 = std::max<int64_t>(0, static_cast<int64_t>(std::ceil(row[i])));
      const int64_t u1 = std::min<int64_t>(width - 1, static_cast<int64_t>(std::floor(row[i + 1])));
      for (int64_t u = u0; u <= u1; ++u) mask[static_cast<size_t>(u + width * v)] = 1;
    }
  }
  for (const auto& p : contour) mask[static_cast<size_t>(p[0] + width * p[1])] = 1;
  return mask;
}

Index3 sliceToVolumeIndex(int axis, int64_t index, PixelUV p) { return sliceToVolumeIndex(axis, index, p[0], p[1]); }

template LiveWire LiveWire::fromSlice(const SliceView<uint8_t>&, const LiveWireOptions&, const std::string&);
template LiveWire LiveWire::fromSlice(const SliceView<int16_t>&, const LiveWireOptions&, const std::string&);
template LiveWire LiveWire::fromSlice(const SliceView<uint16_t>&, const LiveWireOptions&, const std::string&);
template LiveWire LiveWire::fromSlice(const SliceView<float>&, const LiveWireOptions&, const std::string&);

}  // namespace vs
