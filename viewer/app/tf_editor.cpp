#include "app/tf_editor.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace vs::viewer {

void TfEditor::replace(std::vector<TfPoint> points) { tf_ = TransferFunction(std::move(points), tf_.unitDistance()); }

size_t TfEditor::add(double value, double opacity) {
  VS_REQUIRE(std::isfinite(value) && std::isfinite(opacity), "transfer function: a point needs finite coordinates");
  const Rgba c = tf_.evaluate(value);
  std::vector<TfPoint> pts = tf_.points();
  TfPoint p;
  p.value = value;
  p.opacity = std::clamp(opacity, 0.0, 1.0);
  p.color = {double(c.r), double(c.g), double(c.b)};
  const auto at =
      std::upper_bound(pts.begin(), pts.end(), value, [](double v, const TfPoint& q) { return v < q.value; });
  const size_t index = size_t(at - pts.begin());
  pts.insert(at, p);
  replace(std::move(pts));
  return index;
}

const TfPoint& TfEditor::move(size_t i, double value, double opacity) {
  VS_REQUIRE(i < size(), "transfer function: no point " + std::to_string(i));
  VS_REQUIRE(std::isfinite(value) && std::isfinite(opacity), "transfer function: a point needs finite coordinates");
  std::vector<TfPoint> pts = tf_.points();
  // Strictly between the neighbours: a step of a millionth of their gap keeps the order.
  auto inside = [](double lo, double hi) { return (hi - lo) * 1e-6 + 1e-12; };
  if (i > 0) value = std::max(value, pts[i - 1].value + inside(pts[i - 1].value, pts[i].value));
  if (i + 1 < pts.size()) value = std::min(value, pts[i + 1].value - inside(pts[i].value, pts[i + 1].value));
  pts[i].value = value;
  pts[i].opacity = std::clamp(opacity, 0.0, 1.0);
  replace(std::move(pts));
  return point(i);
}

void TfEditor::setColour(size_t i, const std::array<double, 3>& rgb) {
  VS_REQUIRE(i < size(), "transfer function: no point " + std::to_string(i));
  std::vector<TfPoint> pts = tf_.points();
  pts[i].color = rgb;
  replace(std::move(pts));  // validates [0, 1]
}

void TfEditor::remove(size_t i) {
  VS_REQUIRE(i < size(), "transfer function: no point " + std::to_string(i));
  VS_REQUIRE(size() > 2, "transfer function: the curve keeps at least two points");
  std::vector<TfPoint> pts = tf_.points();
  pts.erase(pts.begin() + std::ptrdiff_t(i));
  replace(std::move(pts));
}

std::optional<size_t> TfEditor::nearest(double value, double opacity, double valueSpan, double maxDistance) const {
  VS_REQUIRE(valueSpan > 0, "transfer function: the editor's value span must be > 0");
  std::optional<size_t> best;
  double bestD = maxDistance;
  for (size_t i = 0; i < size(); ++i) {
    const double d = std::hypot((point(i).value - value) / valueSpan, point(i).opacity - opacity);
    if (d <= bestD) best = i, bestD = d;
  }
  return best;
}

std::vector<double> logHistogram(const VolumeF32& volume, double lo, double hi, int bins) {
  VS_REQUIRE(bins > 0 && hi > lo, "histogram: needs bins > 0 and hi > lo");
  std::vector<double> h(size_t(bins), 0.0);
  const double scale = double(bins) / (hi - lo);
  for (float v : volume.voxels()) {
    if (!(v >= lo && v <= hi)) continue;
    h[size_t(std::min<int64_t>(int64_t((v - lo) * scale), bins - 1))] += 1;
  }
  double top = 0;
  for (double& c : h) top = std::max(top, c = std::log1p(c));
  if (top > 0)
    for (double& c : h) c /= top;
  return h;
}

}  // namespace vs::viewer
