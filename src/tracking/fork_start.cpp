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

bool alongParent(const std::vector<size_t>& up, double parentR, double voxMm, const std::vector<Vec3>& q, size_t b,
                 const Vec3& J) {
  constexpr size_t linePoints = 5;
  if (up.empty()) return true;
  const Vec3 d = q[b] - q[up[std::min(up.size(), linePoints) - 1]];
  if (d.norm() < 1e-9) return true;
  const Vec3 t = d.normalized(), off = J - q[b];
  // J not ahead of b on the parent's course (level with it within a voxel, the grain of placeFork's `before`, or
  // behind): b is at the junction's level and b -> J the fused section's sideways step, not a cut ahead across the
  // lumen between returning limbs (11825).
  if (off.dot(t) < voxMm) return true;
  return (off - off.dot(t) * t).norm() <= parentR;
}

namespace {

// Two discs' centres more than one voxel of the grid apart, each axis in its own spacing (zero: voxMm on every axis):
// not one lumen smeared over the grid (see RunInput).
bool apartOnGrid(const Vec3& e1, const Vec3& e2, const Vec3& spacing, double voxMm) {
  const Vec3 grid = spacing.minCoeff() > 0 ? spacing : Vec3::Constant(voxMm);
  return (e1 - e2).cwiseQuotient(grid).norm() > 1;
}

// Section k as the children's two discs, e1 / e2, and not one lumen smeared over the grid (see RunInput).
bool runSection(const RunInput& in, size_t k, Vec3& e1, Vec3& e2) {
  const double lobeReach = 2 * (in.ownR[1] + in.ownR[2]) + 2 * in.voxMm;  // twoLumens' window
  double ra = 0, rb = 0;
  if (!twoDiscs(in.lobes, k, in.q[k], in.ownR[1], in.ownR[2], in.voxMm, lobeReach, e1, e2, ra, rb)) return false;
  return apartOnGrid(e1, e2, in.spacing, in.voxMm);
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

// Whether every one of the first `count` sections of `arm` is thinner than the narrower child's own tube: its
// narrowest chord (twoDiscs' reading, twoLumens' window) short of that child's diameter by more than a voxel (the
// chord's own sampling).
bool thinnerThanChildren(const RunInput& in, const std::vector<size_t>& arm, size_t count) {
  const double lobeReach = 2 * (in.ownR[1] + in.ownR[2]) + 2 * in.voxMm;  // runSection's
  const double childMm = 2 * std::min(in.ownR[1], in.ownR[2]);
  for (size_t i = 0; i < count && i < arm.size(); ++i) {
    Vec3 d;
    double plus = 0, minus = 0, narrowest = 0;
    if (!in.lobes(arm[i], lobeReach, d, plus, minus, narrowest) || narrowest + in.voxMm >= childMm) return false;
  }
  return count > 0;
}

}  // namespace

bool twoDiscRun(const RunInput& in, size_t b, FusedRun& run, Vec3& J, Vec3 (&G)[3]) {
  const auto& arms = in.arms;
  if (!in.lobes || arms.size() != 3 || in.ownR.size() != 3 || !in.hasLine[1] || !in.hasLine[2]) return false;
  const std::vector<size_t>& up = arms[0];
  run = FusedRun{};
  run.up = runLength(in, up);
  if (run.up == 0 || run.up >= up.size()) return false;
  // Two children side by side are each as thick as its own tube: across their line the fused section is at least the
  // narrower child's diameter. A run up the parent arm whose every section is thinner than that by more than a voxel
  // holds no two discs of the children's size - it is one flat lumen, wider than it is thick, which twoDiscs reads as
  // two discs at its ends (the head CTA's sinus from 83,41,53: narrowest 4.0-5.3 mm against the children's 6.4-6.8 mm;
  // the family's fused runs up 1.0-1.35 x their children's diameter): the fork is left where the tree branches (issue
  // 21, session 45 sinus83).
  if (thinnerThanChildren(in, up, run.up)) return false;
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
  const auto& arms = in.arms;
  Vec3 O[3], D[3];  // each child's axis line past its zone and its run
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = arms[a];
    size_t s = std::max(in.zone[a], run.arm[a]);
    if (s + 3 > arm.size() || (q[arm[std::min(arm.size(), s + linePoints) - 1]] - q[arm[s]]).norm() < in.voxMm)
      s = in.zone[a];  // hasLine: an axis past the zone
    O[a] = q[arm[s]], D[a] = (q[arm[std::min(arm.size(), s + linePoints) - 1]] - O[a]).normalized();
  }
  const auto off = [&](size_t a, const Vec3& p) {  // p's distance from child a's axis line (both ways)
    const Vec3 v = p - O[a];
    return (v - v.dot(D[a]) * D[a]).norm();
  };
  bool apart = false;
  const auto section = [&](size_t k, Vec3& e1, Vec3& e2) {  // a run section; its discs apart: not this fork's
    if (!runSection(in, k, e1, e2)) return false;
    apart = apart || (e1 - e2).norm() > in.ownR[1] + in.ownR[2];
    return true;
  };
  // Each child's chain through the fused stretch: P, the shared points (its place: kept / copied), its arm's points
  // up to its first round section past the run (the zones' lumen test); `at` true where a place is set.
  struct Link {
    size_t k;
    Vec3 p;
    bool at;
  };
  std::vector<Link> chain[3];
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = arms[a];
    size_t r = run.arm[a];
    while (r < arm.size() && in.fusedAt(arm[r], 1.5 * in.ownR[a] + in.voxMm)) ++r;
    const size_t end = r < arm.size() ? r + 1 : run.arm[a];  // fused to its end: the run's points only
    for (size_t j = 0; j < end; ++j) {
      Vec3 own = q[arm[j]], other;
      bool at = j == r;  // the round section's point
      if (j < run.arm[a] && (at = section(arm[j], own, other)) &&
          off(a, other) + off(3 - a, own) < off(a, own) + off(3 - a, other))
        std::swap(own, other);  // the way that puts the discs nearer the children's axis lines
      chain[a].push_back({arm[j], own, at});
    }
  }
  // The shared sections, from b up. fused37's choice - the way that puts the discs nearer the children's axis lines -
  // where both lines run along their arms' start (b -> the line's origin within analyseFork's continuation cone, 30
  // degrees): lines extended back to b then describe the children there (11902's children cross at b; 12024's).
  // Else a child turns past its zone (11932's b11, a tight U whose line points back across b12) and each child takes
  // the disc nearer its chain's place below, from its first placed point past b (placeOverlaps' continuity; in voxels
  // of the grid, as the run's smear test: across thick slices a thin tube's place is known to a slice).
  const size_t other = 3 - keep;
  const double continueCos = std::cos(30.0 * M_PI / 180.0);  // analyseFork's
  bool linesHold = true;
  Vec3 below[3] = {Vec3::Zero(), q[shared.back()], q[shared.back()]};
  for (size_t a = 1; a < 3; ++a) {
    linesHold = linesHold && D[a].dot((O[a] - q[shared.back()]).normalized()) >= continueCos;
    for (const Link& l : chain[a])
      if (l.at) {
        below[a] = l.p;
        break;
      }
  }
  const Vec3 grid = in.spacing.minCoeff() > 0 ? in.spacing : Vec3::Constant(in.voxMm);
  const auto apartVox = [&](const Vec3& u, const Vec3& v) { return (u - v).cwiseQuotient(grid).norm(); };
  std::vector<uint8_t> isRun(shared.size(), 0);
  for (size_t i = shared.size(); i-- > 0;) {
    Vec3 e1, e2;
    if (!section(shared[i], e1, e2)) continue;
    if (linesHold ? off(keep, e2) + off(other, e1) < off(keep, e1) + off(other, e2)
                  : apartVox(e2, below[keep]) + apartVox(e1, below[other]) <
                        apartVox(e1, below[keep]) + apartVox(e2, below[other]))
      std::swap(e1, e2);
    kept[i] = below[keep] = e1, copied[i] = below[other] = e2, isRun[i] = 1;
  }
  if (apart) return false;
  const size_t P = arms[0][run.up];
  for (size_t a = 1; a < 3; ++a) {
    std::vector<Link> c{{P, q[P], true}};
    for (size_t i = 0; i < shared.size(); ++i) c.push_back({shared[i], a == keep ? kept[i] : copied[i], isRun[i] != 0});
    c.insert(c.end(), chain[a].begin(), chain[a].end());
    // A point between placed ones whose section twoDiscs refuses goes onto the line between its placed neighbours
    // (its projection: contact36's line rule), not left to the rounds, which centre it on the fused blob.
    for (size_t i = 1; i + 1 < c.size(); ++i) {
      if (c[i].at) continue;
      size_t n = i + 1;
      while (n < c.size() && !c[n].at) ++n;
      if (n == c.size()) break;  // no placed point past it (the arm fused to its end): left to the rounds
      const Vec3 A = c[i - 1].p, seg = c[n].p - A;
      const double t = std::clamp((q[c[i].k] - A).dot(seg) / std::max(seg.squaredNorm(), 1e-12), 0.0, 1.0);
      c[i].p = A + t * seg, c[i].at = true;
      if (i <= shared.size()) (a == keep ? kept : copied)[i - 1] = c[i].p;
    }
    for (size_t i = shared.size() + 1; i + 1 < c.size(); ++i) q[c[i].k] = c[i].p, frozen[c[i].k] = 1;
  }
  return true;
}

bool twoLumens(double ownA, double ownB, size_t b, const std::vector<std::vector<int32_t>>& children,
               const std::vector<Vec3>& q, const std::vector<size_t>& shared, double voxMm, const SectionLobes& lobes,
               const Vec3& spacing) {
  const auto first = [&](size_t i) { return q[static_cast<size_t>(children[b][i])]; };
  if ((first(0) - first(1)).norm() < voxMm) return false;
  const double reachMm = 2 * (ownA + ownB) + 2 * voxMm;
  size_t two = 0;
  for (size_t s : shared) {
    Vec3 e1, e2;
    double ra = 0, rb = 0;
    two += twoDiscs(lobes, s, q[s], ownA, ownB, voxMm, reachMm, e1, e2, ra, rb) && apartOnGrid(e1, e2, spacing, voxMm);
  }
  return 2 * two >= shared.size();
}

bool ontoSibling(const JunctionInput& in, size_t k, const std::vector<size_t>& sibling, const Vec3& p) {
  return in.raw && !sibling.empty() && (p - in.raw(k)).norm() > (p - in.raw(sibling[0])).norm();
}

}  // namespace vs::centreline_detail
