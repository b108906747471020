// Colouring line overlays by a per-point quantity (a measured tree's diameter, issue 24) and the
// colour bar that explains it, drawn into a picture.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesh/tri_mesh.h"
#include "util/image.h"

namespace vs {

// Blue -> cyan -> green -> yellow -> red for t in [0, 1] (clamped).
std::array<float, 3> rampColour(double t);

// The colour of a piece without a measured diameter (a flagged or unmeasured cross-section: a
// radius that is NaN or <= 0 at either end): neutral grey, not on the ramp.
inline constexpr std::array<float, 3> kUnmeasuredColour{0.55f, 0.55f, 0.55f};

struct ColouredPieces {
  std::vector<Polyline> pieces;               // two-point pieces of the input lines, radii kept
  std::vector<std::array<float, 3>> colours;  // per piece: rampColour of its mean diameter over [lo, hi]
                                              // (kUnmeasuredColour where an end has no radius)
  double loMm = 0, hiMm = 0;                  // diameter range (2 x radius) over every point
};

// Throws InvalidArgument when no line carries radii (nothing to colour by).
ColouredPieces colourByDiameter(const std::vector<Polyline>& lines);

// The legend's ticks (one home for `render` and the viewer): lo, the middle and hi, each with its
// place on the bar (0 bottom = lo, 1 top = hi) and its text ("1.5mm", "19mm").
struct LegendTick {
  double valueMm = 0, fraction = 0;
  std::string text;
};
std::vector<LegendTick> colourLegendTicks(double lo, double hi);

// A vertical colour bar at the right edge of the picture (bottom: lo, top: hi), with lo, the
// middle and hi written beside it in a small digit font ("mm" unit), on a dark backing.
void drawColourLegend(RgbaImage& image, double lo, double hi);

}  // namespace vs
