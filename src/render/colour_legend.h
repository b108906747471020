// Colouring line overlays by a per-point quantity (a measured tree's diameter, issue 24) and the
// colour bar that explains it, drawn into a picture.
#pragma once

#include <array>
#include <vector>

#include "mesh/tri_mesh.h"
#include "util/image.h"

namespace vs {

// Blue -> cyan -> green -> yellow -> red for t in [0, 1] (clamped).
std::array<float, 3> rampColour(double t);

struct ColouredPieces {
  std::vector<Polyline> pieces;               // two-point pieces of the input lines, radii kept
  std::vector<std::array<float, 3>> colours;  // per piece: rampColour of its mean diameter over [lo, hi]
  double loMm = 0, hiMm = 0;                  // diameter range (2 x radius) over every point
};

// Throws InvalidArgument when no line carries radii (nothing to colour by).
ColouredPieces colourByDiameter(const std::vector<Polyline>& lines);

// A vertical colour bar at the right edge of the picture (bottom: lo, top: hi), with lo, the
// middle and hi written beside it in a small digit font ("mm" unit), on a dark backing.
void drawColourLegend(RgbaImage& image, double lo, double hi);

}  // namespace vs
