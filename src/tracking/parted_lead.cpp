#include <algorithm>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

size_t inParent(const std::vector<size_t>& arm, size_t b, size_t end, const SectionWidths& widths, double maxMm,
                double parentRadiusMm, double voxMm, double coarseMm) {
  double widestAtB = 0, narrowestAtB = 0;
  if (!widths || !widths(b, maxMm, widestAtB, narrowestAtB)) return 0;
  // The parent's own section is round only to within its digitisation: across slices thicker than the voxel it reads up
  // to half the slice wider along them (16110, 2.3 mm slices: the trunk's widest chords 5.18-5.93 mm against its
  // diameter 4.94), so the allowance is half the coarsest spacing, not half the smallest.
  const double widestIn = std::min(2 * parentRadiusMm, widestAtB) + 0.5 * std::max(voxMm, coarseMm);
  // That smear is the parent's own walls read across the same slices: b's section or the run's earlier ones read it
  // already, and a section a point on reads it again to within the in-plane digitisation. A fork's first widening
  // section - the sibling's lumen entering it, which along the slices reads like smear (11932: 4.45 -> 5.20 mm, then
  // the union's 6.49) - rises past every width read before it by more than that.
  double widestBefore = widestAtB;
  size_t run = 0;
  for (double widest = 0, narrowest = 0;
       run < std::min(end, arm.size()) && widths(arm[run], maxMm, widest, narrowest) && widest <= widestIn &&
       widest <= widestBefore + 0.5 * voxMm && narrowest >= narrowestAtB - 0.5 * voxMm;)
    widestBefore = std::max(widestBefore, widest), ++run;
  return run;
}

}  // namespace vs::centreline_detail
