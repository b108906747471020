// A contour drawn on one slice of a volume, in every coordinate a reader needs: the document that
// `volscissors livewire --out`, Python and the viewer share. Filled from a live-wire by
// vs::contourDocument (scissors/live_wire_document.h); read and written as JSON by io/contour_io.h
// (the schema and the meaning of each field are listed there).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "volume/geometry.h"

namespace vs {

struct ContourDocument {
  using UV = std::array<int64_t, 2>;
  struct Segment {
    UV from{}, to{};
    int64_t pixels = 0;
    double cost = 0, lengthMm = 0;
  };
  std::string file;
  std::string plane;  // anatomical plane of the slice
  int axis = 2;
  int64_t index = 0, width = 0, height = 0;
  double spacingU = 1, spacingV = 1;
  std::string costKind = "mb";
  std::optional<std::array<double, 3>> weights;  // zero crossing, gradient, direction (mb)
  double gradientQuantile = 1;
  int connectivity = 8;
  double smoothMm = 0, snapPx = 0;
  bool closed = false;
  std::vector<UV> points, clicks, clicksInput;
  std::vector<Index3> pointsIndex;
  std::vector<Vec3> pointsWorld;
  std::vector<std::array<double, 2>> pointsPicture;
  double lengthMm = 0, cost = 0;
  std::vector<Segment> segments;
  std::optional<int64_t> areaPixels;
  std::optional<double> areaMm2;
  std::string mask;
};

}  // namespace vs
