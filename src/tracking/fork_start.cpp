// Where a re-branched fork starts (session 36 fork36), splitForks' evidence of two lumens side by side (session 26),
// and placeFork's refusal of a child's point laid onto the sibling's side (session 36). See centreline_junctions.h.
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/centreline_junctions.h"
#include "util/median.h"

namespace vs::centreline_detail {

size_t trunkPointsBeforeFork(const SharedStretch& s, const std::function<double(size_t)>& apartMm,
                             const SectionWidths& widths) {
  if (!widths || s.shared.empty()) return 0;
  // How far from P the two placed chains stay within the parent's radius of each other.
  double arc = 0, togetherMm = 0;
  Vec3 prev = s.q[s.P];
  for (size_t k : s.shared) {
    arc += (s.q[k] - prev).norm(), prev = s.q[k];
    if (apartMm(k) > s.parentR) break;
    togetherMm = arc;
  }
  if (togetherMm <= s.reachMm) return 0;
  // The trunk's own widest chord: its sections above P beyond the junction's reach.
  const double maxMm = 4 * s.parentR + 2 * s.voxMm;
  std::vector<double> trunk;
  for (size_t k : s.above) {
    if (trunk.size() >= ownRadiusPoints) break;
    double widest = 0, narrowest = 0;
    if ((s.q[k] - s.q[s.P]).norm() > s.reachMm && widths(k, maxMm, widest, narrowest)) trunk.push_back(widest);
  }
  if (trunk.empty()) return 0;
  const double own = medianInPlace(trunk);
  const double wideMm = blobWidth(own, s.voxMm);
  for (size_t i = 0; i < s.shared.size(); ++i) {
    double widest = 0, narrowest = 0;
    if (widths(s.shared[i], maxMm, widest, narrowest) && widest > wideMm) return i;
  }
  return s.shared.size();
}

bool twoLumens(double ownA, double ownB, size_t b, const std::vector<std::vector<int32_t>>& children,
               const std::vector<Vec3>& q, const std::vector<size_t>& shared, double voxMm, const SectionLobes& lobes) {
  const auto first = [&](size_t i) { return q[static_cast<size_t>(children[b][i])]; };
  if ((first(0) - first(1)).norm() < voxMm) return false;
  const double reachMm = 2 * (ownA + ownB) + 2 * voxMm;
  size_t two = 0;
  for (size_t s : shared) {
    Vec3 e1, e2;
    double ra = 0, rb = 0;
    two += twoDiscs(lobes, s, q[s], ownA, ownB, voxMm, reachMm, e1, e2, ra, rb) ? 1 : 0;
  }
  return 2 * two >= shared.size();
}

bool ontoSibling(const JunctionInput& in, size_t k, const std::vector<size_t>& sibling, const Vec3& p) {
  return in.raw && !sibling.empty() && (p - in.raw(k)).norm() > (p - in.raw(sibling[0])).norm();
}

}  // namespace vs::centreline_detail
