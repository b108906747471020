#include "render/window_level.h"

namespace vs {

WindowHistogram::WindowHistogram(ValueRange range)
    : range_(range), lo_(range.min), span_(std::max(range.max - range.min, 1e-12)), bins_(kBins, 0) {}

WindowLevel WindowHistogram::window(double lo, double hi) const {
  auto percentile = [&](double f) {
    const int64_t target = static_cast<int64_t>(f * static_cast<double>(count_));
    int64_t acc = 0;
    for (int i = 0; i < kBins; ++i) {
      acc += bins_[static_cast<size_t>(i)];
      if (acc > target) return lo_ + span_ * i / (kBins - 1);
    }
    return range_.max;
  };
  double a = percentile(lo), b = percentile(hi);
  if (!(b > a)) a = range_.min, b = range_.max > range_.min ? range_.max : range_.min + 1;
  return {b - a, 0.5 * (a + b)};
}

}  // namespace vs
