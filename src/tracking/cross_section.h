// The centre and radius of a lumen from its cross-section (issue 21, wide lumens): used by the
// refinement (centreline.cpp) where a point's rays do not resolve its lumen (the lumen is wider
// than the rays, or too few of them find both walls).
//
// The plane normal to `tangent` at `c` is sampled on a square grid (half size halfMm, step
// max(smallest spacing, halfMm / 60)); the lumen is the 4-connected component containing the
// grid point nearest c of the samples beyond a half-way level (the value at c's side of it). The
// level is first half-way between `centreValue` and `surroundings`, then half-way between the
// section's own plateau (median inside the component, two steps from its edge and more) and its
// own background (median outside the component in a ring 2-5 steps beyond the inscribed circle),
// and the component is found again. The centre: the grid point reached by steepest ascent of the
// component's Euclidean distance map from c (the largest inscribed circle of c's lobe: where two
// lumens are fused in the plane, at a junction, the ascent stays in c's, bounded by the carina),
// then twice the centroid of the component's samples within the inscribed radius + 2 steps of
// it; the radius: that disc's lumen area as a circle's radius (sub-voxel: a sample is lumen when
// it lies beyond the half-way level, so the area is the half-maximum contour's). A circle of
// radius R gives its centre and R to within a fraction of a step; the radius never exceeds the
// inscribed radius + 2 steps. Not found (ok false) when c's sample is not lumen or the level is
// undefined. O((halfMm / step)^2)
// samples. Thread-safe with one scratch per thread.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "volume/sample.h"

namespace vs {

struct SectionScratch {
  std::vector<float> value;
  std::vector<uint8_t> lumen;
  std::vector<float> dist2;  // squared distance (steps) to the nearest non-component sample
  std::vector<float> tmp;
  std::vector<int32_t> stack;
  std::vector<double> pick;
  std::vector<float> outside2;                // squared distance (steps) to the component, outside it
  std::vector<std::pair<int, float>> banded;  // (sector, value) of the samples in the wall's bands
};

struct SectionResult {
  bool ok = false;
  Vec3 centre{0, 0, 0};  // mm (index x spacing)
  double radiusMm = 0;
  double inscribedMm = 0;  // the largest inscribed circle's radius (grid)
  double ownMm = 0;        // c's own depth: its sample's distance to the component's edge (grid)
  double topMm = 0;        // from c's sample to the largest inscribed circle's centre (grid)
  double stepMm = 0;       // the grid's step
  double level = 0;
};

// `c` in mm (index x spacing); the sampler reads the continuous index c / spacing.
SectionResult sectionCentre(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                            double centreValue, double surroundings, double halfMm, SectionScratch& scratch);

// Whether the circle found holds c's own lumen: c's own inscribed circle (its depth around it) lies
// within the largest inscribed circle (to 2 grid steps). Where it does not, c lies in a lobe of its
// own that opens into a wider lumen in the plane (a daughter's first points just beyond a wide
// trunk's wall: the section's circle is the trunk's), so the section's radius is not c's.
bool sectionHoldsPoint(const SectionResult& s);

// Squared distances (in grid steps) to the nearest source over an n x n grid, in place: f is 0 at sources and
// kSectionFar elsewhere. tmp and idx are scratch. One home for the sections' and the lobes' distance transforms.
inline constexpr float kSectionFar = 1e20f;
void squaredDistance2d(float* f, int n, std::vector<float>& tmp, std::vector<int32_t>& idx);

// Flood fill over an n x n grid (index i + n * j), 4-connected, from the seeds already on `stack`: `take(k)` says
// whether grid point k joins (and marks it). One home for the sections' and the lobes' components.
template <class Take>
void floodGrid4(int n, std::vector<int32_t>& stack, Take&& take) {
  while (!stack.empty()) {
    const int p = stack.back();
    stack.pop_back();
    const int i = p % n, j = p / n;
    const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
    for (const auto& q : nb)
      if (q[0] >= 0 && q[1] >= 0 && q[0] < n && q[1] < n && take(q[0] + n * q[1])) stack.push_back(q[0] + n * q[1]);
  }
}

}  // namespace vs
