// The live-wire tool's anchor editing (thesis 5.2: nodes inserted into a contour, moved and
// removed) and its path-cooling option. The re-wiring is the core's (scissors/live_wire.h
// LiveWire::insertAnchor, moveAnchor, removeAnchor); the tool adds snapping, the choice of the
// segment or anchor under the mouse and one undo step per edit (the wire's state before and after).
#include <cmath>
#include <limits>

#include "app/tools.h"
#include "util/error.h"

namespace vs::viewer {

namespace {

double distance2(PixelUV a, PixelUV b) {
  const double du = double(a[0] - b[0]), dv = double(a[1] - b[1]);
  return du * du + dv * dv;
}

}  // namespace

template <class F>
void LiveWireTool::edit(F&& change) {
  LiveWire& w = wire();
  auto before = std::make_shared<const LiveWire::Snapshot>(w.snapshot());
  try {
    change(w);
  } catch (...) {
    w.restore(*before);  // the core validates before it changes anything; this is belt and braces
    throw;
  }
  live_.clear();
  refreshAnchors();
  record({Action::Kind::Edit, {}, std::move(before), std::make_shared<const LiveWire::Snapshot>(w.snapshot())});
}

void LiveWireTool::insertAnchor(size_t segment, PixelUV p) {
  const PixelUV q = snap(p);
  edit([&](LiveWire& w) { w.insertAnchor(segment, q); });
}

void LiveWireTool::insertAnchor(PixelUV p) {
  const auto k = segmentNear(p, std::numeric_limits<double>::infinity());
  VS_REQUIRE(k, "live-wire: no contour segment to insert a point into (click at least two points first)");
  insertAnchor(*k, p);
}

void LiveWireTool::moveAnchor(size_t anchor, PixelUV p) {
  const PixelUV q = snap(p);
  edit([&](LiveWire& w) { w.moveAnchor(anchor, q); });
}

void LiveWireTool::removeAnchor(size_t anchor) {
  edit([&](LiveWire& w) { w.removeAnchor(anchor); });
}

std::optional<size_t> LiveWireTool::anchorNear(PixelUV p, double radiusPx) const {
  std::optional<size_t> best;
  double bestD = radiusPx * radiusPx;
  for (size_t k = 0; k < clicks_.size(); ++k)
    if (const double d = distance2(clicks_[k], p); d <= bestD) {
      best = k;
      bestD = d;
    }
  return best;
}

std::optional<size_t> LiveWireTool::segmentNear(PixelUV p, double radiusPx) const {
  if (!wire_) return std::nullopt;
  std::optional<size_t> best;
  double bestD = radiusPx * radiusPx;
  const auto& segments = wire_->segments();
  for (size_t k = 0; k < segments.size(); ++k)
    for (const PixelUV& q : segments[k].pixels)
      if (const double d = distance2(q, p); d < bestD || (d == bestD && !best)) {
        best = k;
        bestD = d;
      }
  return best;
}

void LiveWireTool::setCooling(int moves) {
  VS_REQUIRE(moves >= 0 && moves <= 100, "live-wire path cooling: give 0 (off) to 100 mouse moves");
  options_.coolingMoves = moves;
  if (wire_) wire_->setCoolingMoves(moves);
}

}  // namespace vs::viewer
