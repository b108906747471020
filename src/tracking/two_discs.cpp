// A cross-section fitted as two discs (session 24's placeOverlaps; session 26: splitForks' evidence
// of two lumens side by side). See centreline_junctions.h.
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/centreline_junctions.h"
#include "util/median.h"

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

// Distance from p to the polyline through pts[arm[0]], pts[arm[1]], ... (infinite for fewer than two points).
static double toArm(const Vec3& p, const std::vector<Vec3>& pts, const std::vector<size_t>& arm) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j + 1 < arm.size(); ++j) {
    const Vec3 a = pts[arm[j]], d = pts[arm[j + 1]] - a;
    const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-12), 0.0, 1.0);
    best = std::min(best, (p - (a + t * d)).norm());
  }
  return best;
}

// Whether the chain from arm[i] to arm[lastTwo] runs longer than the child's own tube is wide (twice its own radius):
// one-lumen sections along more than that are the lumen's shape, not a local misreading of two fused tubes.
static bool oneLumenRun(const std::vector<Vec3>& q, const std::vector<size_t>& arm, size_t i, size_t lastTwo,
                        double ownMm) {
  double run = 0;
  for (size_t j = i; j < lastTwo && j + 1 < arm.size(); ++j) run += (q[arm[j + 1]] - q[arm[j]]).norm();
  return run > 2 * ownMm;
}

bool placeOverlaps(const OverlapArms& g, const std::vector<double>& radius, const std::vector<Vec3>& q, double voxMm,
                   const SectionLobes& lobes, std::vector<Vec3>& target, std::vector<uint8_t>& moved,
                   std::vector<double>& lobeR, bool freeFork) {
  constexpr size_t ownPoints = 10;
  if (!lobes || g.arms.size() != 3) return true;
  auto chainDistance = [&](const Vec3& p, const std::vector<size_t>& arm) { return toArm(p, q, arm); };
  size_t end[3] = {0, 0, 0};
  double own[3] = {0, 0, 0};
  const double tolMm = std::max(0.5 * voxMm, 0.5 * std::min(g.ownR[1], g.ownR[2]));
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = g.arms[a];
    size_t i = g.zone[a];
    while (i < arm.size() && chainDistance(q[arm[i]], g.arms[3 - a]) <= tolMm) ++i;
    end[a] = i;
    std::vector<double> rr;
    for (size_t j = i; j < arm.size() && j < i + ownPoints; ++j) rr.push_back(radius[arm[j]]);
    if (rr.size() < 3) return false;  // the overlap runs (almost) to the arm's end
    own[a] = medianInPlace(rr);
  }
  if (std::max(own[1], own[2]) > 2 * std::min(own[1], own[2])) return true;
  const double reachMm = 2 * (own[1] + own[2]) + 2 * voxMm;
  std::vector<std::pair<size_t, Vec3>> placed[3];  // per child arm: each placed point and its section's other disc
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = g.arms[a];
    const size_t lower = freeFork ? 0 : g.zone[a];
    if (end[a] <= lower || end[a] >= arm.size()) continue;
    Vec3 prev = target[arm[end[a]]];
    size_t lastTwo = end[a];  // the last section walked that held two lumens (the parting's to start)
    for (size_t i = end[a]; i-- > lower;) {
      const size_t k = arm[i];
      // A point placeParted put in its own lobe stays (its lobe test is the stricter).
      if (!lobeR.empty() && !std::isnan(lobeR[k])) {
        prev = target[k], lastTwo = i;
        continue;
      }
      Vec3 ePlus, eMinus;
      double ra = 0, rb = 0;
      // Two children fused side by side hold two discs from where they part back towards their fork; a section that
      // does not is skipped (a local misreading: 7103's one to three sections near the parting), but where the
      // sections since the last two-disc one (the parting to start) read one lumen along more than the child's own
      // diameter, the two chains are one vessel from there back to the junction zone - the fork is where they part,
      // nothing before it is fitted as two discs (issue 21, session 44 wideT: the head CTA sinus from 150,171,139,
      // whose tree parts at the root's neighbour and whose flat section read two discs at two points 9 mm of one
      // lumen back from the parting, then put 1.8-2.8 mm off the vessel's axis). A free fork's junction zone is
      // fitted section by section as before (session 30; thin seed 25's point there).
      if (!twoDiscs(lobes, k, q[k], own[a], own[3 - a], voxMm, reachMm, ePlus, eMinus, ra, rb)) {
        if (i >= g.zone[a] && oneLumenRun(q, arm, i, lastTwo, own[a])) {
          if (g.zone[a] <= lower) break;
          i = g.zone[a];
        }
        continue;
      }
      lastTwo = i;
      const Vec3 p = (ePlus - prev).norm() <= (eMinus - prev).norm() ? ePlus : eMinus;
      if ((p - q[k]).norm() > std::max(ra, 0.5 * (ra + rb))) continue;
      target[k] = p, moved[k] = 1, prev = p;
      placed[a].emplace_back(k, p == ePlus ? eMinus : ePlus);
      if (!lobeR.empty()) lobeR[k] = ra;
    }
  }
  // Two children fused side by side hold a section's two discs, one each (issue 21, session 39 route124). Where a
  // child's walk back took, at every point it placed over a run longer than the contact's reach (the two own radii
  // together, the fused walk's run), the disc the sibling's placed chain runs through (within the overlap's
  // tolerance, the section's other disc not), its continuity went wrong from its start - across a tight U's bottom
  // the walk's first point lies past the bend, nearer the disc on the U's inside, which is the sibling's where it
  // curls against the U (12124's b1 on b2) - and the child's points go to the other discs where its discrete path's
  // voxels lie nearer those, summed over its placed points (the route is the child's own there; a single section's
  // conflict at a fork - 10602, 511 - is left to continuity). Decided for both arms, then applied.
  if (g.raw && *g.raw) {
    auto placedDistance = [&](const Vec3& p, const std::vector<size_t>& arm) { return toArm(p, target, arm); };
    bool swap[3] = {false, false, false};
    for (size_t a = 1; a < 3; ++a) {
      const std::vector<size_t>& sibling = g.arms[3 - a];
      bool every = !placed[a].empty();
      double nearer = 0;  // the raw voxels' distances to the taken discs less those to the other discs
      for (const auto& [k, otherDisc] : placed[a]) {
        every = every && placedDistance(target[k], sibling) <= tolMm && placedDistance(otherDisc, sibling) > tolMm;
        const Vec3 v = (*g.raw)(k);
        nearer += (target[k] - v).norm() - (otherDisc - v).norm();
      }
      double runMm = 0;  // the placed points' run along the arm
      for (size_t j = 1; j < placed[a].size(); ++j)
        runMm += (target[placed[a][j].first] - target[placed[a][j - 1].first]).norm();
      swap[a] = every && nearer > 0 && runMm > own[1] + own[2];
    }
    for (size_t a = 1; a < 3; ++a)
      if (swap[a])
        for (const auto& [k, otherDisc] : placed[a]) target[k] = otherDisc;
  }
  return true;
}

}  // namespace vs::centreline_detail
