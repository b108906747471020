// A cross-section fitted as two discs (session 24's placeOverlaps; session 26: splitForks' evidence
// of two lumens side by side). See centreline_junctions.h.
#include <algorithm>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

bool twoDiscs(const SectionLobes& lobes, size_t k, const Vec3& qk, double ownA, double ownB, double voxMm,
              double reachMm, Vec3& ePlus, Vec3& eMinus, double& ra, double& rb) {
  Vec3 d;
  double plus = 0, minus = 0, narrowest = 0;
  if (!lobes || !lobes(k, reachMm, d, plus, minus, narrowest)) return false;
  ra = std::max(ownA, 0.5 * narrowest), rb = std::max(ownB, 0.5 * narrowest);
  const double sep = plus + minus - ra - rb;  // the discs' centres' separation
  if (sep < std::max(0.5 * voxMm, 0.5 * std::min(ra, rb)) || sep > ra + rb || narrowest > 2.5 * std::max(ownA, ownB))
    return false;
  ePlus = qk + (plus - ra) * d, eMinus = qk - (minus - ra) * d;
  return true;
}

}  // namespace vs::centreline_detail
