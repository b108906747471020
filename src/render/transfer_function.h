// Transfer functions for direct volume rendering (thesis 1.1: "assigning a colour and
// opacity to each voxel"): piecewise-linear colour (RGB in [0,1]) and opacity over the
// voxel value, plus presets for CT (Hounsfield units) and MRI and a lookup table used by
// the ray caster.
//
// Opacity convention: a point's opacity is the opacity of a slab `unitDistance` mm thick
// (default 1 mm, like VTK's ScalarOpacityUnitDistance). The renderer corrects it for its
// sample step dt with  alpha' = 1 - (1 - alpha)^(dt / unitDistance).
//
// JSON file format (documented in docs/notes/render.md):
//   {"points": [{"value": -500, "color": [0.8, 0.5, 0.4], "opacity": 0.0},
//               {"value":  300, "color": [1, 1, 0.9],     "opacity": 0.8}],
//    "unit_distance": 1.0}                       // optional, mm
// Points may come in any order (they are sorted by value); below the first and above the
// last point the end values hold. colour components and opacity must lie in [0, 1].
#pragma once

#include <array>
#include <string>
#include <vector>

#include "volume/volume.h"

namespace vs {

struct TfPoint {
  double value = 0;                      // voxel value (data units, e.g. HU)
  std::array<double, 3> color{1, 1, 1};  // RGB in [0,1]
  double opacity = 0;                    // in [0,1], per unitDistance mm
};

struct Rgba {
  float r = 0, g = 0, b = 0, a = 0;
};

class TransferFunction {
 public:
  TransferFunction() = default;
  // Throws InvalidArgument if points is empty, a value is not finite, or a colour/opacity
  // is outside [0,1].
  explicit TransferFunction(std::vector<TfPoint> points, double unitDistance = 1.0);

  const std::vector<TfPoint>& points() const { return points_; }
  double unitDistance() const { return unitDistance_; }
  bool empty() const { return points_.empty(); }

  // Piecewise-linear evaluation (clamped at the ends). O(log n).
  Rgba evaluate(double value) const;
  // Smallest and largest value where the opacity may be non-zero; {inf, -inf} when the
  // opacity is zero everywhere.
  std::pair<double, double> opaqueRange() const;

  // Presets: "ct-skin", "ct-bone", "ct-lung" (airways/lung, shows air-tissue borders),
  // "ct-angio" (contrast-filled vessels + bone), "mri" (T1 head), "vessels" (the peers'
  // uint8 vessel phantom, same as VTK's benchmark TF), "auto" (a ramp over the data range).
  // CT presets are in HU. Throws InvalidArgument naming the preset and listing valid names.
  static TransferFunction preset(const std::string& name, const ValueRange& dataRange);
  static std::vector<std::string> presetNames();

  // Parses the JSON format above; `source` names the file in messages. Throws IoError
  // for malformed JSON or a missing/ill-typed field, InvalidArgument for out-of-range values.
  static TransferFunction fromJson(const std::string& text, const std::string& source = "transfer function");
  // Reads and parses a JSON file (IoError naming the file when it cannot be read).
  static TransferFunction fromFile(const std::string& path);
  std::string toJson() const;

 private:
  std::vector<TfPoint> points_;
  double unitDistance_ = 1.0;
};

// A lookup table of a transfer function over [lo, hi] with `size` entries, colour
// premultiplied by nothing (straight RGB) and opacity already corrected for a sample
// step of `stepMm`. index(v) = clamp(round((v - lo) * scale)). Also a prefix count of
// entries with non-zero opacity so a value interval can be tested for emptiness in O(1)
// (empty-space skipping).
struct TfTable {
  double lo = 0, hi = 1, scale = 1;
  std::vector<Rgba> entries;
  std::vector<int> opaquePrefix;  // opaquePrefix[i] = #entries j < i with alpha > 0

  TfTable() = default;
  TfTable(const TransferFunction& tf, double lo, double hi, double stepMm, int size = 4096);
  int index(float v) const {
    float f = (v - static_cast<float>(lo)) * static_cast<float>(scale) + 0.5f;
    if (!(f > 0.f)) return 0;
    const int i = static_cast<int>(f);
    return i >= static_cast<int>(entries.size()) ? static_cast<int>(entries.size()) - 1 : i;
  }
  const Rgba& operator()(float v) const { return entries[static_cast<size_t>(index(v))]; }
  // True if every value in [vmin, vmax] maps to zero opacity.
  bool transparent(float vmin, float vmax) const {
    const int a = index(vmin), b = index(vmax);
    return opaquePrefix[static_cast<size_t>(b) + 1] - opaquePrefix[static_cast<size_t>(a)] == 0;
  }
};

}  // namespace vs
