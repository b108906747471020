// Window/level: the grey mapping of slice images and of the ray caster's planes, box faces and
// MIP, one definition for both renderers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "volume/volume.h"

namespace vs {

struct WindowLevel {
  double window = 0;  // width in data units; <= 0: automatic (1st..99.5th percentile)
  double level = 0;   // centre
};

// Grey in [0, 1] of value v: 0 at or below level - window / 2, 1 at or above level + window / 2.
// window must be > 0.
inline double windowGrey(double v, const WindowLevel& wl) {
  return std::clamp((v - (wl.level - 0.5 * wl.window)) / wl.window, 0.0, 1.0);
}

// The usual CT window/level presets (Hounsfield units), as radiology viewers offer them:
// "ct-brain" 80/40, "ct-subdural" 200/75, "ct-abdomen" 400/50, "ct-lung" 1500/-600,
// "ct-bone" 2000/500.
struct WindowPreset {
  const char* name;
  WindowLevel wl;
};
inline const std::vector<WindowPreset>& windowPresets() {
  static const std::vector<WindowPreset> presets = {{"ct-brain", {80, 40}},
                                                    {"ct-subdural", {200, 75}},
                                                    {"ct-abdomen", {400, 50}},
                                                    {"ct-lung", {1500, -600}},
                                                    {"ct-bone", {2000, 500}}};
  return presets;
}

// The automatic window: 1st..99.5th percentile of the values added, from a 4096-bin histogram
// over `range` (the values' min..max). Non-finite values are ignored. O(1) per value.
class WindowHistogram {
 public:
  explicit WindowHistogram(ValueRange range);
  void add(double v) {
    if (!std::isfinite(v)) return;
    ++bins_[static_cast<size_t>(std::clamp(static_cast<int>((v - lo_) / span_ * (kBins - 1)), 0, kBins - 1))];
    ++count_;
  }
  // {width, centre} between the lo and hi quantiles (0 <= lo < hi <= 1); the whole range (at
  // least 1 wide) when the quantiles coincide.
  WindowLevel window(double lo = 0.01, double hi = 0.995) const;

 private:
  static constexpr int kBins = 4096;
  ValueRange range_;
  double lo_, span_;
  std::vector<int64_t> bins_;
  int64_t count_ = 0;
};

}  // namespace vs
