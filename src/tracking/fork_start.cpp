// Where a re-branched fork starts (session 36 fork36), splitForks' evidence of two lumens side by side (session 26),
// placeFork's refusal of a child's point laid onto the sibling's side (session 36), and a narrow fused fork's shared
// stretch seen as the children's two discs (session 36 shared36, session 37 fused37). See centreline_junctions.h.
#include <algorithm>
#include <cmath>
#include <utility>
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

namespace {

// Section k as the children's two discs, e1 / e2, and not one lumen smeared over the grid (see RunInput).
bool runSection(const RunInput& in, size_t k, Vec3& e1, Vec3& e2) {
  const double lobeReach = 2 * (in.ownR[1] + in.ownR[2]) + 2 * in.voxMm;  // twoLumens' window
  double ra = 0, rb = 0;
  if (!twoDiscs(in.lobes, k, in.q[k], in.ownR[1], in.ownR[2], in.voxMm, lobeReach, e1, e2, ra, rb)) return false;
  const Vec3 grid = in.spacing.minCoeff() > 0 ? in.spacing : Vec3::Constant(in.voxMm);
  return (e1 - e2).cwiseQuotient(grid).norm() > 1;
}

// The count of run sections from the start of `arm` on.
size_t runLength(const RunInput& in, const std::vector<size_t>& arm) {
  size_t i = 0;
  for (Vec3 e1, e2; i < arm.size() && runSection(in, arm[i], e1, e2);) ++i;
  return i;
}

// The arc length along `arm` from its start to its point i (inclusive), from `from`.
double arcTo(const std::vector<Vec3>& q, const Vec3& from, const std::vector<size_t>& arm, size_t i) {
  double arc = 0;
  Vec3 prev = from;
  for (size_t j = 0; j <= i && j < arm.size(); ++j) arc += (q[arm[j]] - prev).norm(), prev = q[arm[j]];
  return arc;
}

}  // namespace

bool twoDiscRun(const RunInput& in, size_t b, FusedRun& run, Vec3& J, Vec3 (&G)[3]) {
  const auto& arms = in.arms;
  if (!in.lobes || arms.size() != 3 || in.ownR.size() != 3 || !in.hasLine[1] || !in.hasLine[2]) return false;
  const std::vector<size_t>& up = arms[0];
  run = FusedRun{};
  run.up = runLength(in, up);
  if (run.up == 0 || run.up >= up.size()) return false;
  for (size_t a = 1; a < 3; ++a) run.arm[a] = runLength(in, arms[a]);
  const double upMm = arcTo(in.q, in.q[b], up, run.up - 1);
  double runMm = upMm;
  if (run.arm[1] > 0 && run.arm[2] > 0)
    runMm += std::min(arcTo(in.q, in.q[b], arms[1], run.arm[1] - 1), arcTo(in.q, in.q[b], arms[2], run.arm[2] - 1));
  // The junction's reach (the parent's radius + the wider child's): a fused stretch within it is the junction zone's.
  if (runMm <= in.ownR[0] + std::max(in.ownR[1], in.ownR[2])) return false;
  J = in.q[up[run.up]];
  for (size_t a = 1; a < 3; ++a) G[a] = in.q[arms[a][in.zone[a]]];  // hasLine: the arm goes on past its zone
  return true;
}

bool runDiscs(const RunInput& in, const FusedRun& run, const std::vector<size_t>& shared, size_t keep,
              std::vector<Vec3>& kept, std::vector<Vec3>& copied, std::vector<Vec3>& q, std::vector<uint8_t>& frozen) {
  constexpr size_t linePoints = 5;  // analyseFork's
  Vec3 O[3], D[3];                  // each child's axis line past its zone and its run
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = in.arms[a];
    size_t s = std::max(in.zone[a], run.arm[a]);
    if (s + 3 > arm.size() || (q[arm[std::min(arm.size(), s + linePoints) - 1]] - q[arm[s]]).norm() < in.voxMm)
      s = in.zone[a];  // hasLine: an axis past the zone
    O[a] = q[arm[s]], D[a] = (q[arm[std::min(arm.size(), s + linePoints) - 1]] - O[a]).normalized();
  }
  const auto off = [&](size_t a, const Vec3& p) {  // p's distance from child a's axis line (both ways)
    const Vec3 v = p - O[a];
    return (v - v.dot(D[a]) * D[a]).norm();
  };
  // Section k's disc for child a (the other disc is the sibling's), or false where k is no run section.
  const auto discFor = [&](size_t a, size_t k, Vec3& own, Vec3& other, bool& apart) {
    Vec3 e1, e2;
    if (!runSection(in, k, e1, e2)) return false;
    apart = apart || (e1 - e2).norm() > in.ownR[1] + in.ownR[2];
    const bool swap = off(a, e2) + off(3 - a, e1) < off(a, e1) + off(3 - a, e2);
    own = swap ? e2 : e1, other = swap ? e1 : e2;
    return true;
  };
  bool apart = false;
  std::vector<std::pair<size_t, Vec3>> placed;
  for (size_t i = 0; i < shared.size(); ++i) discFor(keep, shared[i], kept[i], copied[i], apart);
  for (size_t a = 1; a < 3; ++a)
    for (size_t j = 0; j < run.arm[a]; ++j) {
      Vec3 own, other;
      if (discFor(a, in.arms[a][j], own, other, apart)) placed.emplace_back(in.arms[a][j], own);
    }
  if (apart) return false;
  for (const auto& [k, p] : placed) q[k] = p, frozen[k] = 1;  // in.q is q: read above, written once decided
  return true;
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
