// The transfer-function editor's edits, GL-free (the window's panel draws the curve over the
// histogram and calls these): control points of the opacity curve moved, added, removed and
// recoloured. The result is a plain TransferFunction, saved in the JSON format the CPU renderer
// and `tf FILE` read (render/transfer_function.h).
#pragma once
#include <array>
#include <optional>
#include <vector>

#include "render/transfer_function.h"
#include "volume/volume.h"

namespace vs::viewer {

class TfEditor {
 public:
  explicit TfEditor(TransferFunction tf) : tf_(std::move(tf)) {}
  const TransferFunction& tf() const { return tf_; }
  size_t size() const { return tf_.points().size(); }
  const TfPoint& point(size_t i) const { return tf_.points().at(i); }

  // A point at (value, opacity) with the curve's colour there; returns its index.
  size_t add(double value, double opacity);
  // Moves point i; its value stays strictly between its neighbours' (the order never changes
  // under the mouse), the opacity within [0, 1]. Returns the point as placed.
  const TfPoint& move(size_t i, double value, double opacity);
  void setColour(size_t i, const std::array<double, 3>& rgb);
  // InvalidArgument when only two points are left (a curve needs two ends).
  void remove(size_t i);
  // The point nearest to (value, opacity) in the editor's normalised plane (value / valueSpan,
  // opacity), if within maxDistance there.
  std::optional<size_t> nearest(double value, double opacity, double valueSpan, double maxDistance) const;

 private:
  void replace(std::vector<TfPoint> points);
  TransferFunction tf_;
};

// Histogram of the volume over [lo, hi] in `bins` bins, as log(1 + count) scaled to a maximum of 1
// (the editor's background: CT histograms span orders of magnitude).
std::vector<double> logHistogram(const VolumeF32& volume, double lo, double hi, int bins);

}  // namespace vs::viewer
