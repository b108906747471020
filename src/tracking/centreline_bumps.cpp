// Steps and placements of refineCentreline's points beside the rays' own rules (centreline_junctions.h).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

Vec3 clampedStep(const CentrelineOptions& o, double rayMm, double radiusBefore, double medianChord, Vec3 off) {
  double maxStep = rayMm > o.maxRadiusMm ? std::max(o.maxStepMm, o.maxStepRadii * 0.5 * medianChord) : o.maxStepMm;
  if (radiusBefore < maxStep) maxStep = std::max(o.maxStepMm, radiusBefore);
  if (off.norm() > maxStep) off *= maxStep / off.norm();
  return off;
}

namespace {

// From point k along its plain chain (up: towards the root; down: its one child), the first point whose radius is at
// most `limit` within `reachMm` along the input points (`along`: the distance walked); -1 where a branch point, a
// placed (frozen) point, an end or the reach comes first.
int64_t narrowerAlong(const JunctionInput& in, const std::vector<uint8_t>& frozen, size_t k, bool up, double limit,
                      double reachMm, double& along) {
  along = 0;
  for (size_t at = k;;) {
    const int64_t next = up ? in.parent[at] : in.children[at].size() == 1 ? in.children[at][0] : -1;
    if (next < 0) return -1;
    const size_t j = static_cast<size_t>(next);
    along += (in.raw(j) - in.raw(at)).norm();
    if (along > reachMm || frozen[j]) return -1;
    if (in.radius[j] <= limit) return next;
    if (in.children[j].size() != 1) return -1;  // a branch point or an end before a narrower point
    at = j;
  }
}

// Distances along the tree (path voxels) from point k to the points within `boundMm` of it that way.
std::unordered_map<size_t, double> alongTreeWithin(const JunctionInput& in, size_t k, double boundMm) {
  std::unordered_map<size_t, double> d{{k, 0.0}};
  std::vector<size_t> stack{k};
  while (!stack.empty()) {
    const size_t at = stack.back();
    stack.pop_back();
    auto visit = [&](int64_t next) {
      if (next < 0 || d.count(size_t(next))) return;
      const double w = d[at] + (in.raw(size_t(next)) - in.raw(at)).norm();
      if (w > boundMm) return;
      d[size_t(next)] = w;
      stack.push_back(size_t(next));
    };
    visit(in.parent[at]);
    for (const int32_t c : in.children[at]) visit(c);
  }
  return d;
}

// The evidence of a second tube in point k's blob: a path voxel of another stretch of the tree (its way to k along
// the tree over o.fusedBumpDetour x their straight distance: not the own chain, not a wide fork's sibling) within the
// blob's radius of the point, and farther from `to` (the place the point would go to) than from the point: the point
// was pulled towards that tube and goes back away from it. Meant to leave a real widening (a sinus, a junction's
// flare) alone; on the head CTA's network it does not (docs/notes/tracking.md, session 27 kiss22: not merged).
bool otherTubeInBlob(const JunctionInput& in, const std::vector<Vec3>& q, const CentrelineOptions& o, size_t k,
                     const Vec3& to, const std::function<double(size_t, const Vec3&)>& ownShare) {
  const double blob = in.radius[k], straightMax = blob + (q[k] - in.raw(k)).norm();
  const auto along = alongTreeWithin(in, k, o.fusedBumpDetour * straightMax);
  for (size_t j = 0; j < q.size(); ++j) {
    const Vec3 v = in.raw(j);
    if ((v - q[k]).norm() >= blob || (v - to).norm() <= (v - q[k]).norm()) continue;
    const auto it = along.find(j);
    if (it != along.end() && it->second <= o.fusedBumpDetour * (v - in.raw(k)).norm()) continue;
    // share at q[k] is 1 by definition
    const double ends = std::max(ownShare(k, to), ownShare(k, v));
    if (std::getenv("VS_KISS22_DEBUG"))
      std::fprintf(stderr, "[k5] k %zu j %zu ends %.3f at %.3f v %.3f\n", k, j, ends, ownShare(k, to), ownShare(k, v));
    const double need = std::getenv("VS_KISS22_PEAK") ? std::atof(std::getenv("VS_KISS22_PEAK")) : 0.0;
    if (ends >= need) return true;
  }
  return false;
}

}  // namespace

void bridgeFusedBumps(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                      std::vector<Vec3>& q, const std::function<double(size_t, const Vec3&)>& ownShare) {
  if (!(o.fusedBumpRadii > 1) || !(o.fusedBumpReachRadii > 0)) return;
  std::vector<Vec3> out = q;
  for (size_t k = 1; k < q.size(); ++k) {
    if (frozen[k] || in.children[k].size() != 1 || in.parent[k] < 0) continue;
    const double limit = in.radius[k] / o.fusedBumpRadii, reach = o.fusedBumpReachRadii * in.radius[k];
    double up = 0, down = 0;
    const int64_t a = narrowerAlong(in, frozen, k, true, limit, reach, up);
    const int64_t b = a < 0 ? -1 : narrowerAlong(in, frozen, k, false, limit, reach - up, down);
    if (b < 0) continue;
    const double t = up / (up + down);
    const Vec3 at = q[size_t(a)] + (q[size_t(b)] - q[size_t(a)]) * t;
    // The path voxel lies in the own lumen, so its centre lies within the own radius of it: a line farther than that
    // cuts across the tube's bends (on the head CTA's network, runs of bridged points kinked against their neighbours).
    const double own = in.radius[size_t(a)] + (in.radius[size_t(b)] - in.radius[size_t(a)]) * t;
    if ((at - in.raw(k)).norm() <= own && ownShare(k, at) >= 0.5 &&
        (!(o.fusedBumpDetour > 0) || otherTubeInBlob(in, q, o, k, at, ownShare)))
      out[k] = at;
  }
  q = std::move(out);
}

}  // namespace vs::centreline_detail
