#include "scissors/live_wire_document.h"

#include <variant>

#include "util/error.h"
#include "volume/slice.h"

namespace vs {

LiveWire liveWireOnSlice(const AnyVolume& volume, int axis, int64_t index, const LiveWireOptions& options,
                         const std::string& what) {
  const Geometry& g = geometryOf(volume);
  if (axis < 0 || axis > 2) throw InvalidArgument("slice axis must be 0, 1 or 2, got " + std::to_string(axis));
  if (index < 0 || index >= g.dims[static_cast<size_t>(axis)])
    throw InvalidArgument("slice " + sliceName(axis, index) + " is outside the volume (0.." +
                          std::to_string(g.dims[static_cast<size_t>(axis)] - 1) + ")");
  return std::visit(
      [&](const auto& v) {
        return LiveWire::fromSlice(sliceView(v, axis, index), options,
                                   what.empty() ? describeSlice(axis, index) : what);
      },
      volume);
}

ContourDocument contourDocument(const LiveWire& wire, const Geometry& geometry, int axis, int64_t index,
                                const ContourClicks& clicks, const std::string& file) {
  const LiveWireContour c = wire.contour();
  const LiveWireOptions& o = wire.options();
  const SliceFrame frame = sliceFrame(geometry, axis, index);
  ContourDocument doc;
  doc.file = file;
  doc.plane = anatomicalPlaneName(frame.plane);
  doc.axis = axis;
  doc.index = index;
  doc.width = wire.width();
  doc.height = wire.height();
  doc.spacingU = wire.features().spacingU;
  doc.spacingV = wire.features().spacingV;
  doc.costKind = liveWireCostKindName(o.cost.kind);
  if (o.cost.kind == LiveWireCostKind::MortensenBarrett)
    doc.weights = std::array<double, 3>{o.cost.weightZ, o.cost.weightG, o.cost.weightD};
  doc.gradientQuantile = o.cost.gradientReferenceQuantile;
  doc.connectivity = o.connectivity;
  doc.smoothMm = o.features.smoothSigmaMm;
  doc.snapPx = clicks.snapPx;
  doc.closed = c.closed;
  doc.points = c.pixels;
  for (const auto& p : c.pixels) {
    const Index3 i = sliceToVolumeIndex(axis, index, p[0], p[1]);
    const Vec3 ci = Vec3(double(i[0]), double(i[1]), double(i[2]));
    doc.pointsIndex.push_back(i);
    doc.pointsWorld.push_back(geometry.indexToWorld(ci));
    doc.pointsPicture.push_back(frame.pictureOf(ci));
  }
  doc.clicks = clicks.snapped.empty() ? clicks.input : clicks.snapped;
  doc.clicksInput = clicks.input;
  doc.lengthMm = c.lengthMm;
  doc.cost = c.cost;
  for (const auto& s : wire.segments())
    doc.segments.push_back({s.from, s.to, static_cast<int64_t>(s.pixels.size()), s.cost, s.lengthMm});
  if (c.closed) {
    int64_t area = 0;
    for (uint8_t m : fillContour(c.pixels, wire.width(), wire.height())) area += m;
    doc.areaPixels = area;
    doc.areaMm2 = static_cast<double>(area) * doc.spacingU * doc.spacingV;
  }
  return doc;
}

}  // namespace vs
