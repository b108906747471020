#include <algorithm>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

size_t inParent(const std::vector<size_t>& arm, size_t b, size_t end, const SectionWidths& widths, double maxMm,
                double parentRadiusMm, double voxMm) {
  double widestAtB = 0, narrowestAtB = 0;
  if (!widths || !widths(b, maxMm, widestAtB, narrowestAtB)) return 0;
  const double widestIn = std::min(2 * parentRadiusMm, widestAtB) + 0.5 * voxMm;
  size_t run = 0;
  for (double widest = 0, narrowest = 0; run < std::min(end, arm.size()) &&
                                         widths(arm[run], maxMm, widest, narrowest) && widest <= widestIn &&
                                         narrowest >= narrowestAtB - 0.5 * voxMm;)
    ++run;
  return run;
}

}  // namespace vs::centreline_detail
