// Fork centring (session 35 centre35): the shared chain's points in a fork's fused junction blob put back on the
// trunk's curve. See centreline_junctions.h (centreForkTrunks).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include "tracking/centreline_junctions.h"
#include "util/median.h"

namespace vs::centreline_detail {

Vec3 hermite(const Vec3& a, const Vec3& ta, const Vec3& b, const Vec3& tb, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * a + (s3 - 2 * s2 + s) * ta + (-2 * s3 + 3 * s2) * b + (s3 - s2) * tb;
}

Vec3 chainCurveAt(const JunctionInput& in, const std::vector<Vec3>& q, size_t a, size_t b, double s) {
  const Vec3 chord = q[b] - q[a];
  const double L = chord.norm();
  if (L < 1e-9) return q[a];
  // The chain's direction beyond an end: to the end from the point chainTangentSteps up the tree past a, and from b to
  // the point so far down its plain chain past b (fewer where the chain stops); the chord's where there is none.
  auto beyond = [&](size_t end, bool up) {
    size_t j = end;
    for (size_t i = 0; i < chainTangentSteps; ++i) {
      const int32_t next = up ? in.parent[j] : (in.children[j].size() == 1 ? in.children[j][0] : -1);
      if (next < 0) break;
      j = static_cast<size_t>(next);
    }
    const Vec3 d = up ? Vec3(q[end] - q[j]) : Vec3(q[j] - q[end]);
    return d.norm() < 1e-9 ? Vec3(chord / L) : Vec3(d.normalized());
  };
  return hermite(q[a], L * beyond(a, true), q[b], L * beyond(b, false), s);
}

namespace {

constexpr size_t tangentSteps = chainTangentSteps;
constexpr int curveSamples = 64;

// The sample of the Hermite segment from a (direction ta) to b (direction tb, both scaled by |b - a|) nearest x, of
// curveSamples + 1 along it: its position, its parameter in *at and its distance to x in *dist.
Vec3 nearestOnCurve(const Vec3& a, const Vec3& ta, const Vec3& b, const Vec3& tb, const Vec3& x, double* at,
                    double* dist) {
  const double L = (b - a).norm();
  *dist = 1e300, *at = 0;
  Vec3 best = a;
  for (int s = 0; s <= curveSamples; ++s) {
    const double t = double(s) / curveSamples;
    const Vec3 p = hermite(a, L * ta, b, L * tb, t);
    if ((p - x).norm() < *dist) *dist = (p - x).norm(), *at = t, best = p;
  }
  return best;
}

// The plain chain from `start` (included) up towards the root or down along single children, to the next branch
// point (excluded) or end; at most maxPoints.
std::vector<size_t> plainArm(const JunctionInput& in, int32_t start, bool up, size_t maxPoints) {
  std::vector<size_t> a;
  for (int32_t p = start; p >= 0 && a.size() < maxPoints;) {
    const size_t k = static_cast<size_t>(p);
    if (in.children[k].size() >= 2) break;
    a.push_back(k);
    if (k == 0) break;
    p = up ? in.parent[k] : (in.children[k].size() == 1 ? in.children[k][0] : -1);
  }
  return a;
}

// An arm's own radius: the median of its points' radii beyond reachMm from the branch point (at most ownRadiusPoints of
// them); a short arm: its far half. 0 where none has a radius.
double ownRadius(const JunctionInput& in, const std::vector<size_t>& arm, const std::vector<Vec3>& q, const Vec3& b,
                 double reachMm) {
  std::vector<double> r;
  for (size_t i = 0; i < arm.size() && r.size() < ownRadiusPoints; ++i)
    if ((q[arm[i]] - b).norm() > reachMm && in.radius[arm[i]] > 0) r.push_back(in.radius[arm[i]]);
  for (size_t i = arm.size() / 2; r.empty() && i < arm.size(); ++i)
    if (in.radius[arm[i]] > 0) r.push_back(in.radius[arm[i]]);
  return medianInPlace(r);
}

// The unit direction from arm[i] to the point tangentSteps further along the arm (fewer where the arm is shorter);
// false where there is none.
bool armDirection(const std::vector<size_t>& arm, size_t i, const std::vector<Vec3>& q, Vec3& d) {
  const size_t e = std::min(arm.size() - 1, i + tangentSteps);
  if (e <= i) return false;
  d = q[arm[e]] - q[arm[i]];
  if (d.norm() < 1e-9) return false;
  d.normalize();
  return true;
}

struct ChildEnd {
  Vec3 G, tG;  // the child's first unfused point and its direction outward
  double r = 0;
  double alongMm = 0;  // the chain's length from the branch point to G
};

// The chain's length through the points `pts` in order.
double chainLength(const std::vector<Vec3>& q, const std::vector<size_t>& pts) {
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += (q[pts[i]] - q[pts[i - 1]]).norm();
  return len;
}

// The junction's reach from a chain's start along `up`: 1.5 of its first points' radii + 2 voxels, as the junction
// zones'.
double junctionReach(const JunctionInput& in, const std::vector<size_t>& up, double voxMm) {
  std::vector<double> first;
  for (size_t i = 0; i < up.size() && i < 20; ++i)
    if (in.radius[up[i]] > 0) first.push_back(in.radius[up[i]]);
  return 1.5 * medianInPlace(first) + 2 * voxMm;
}

// A junction the tree does not fork at (session 37 cross37; centreline_junctions.h: centreForkTrunks' second part):
// per plain chain point k whose chain runs on both ways past the junction's reach (from its traced forks and ends), the
// chain's own radius up and down (ownRadius past the reach); where the two differ by more than the blob's margin
// (blobWidth: the chain passes from a tube into a narrower one, a sibling left there), the wider is one the rays
// resolve (at most wideRadii x maxRadiusMm: wider ones are the wide trunk's) and k is wider than both, the run of
// such points round k is the junction's fused blob - if it is a bump (its widest section wider than blobWidth of both
// its ends') and no point off the chain lies in it (their lumens overlapping: the sibling's start is traced by no
// path, so no fork is there to centre). The run goes onto the chain's own curve: the Hermite segment from the first
// point up at or under the wider radius (along the chain) to the first point down so (along the chain), within the
// two radii together of each other twice over (a junction's zone), each point by more than half a voxel and at most
// the narrower radius; its radius interpolated. Returns the count moved.
size_t centreUnforkedJunctions(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                               double voxMm, std::vector<Vec3>& q, std::vector<double>& radiusOut,
                               std::vector<uint8_t>& taken) {
  const size_t n = q.size();
  const bool debug = std::getenv("VS_FORK_CENTRE_DEBUG") != nullptr;
  std::vector<std::pair<size_t, std::pair<Vec3, double>>> moves;
  const auto reachesPast = [&](const std::vector<size_t>& arm, const Vec3& x, double reachMm) {
    return !arm.empty() && (q[arm.back()] - x).norm() > reachMm;
  };
  for (size_t k = 1; k < n; ++k) {
    if (taken[k] || frozen[k] || in.children[k].size() != 1 || in.parent[k] < 0 || !(in.radius[k] > 0)) continue;
    const std::vector<size_t> up = plainArm(in, in.parent[k], true, 60);
    const std::vector<size_t> down = plainArm(in, in.children[k][0], false, 60);
    if (up.size() < tangentSteps + 2 || down.size() < tangentSteps + 2) continue;
    const double reachMm = junctionReach(in, up, voxMm);
    if (!reachesPast(up, q[k], reachMm) || !reachesPast(down, q[k], reachMm)) continue;
    const double rUp = ownRadius(in, up, q, q[k], reachMm), rDown = ownRadius(in, down, q, q[k], reachMm);
    if (!(rUp > 0) || !(rDown > 0)) continue;
    const double wider = std::max(rUp, rDown), narrower = std::min(rUp, rDown);
    if (wider <= blobWidth(narrower, voxMm) || wider > o.wideRadii * o.maxRadiusMm || in.radius[k] <= wider) continue;
    // The run round k wider than both, and its ends A (up) and G (down).
    size_t ia = 0, ig = 0;
    while (ia < up.size() && in.radius[up[ia]] > wider) ++ia;
    while (ig < down.size() && in.radius[down[ig]] > wider) ++ig;
    if (ia >= up.size() || ig >= down.size()) continue;
    const Vec3 A = q[up[ia]], G = q[down[ig]];
    const double L = (G - A).norm();
    Vec3 tA, tG;
    if (L > 2 * (rUp + rDown) || !armDirection(up, ia, q, tA) || !armDirection(down, ig, q, tG)) continue;
    tA = -tA;  // towards the run
    std::vector<size_t> run(up.rend() - static_cast<std::ptrdiff_t>(ia), up.rend());
    run.push_back(k);
    run.insert(run.end(), down.begin(), down.begin() + static_cast<std::ptrdiff_t>(ig));
    // A bump: its widest section wider than blobWidth of both ends' (a tube's own calibre running on is none).
    double peak = 0;
    for (size_t j : run) peak = std::max(peak, in.radius[j]);
    if (peak <= blobWidth(std::max(in.radius[up[ia]], in.radius[down[ig]]), voxMm)) continue;
    // The sibling's start traced by no path: no point off this plain chain lies in the blob (their lumens touching).
    std::vector<uint8_t> chain(n, 0);
    for (const std::vector<size_t>* arm : {&up, &down})
      for (size_t j : *arm) chain[j] = 1;
    chain[k] = 1;
    bool traced = false;
    for (size_t m = 0; m < n && !traced; ++m)
      for (size_t j : run)
        if (!chain[m] && (q[m] - q[j]).norm() < in.radius[m] + in.radius[j]) traced = true;
    if (debug && traced) std::fprintf(stderr, "[cross37] point %zu: the blob's sibling traced\n", k);
    if (traced) {
      for (size_t j : run) taken[j] = 1;
      continue;
    }
    for (size_t j : run) {
      taken[j] = 1;
      if (frozen[j]) continue;
      double best = 0, bestS = 0;
      const Vec3 at = nearestOnCurve(A, tA, G, tG, q[j], &bestS, &best);
      if (debug)
        std::fprintf(stderr, "[cross37] point %zu r %.2f up %.2f down %.2f run %zu shift %.2f\n", j, in.radius[j], rUp,
                     rDown, run.size(), best);
      if (best <= 0.5 * voxMm || best > narrower) continue;
      moves.push_back({j, {at, in.radius[up[ia]] + (in.radius[down[ig]] - in.radius[up[ia]]) * bestS}});
    }
  }
  for (const auto& [k, m] : moves) q[k] = m.first, radiusOut[k] = m.second;
  return moves.size();
}

}  // namespace

size_t centreForkTrunks(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                        double voxMm, std::vector<Vec3>& q, std::vector<double>& radiusOut) {
  if (!o.junctions || o.iterations <= 0) return 0;
  const size_t n = q.size();
  const bool debug = std::getenv("VS_FORK_CENTRE_DEBUG") != nullptr;
  std::vector<std::pair<size_t, std::pair<Vec3, double>>> moves;
  std::vector<uint8_t> taken(n, 0);
  for (size_t b = 1; b < n; ++b) {
    if (in.children[b].size() < 2 || in.parent[b] < 0) continue;
    const std::vector<size_t> up = plainArm(in, in.parent[b], true, 60);
    if (up.size() < tangentSteps + 2) continue;
    // The trunk's radius: its points beyond the junction's reach.
    const double reachMm = junctionReach(in, up, voxMm);
    const double trunkR = ownRadius(in, up, q, q[b], reachMm);
    if (!(trunkR > 0)) continue;
    // The children: their own radii and first unfused points past the junction zone (trunk + child radius from b).
    std::vector<std::vector<size_t>> arms;
    std::vector<double> childR;
    double widestChild = 0;
    for (int32_t c : in.children[b]) {
      arms.push_back(plainArm(in, c, false, 60));
      childR.push_back(ownRadius(in, arms.back(), q, q[b], reachMm));
      widestChild = std::max(widestChild, childR.back());
    }
    const double zoneMm = trunkR + widestChild;
    const auto wide = [&](size_t k, double own) { return in.radius[k] > blobWidth(own, voxMm); };
    std::vector<ChildEnd> ends;
    for (size_t a = 0; a < arms.size(); ++a) {
      if (!(childR[a] > 0)) continue;
      for (size_t i = 0; i < arms[a].size(); ++i) {
        const size_t k = arms[a][i];
        if ((q[k] - q[b]).norm() < zoneMm || wide(k, childR[a])) continue;
        std::vector<size_t> toG(1, b);
        toG.insert(toG.end(), arms[a].begin(), arms[a].begin() + static_cast<std::ptrdiff_t>(i) + 1);
        ChildEnd e{q[k], Vec3::Zero(), in.radius[k], chainLength(q, toG)};
        if (armDirection(arms[a], i, q, e.tG)) ends.push_back(e);
        break;
      }
    }
    if (debug)
      std::fprintf(
          stderr,
          "[centre35] fork %zu r %.2f frozen %d at %.1f %.1f %.1f up %zu trunk %.2f zone %.2f ends %zu children %zu\n",
          b, in.radius[b], int(frozen[b]), q[b][0], q[b][1], q[b][2], up.size(), trunkR, zoneMm, ends.size(),
          arms.size());
    if (ends.empty()) continue;
    // The blob's points on the shared chain (the branch point first): within the zone, wider than the trunk (`wide`),
    // not placed.
    std::vector<size_t> blob;
    if (wide(b, trunkR) && !frozen[b]) blob.push_back(b);
    size_t last = 0;  // the index in `up` past the farthest blob point
    for (size_t i = 0; i < up.size() && (q[up[i]] - q[b]).norm() < zoneMm; ++i)
      if (wide(up[i], trunkR) && !frozen[up[i]]) blob.push_back(up[i]), last = i + 1;
    if (blob.empty()) continue;
    // The trunk's last unfused point A above them, and its direction towards the fork.
    size_t ia = last;
    while (ia < up.size() && wide(up[ia], trunkR) && (q[up[ia]] - q[b]).norm() < 2 * zoneMm) ++ia;
    if (ia >= up.size() || wide(up[ia], trunkR)) continue;
    Vec3 tA;
    if (!armDirection(up, ia, q, tA)) continue;
    tA = -tA;  // towards the fork
    const Vec3 A = q[up[ia]];
    const double rA = in.radius[up[ia]];
    // The trunk turned round before the fork (session 39 ubottom, 12124's U bottom): every child's direction at its
    // end turns back against the trunk's at A (over 90 degrees, the walks' turn back). The chord A-G then measures the
    // U's width, not the chain's run round it, and a curve scaled by it cuts the U's inside: each curve is scaled by
    // the chain's own length from A through the branch point to G instead, and each blob point goes to its share of
    // that length from A along it (a point the chords drew to the U's inside has no nearest curve point of its own).
    bool turnedRound = true;
    for (const ChildEnd& e : ends) turnedRound = turnedRound && tA.dot(e.tG) < 0;
    std::vector<size_t> toA(1, b);
    toA.insert(toA.end(), up.begin(), up.begin() + static_cast<std::ptrdiff_t>(ia) + 1);
    const double upAlong = chainLength(q, toA);
    for (size_t k : blob) {
      if (taken[k]) continue;
      Vec3 sum = Vec3::Zero();
      double rSum = 0;
      double fromB = 0;  // the chain's length from the branch point up to k
      for (size_t i = 0, prev = b; k != b && i < up.size(); prev = up[i], ++i) {
        fromB += (q[up[i]] - q[prev]).norm();
        if (up[i] == k) break;
      }
      for (const ChildEnd& e : ends) {
        double best = 0, bestS = 0;
        if (turnedRound) {
          const double along = upAlong + e.alongMm;
          bestS = std::clamp((upAlong - fromB) / along, 0.0, 1.0);
          sum += hermite(A, along * tA, e.G, along * e.tG, bestS), rSum += rA + (e.r - rA) * bestS;
          continue;
        }
        sum += nearestOnCurve(A, tA, e.G, e.tG, q[k], &bestS, &best), rSum += rA + (e.r - rA) * bestS;
      }
      const Vec3 target = sum / double(ends.size());
      const double shift = (target - q[k]).norm();
      if (debug)
        std::fprintf(stderr, "[centre35] fork %zu point %zu r %.2f trunk %.2f zone %.2f shift %.2f curves %zu\n", b, k,
                     in.radius[k], trunkR, zoneMm, shift, ends.size());
      // Only a point off the curve by more than half a voxel, and not beyond the trunk's radius (the curve is the
      // trunk's axis, inside its lumen).
      // Turned round: the curve within the trunk's radius of the point or of its own path voxel (the route's voxel in
      // the trunk's lumen; the chords drew the point to the U's inside, towards whatever lies there).
      const bool nearRaw = turnedRound && in.raw && (target - in.raw(k)).norm() <= trunkR;
      if (shift <= 0.5 * voxMm || (shift > trunkR && !nearRaw)) continue;
      taken[k] = 1;
      moves.push_back({k, {target, rSum / double(ends.size())}});
    }
  }
  for (const auto& [k, m] : moves) q[k] = m.first, radiusOut[k] = m.second, taken[k] = 1;
  return moves.size() + centreUnforkedJunctions(in, frozen, o, voxMm, q, radiusOut, taken);
}

}  // namespace vs::centreline_detail
