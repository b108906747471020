// A lumen model per tube where two kissing tubes are fused into one blob (session 29 kiss25): the blob's
// cross-sections fitted as one blurred disc and as two. See centreline_junctions.h.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "tracking/centreline_junctions.h"
#include "tracking/disc_shapes.h"
#include "tracking/point_cells.h"
#include "util/median.h"

namespace vs::centreline_detail {

bool withinForkReach(const JunctionInput& in, const CentrelineOptions& o, size_t k, size_t j, std::vector<size_t>& upK,
                     std::vector<size_t>& upJ) {
  // The points up the tree from k within `reach` along the input points (k itself first).
  const auto upWithin = [&](size_t from, double reach, std::vector<size_t>& up) {
    up.assign(1, from);
    double along = 0;
    for (int64_t at = in.parent[from]; at >= 0; at = in.parent[static_cast<size_t>(at)]) {
      along += (in.raw(static_cast<size_t>(at)) - in.raw(up.back())).norm();
      if (along > reach) break;
      up.push_back(static_cast<size_t>(at));
    }
  };
  const double reach = o.lobeForkRadii * std::max(in.radius[k], in.radius[j]);
  upWithin(k, reach, upK), upWithin(j, reach, upJ);
  for (size_t a : upK)
    if (std::find(upJ.begin(), upJ.end(), a) != upJ.end()) return true;
  return false;
}

namespace {

using Vec2 = Eigen::Vector2d;
using VecX = Eigen::VectorXd;

// From point k along its plain chain (up: towards the root; down: its one child), the first point that is `unfused`
// within `reachMm` along the input points (`along`: the distance walked); -1 where a branch point, a placed (frozen)
// point, an end or the reach comes first.
int64_t unfusedAlong(const JunctionInput& in, const std::vector<uint8_t>& frozen, size_t k, bool up,
                     const std::function<bool(size_t)>& unfused, double reachMm, double& along) {
  along = 0;
  for (size_t at = k;;) {
    const int64_t next = up ? in.parent[at] : in.children[at].size() == 1 ? in.children[at][0] : -1;
    if (next < 0) return -1;
    const size_t j = static_cast<size_t>(next);
    along += (in.raw(j) - in.raw(at)).norm();
    if (along > reachMm || frozen[j]) return -1;
    if (unfused(j)) return next;
    if (in.children[j].size() != 1) return -1;  // a branch point or an end before an unfused point
    at = j;
  }
}

// Per point, whether it was centred onto another traced path's lumen (session 32 kiss36): a point of another branch,
// more than lobeForkRadii x the larger radius along the tree from it (past their fork's own fused section), lies
// within the smaller of the two radii of it (inside each other's lumen, which two tubes' axes never are) though their
// path voxels lie farther apart than that (the refinement drew them together). Two tubes touching with no gap a slice
// resolves are centred on their fused blob this way even where its radius does not bump (the family's 10209: the
// points 0.82 mm apart, their voxels a slice apart, the radius 1.16x the chain's).
// partner: per point so drawn, the nearest point of the other path it was drawn to (-1: none).
std::vector<uint8_t> drawnTogether(const JunctionInput& in, const CentrelineOptions& o, const std::vector<Vec3>& q,
                                   std::vector<int64_t>& partner) {
  const size_t n = q.size();
  std::vector<uint8_t> out(n, 0);
  partner.assign(n, -1);
  std::vector<double> partnerMm(n, std::numeric_limits<double>::infinity());
  if (!(o.lobeForkRadii > 0)) return out;
  // Pairs closer than the smaller radius lie in the same or adjacent cells of a grid as wide as the largest radius:
  // only those are compared (every pair was compared before: quadratic in the tree's points on every refinement).
  double cellMm = 0;
  for (size_t k = 0; k < n; ++k)
    if (std::isfinite(in.radius[k])) cellMm = std::max(cellMm, in.radius[k]);
  if (!(cellMm > 0)) return out;
  PointCells grid(cellMm);
  for (size_t k = 0; k < n; ++k)
    if (std::isfinite(in.radius[k]) && q[k].allFinite()) grid.add(q[k], k);
  std::vector<size_t> upK, upJ;
  for (const auto& [c, members] : grid.cells())
    for (size_t k : members)
      grid.forEachNear(c, [&](size_t j) {
        if (j <= k) return;  // each pair once
        const double d = (q[k] - q[j]).norm();
        if (!(d < std::min(in.radius[k], in.radius[j])) || !((in.raw(k) - in.raw(j)).norm() > d)) return;
        if (withinForkReach(in, o, k, j, upK, upJ)) return;
        out[k] = out[j] = 1;
        if (d < partnerMm[k]) partnerMm[k] = d, partner[k] = static_cast<int64_t>(j);
        if (d < partnerMm[j]) partnerMm[j] = d, partner[j] = static_cast<int64_t>(k);
      });
  return out;
}

using discs::Samples;

// The other tube's points beside a moved stretch (first..last: its run along the own chain; `run`: the sections that
// went to their own disc, the run's and extendRun's, in chain order): those sections also fitted the other tube's
// disc, so its centre line over the stretch is the polyline of the other discs' centres. Points of other chains whose
// foot on that line falls within the stretch and that lie in the other disc (within its radius of the line, nearer
// to it than to the own centres) go to their foot: the centring pulled them towards the contact, where the fused
// blob's rays are longest (session 31 kref33, session 32 kref34). Returns the count moved.
size_t placeOtherTube(const JunctionInput& in, const std::vector<uint8_t>& frozen, const std::vector<Vec3>& q,
                      const std::vector<TwoTubeFit>& run, size_t first, size_t last, bool debug,
                      std::vector<Vec3>& out) {
  if (run.size() < 2) return 0;
  // The foot of p on a polyline (the stretch's centres of one tube): its distance; infinite where p lies past either
  // end of the stretch along its chord (the sections are cut along slightly different lines, so the centres need not
  // advance monotonically: a segment's own span does not bound the stretch).
  auto foot = [&](const Vec3& p, bool other, Vec3& at) {
    const auto centre = [&](size_t i) { return other ? run[i].otherAt : run[i].own; };
    const Vec3 chord = centre(run.size() - 1) - centre(0);
    const double along = (p - centre(0)).dot(chord);
    if (!(along >= 0 && along <= chord.squaredNorm())) return std::numeric_limits<double>::infinity();
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i + 1 < run.size(); ++i) {
      const Vec3 a = centre(i), ab = centre(i + 1) - a;
      const double len2 = ab.squaredNorm(), t = len2 > 1e-12 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      const Vec3 f = a + ab * t;
      if ((p - f).norm() < best) best = (p - f).norm(), at = f;
    }
    return best;
  };
  std::vector<double> radii;
  for (const TwoTubeFit& f : run) radii.push_back(f.other);
  const double otherR = medianInPlace(radii);
  // The own tube's chain through the run, up and down to its branch points or ends, is not the other tube.
  std::vector<uint8_t> onRun(q.size(), 0);
  for (int64_t at = static_cast<int64_t>(first); at >= 0; at = in.parent[static_cast<size_t>(at)]) {
    onRun[static_cast<size_t>(at)] = 1;
    if (in.children[static_cast<size_t>(at)].size() != 1) break;
  }
  for (size_t at = last; in.children[at].size() == 1; at = static_cast<size_t>(in.children[at][0])) onRun[at] = 1;
  size_t moved = 0;
  for (size_t j = 0; j < q.size(); ++j) {
    if (onRun[j] || frozen[j] || in.parent[j] < 0 || in.children[j].size() != 1 || out[j] != q[j]) continue;
    Vec3 toOther = Vec3::Zero(), toOwn = Vec3::Zero();
    const double dOther = foot(q[j], true, toOther), dOwn = foot(q[j], false, toOwn);
    if (!(dOther <= otherR) || !(dOther < dOwn)) continue;
    if (debug)
      std::fprintf(stderr, "[kref33] run %zu-%zu point %zu off %.2f other %.2f\n", first, last, j, dOther, otherR);
    out[j] = toOther, ++moved;
  }
  return moved;
}

}  // namespace

TwoTubeFit fitTwoTubeSection(const Vec3& o, const Vec3& t, const Vec3& ownGuess, double ownR, double blobR,
                             const Vec3& spacing, const std::function<double(const Vec3&)>& value, double bicMin,
                             const Vec3* otherGuess, double otherR) {
  TwoTubeFit out;
  Vec3 u = t.unitOrthogonal(), w = t.cross(u);
  const Vec3 toOwn = ownGuess - o - t * t.dot(ownGuess - o);
  if (toOwn.norm() > 1e-6) u = toOwn.normalized(), w = t.cross(u);
  Vec3 toOther = Vec3::Zero();
  if (otherGuess) {
    toOther = *otherGuess - o - t * t.dot(*otherGuess - o);
    if (toOwn.norm() <= 1e-6 && toOther.norm() > 1e-6) u = -toOther.normalized(), w = t.cross(u);
  }
  // The window holds the blob (half-extent up to about 1.6 of its median ray) and a voxel of background round it.
  const double h = 0.5 * spacing.minCoeff(), reach = 1.6 * blobR + spacing.maxCoeff();
  Samples s;
  std::vector<double> v;
  size_t inWindow = 0;
  for (double x = -reach; x <= reach; x += h)
    for (double y = -reach; y <= reach; y += h) {
      if (x * x + y * y > reach * reach) continue;
      ++inWindow;
      const double val = value(o + x * u + y * w);
      // Off the volume (a tube near its side, a wide window on thick slices): the volume's part of the window,
      // as long as that holds half of it.
      if (std::isnan(val)) continue;
      s.p.emplace_back(x, y), v.push_back(val);
    }
  s.v = Eigen::Map<VecX>(v.data(), static_cast<Eigen::Index>(v.size()));
  auto extent = [&](const Vec3& d) { return 1 / d.cwiseQuotient(spacing).norm(); };
  if (v.size() < inWindow / 2) return out;
  s.nEff = M_PI * reach * reach / (extent(u) * extent(w)) * static_cast<double>(v.size()) / inWindow;
  const double blur0 = std::log(0.5 * spacing.minCoeff()), tn = toOwn.norm();
  VecX one(4);
  one << 0, 0, std::log(blobR), blur0;
  double c1 = 0, c2 = 0;
  const double rss1 = discs::fitShape(s, discs::OneDisc{}, one, c1);
  // Two discs: the own at the chain's radius from the chain's line, the other beyond the blob's centre from it.
  VecX two(6);
  two << tn, 0, -std::max(tn, 0.5 * blobR), 0, std::log(blobR), blur0;
  if (otherGuess) two << tn, 0, toOther.dot(u), toOther.dot(w), std::log(otherR), blur0;
  const double rss2 = discs::fitShape(s, discs::TwoDiscs{ownR}, two, c2);
  if (!(rss1 > 0) || !(rss2 > 0)) return out;
  // The information criterion's gain of two discs over one (Gaussian residuals, two parameters more).
  out.dBic = s.nEff * std::log(rss1 / rss2) - 2 * std::log(s.nEff);
  out.sep = (two.head<2>() - two.segment<2>(2)).norm(), out.other = std::exp(two[4]), out.blur = std::exp(two[5]);
  out.own = o + two[0] * u + two[1] * w, out.otherAt = o + two[2] * u + two[3] * w;
  // The own centre read with the own radius fitted too: the chain's radius (its rays' median) reads a thin tube wide
  // across thick slices (14707: 1.57 mm against 1.16 on 2.26 mm slices), and a disc that wide, held to the thin
  // tube's outer edge, has its centre short of the tube's axis by the excess (the fitted separation 3.2-3.5 mm
  // against 4.0). The decision above stays the fixed radius's; the narrower disc is taken only where it lies within
  // the fixed one's blurred edge (the same own lumen, read narrower, not another structure the free disc went to).
  // Not past the contact (otherGuess: the stretch test's end sections), where the own centre near the chain's point
  // is the evidence that the own tube goes on: read narrower it fell off the point and refused a run (13008).
  if (!otherGuess) {
    VecX free(7);
    free << two, std::log(ownR);
    double c3 = 0;
    const double rss3 = discs::fitShape(s, discs::TwoDiscsOwnFree{}, free, c3);
    const double freeR = std::exp(free[6]), shift = (free.head<2>() - two.head<2>()).norm();
    if (rss3 > 0 && c3 * c2 > 0 && freeR < ownR && shift + freeR <= ownR + out.blur)
      out.own = o + free[0] * u + free[1] * w;
  }
  // Two tubes, not one with a bulge: neither centre inside the other disc, the discs touching (within a voxel), the
  // same contrast as the one disc's.
  // Past the contact (otherGuess) the tubes may have parted.
  out.decisive = out.dBic > bicMin && out.sep >= std::max(ownR, out.other) &&
                 (otherGuess || out.sep <= ownR + out.other + spacing.maxCoeff()) && c1 * c2 > 0;
  return out;
}

namespace {

// Points of an accepted stretch between its run and the run's unfused ends (before / after) lie in the same blob,
// though their radius is under fusedBumpRadii x the own (a contact seen at a slant, or across thick slices, where
// only the blob's middle sections bump by that much: session 31 kiss35, 11508). Walking out from the run's end
// `end`, each such point whose section, cut along the stretch's own line, is decisive, has its path voxel in the own
// lumen and continues both centre lines smoothly goes to its own disc; the walk stops at the first that does not.
size_t extendRun(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                 const std::function<double(const Vec3&)>& value, const Vec3& spacing, const std::vector<Vec3>& q,
                 size_t end, TwoTubeFit at, double atR, int64_t a, int64_t b, bool up, std::vector<Vec3>& out,
                 std::vector<TwoTubeFit>& placed, bool debug) {
  const Vec3 qa = q[static_cast<size_t>(a)], qb = q[static_cast<size_t>(b)], ab = qb - qa;
  const double ra = in.radius[static_cast<size_t>(a)], rb = in.radius[static_cast<size_t>(b)];
  if (ab.norm() < 1e-9) return 0;
  size_t moved = 0;
  for (size_t prev = end;;) {
    const int64_t next = up ? in.parent[prev] : in.children[prev].size() == 1 ? in.children[prev][0] : -1;
    if (next < 0 || next == a || next == b) break;
    const size_t j = static_cast<size_t>(next);
    if (frozen[j] || in.children[j].size() != 1 || out[j] != q[j]) break;
    const double share = std::clamp((q[j] - qa).dot(ab) / ab.squaredNorm(), 0.0, 1.0), ownR = ra + (rb - ra) * share;
    const TwoTubeFit f =
        fitTwoTubeSection(q[j], ab.normalized(), qa + ab * share, ownR, in.radius[j], spacing, value, o.twoTubeBic);
    const double step = (q[j] - q[prev]).norm();
    const bool ok = f.decisive && (f.own - in.raw(j)).norm() <= ownR + 0.5 * spacing.norm() &&
                    (f.own - at.own).norm() <= step + 0.5 * std::min(ownR, atR) &&
                    (f.otherAt - at.otherAt).norm() <= step + 0.5 * std::min(f.other, at.other);
    if (debug)
      std::fprintf(stderr, "[kiss35] from %zu at %zu dBic %.1f sep %.2f other %.2f shift %.2f ok %d\n", end, j, f.dBic,
                   f.sep, f.other, (f.own - q[j]).norm(), ok);
    if (!ok) break;
    out[j] = f.own, ++moved, at = f, atR = ownR, prev = j;
    placed.push_back(f);
  }
  return moved;
}

// Two traced paths crossing at an angle (session 34 xfit34): where a point drawn onto another path's lumen is
// left where it was and that path's unfused ends run at more than 45 degrees to its own, the other tube fills its
// sections over only about (its radius + the own) / sin(angle) - no second tube going on beside, so no stretch the
// fit above accepts - and the centring put both paths' points on the merged lumen's middle (a fused bump along the
// run of such points: without one, the centring kept them apart). The own axis there is
// the line between the chain's unfused ends (round sections of its own tube either side), at the point's share of
// the way along its path voxels; taken where that line keeps to the own lumen round the point's path voxel (as the
// fit's own centre must). Paths side by side go there too (session 35 kiss39) where the point lies past the midline
// between the two traced paths (nearer the other path's voxel than its own): a bump section the stretch test refused
// (a run of one) or one fused to a single disc, the centring took it onto the other tube (11709's neck, 521).
// Per candidate point of fitTwoTubes: its chain's unfused ends up (before) and down (after), the straight line between
// them at the point's share of the way (line) and their chord.
struct UnfusedEnds {
  const std::vector<Vec3>& line;
  const std::vector<Vec3>& chord;
  const std::vector<int64_t>& before;
  const std::vector<int64_t>& after;
};

size_t crossingOnLine(const JunctionInput& in, const CentrelineOptions& o, const std::vector<uint8_t>& together,
                      const std::vector<int64_t>& partner, const std::vector<double>& ownR, const UnfusedEnds& ends,
                      const Vec3& spacing, const std::vector<Vec3>& q, bool debug, std::vector<Vec3>& out,
                      std::vector<double>* radiusOut) {
  const size_t n = q.size();
  const std::vector<Vec3>&line = ends.line, &chord = ends.chord;
  const std::vector<int64_t>&before = ends.before, &after = ends.after;
  // The own axis at k: the chain's own curve between its unfused ends at the point's share of the way (session 39
  // kiss232: a thin child's return bending through the contact with its sibling's start - the straight line between
  // the ends cut across the bend's inside, towards the sibling, by up to a voxel).
  const auto curve = [&](size_t k) {
    const size_t a = static_cast<size_t>(before[k]), b = static_cast<size_t>(after[k]);
    return chainCurveAt(in, q, a, b, (line[k] - q[a]).dot(chord[k]) / chord[k].squaredNorm());
  };
  // Whether the run of drawn-together points through k along its plain chain holds a fused bump (a radius
  // fusedBumpRadii x its unfused ends' or more): the centring put it on a merged lumen, not beside it.
  const auto bumped = [&](size_t j) { return ownR[j] > 0 && in.radius[j] >= o.fusedBumpRadii * ownR[j]; };
  auto fused = [&](size_t k) {
    for (int64_t at = static_cast<int64_t>(k); at >= 0 && together[static_cast<size_t>(at)];
         at = in.parent[static_cast<size_t>(at)]) {
      if (bumped(static_cast<size_t>(at))) return true;
      if (in.children[static_cast<size_t>(at)].size() != 1) break;
    }
    for (size_t at = k; in.children[at].size() == 1;) {
      at = static_cast<size_t>(in.children[at][0]);
      if (!together[at]) break;
      if (bumped(at)) return true;
    }
    return false;
  };
  size_t moved = 0;
  std::vector<size_t> onAxis;
  for (size_t k = 1; k < n; ++k) {
    if (!together[k] || ownR[k] <= 0 || partner[k] < 0 || out[k] != q[k] || !fused(k)) continue;
    const size_t j = static_cast<size_t>(partner[k]);
    if (ownR[j] <= 0 || chord[k].norm() < 1e-9 || chord[j].norm() < 1e-9) continue;
    const bool crossing = std::abs(chord[k].dot(chord[j])) < std::sqrt(0.5) * chord[k].norm() * chord[j].norm();
    // Or side by side (session 35 kiss39): the point lies past the midline between the two traced paths (nearer the
    // other path's voxel than its own) - the centring took it over to the other tube's side of the fused blob.
    const bool across = (q[k] - in.raw(j)).norm() < (q[k] - in.raw(k)).norm();
    const Vec3 own = curve(k);
    const bool inLumen = (own - in.raw(k)).norm() <= ownR[k] + 0.5 * spacing.norm();
    if (debug)
      std::fprintf(stderr, "[xfit34] k %zu partner %zu cos %.2f shift %.2f raw %.2f own %.2f crossing %d across %d\n",
                   k, j, chord[k].dot(chord[j]) / (chord[k].norm() * chord[j].norm()), (own - q[k]).norm(),
                   (own - in.raw(k)).norm(), ownR[k], int(crossing && inLumen), int(across && inLumen));
    if ((crossing || across) && inLumen) out[k] = own, ++moved, onAxis.push_back(k);
  }
  // On its own axis, its own radius (interpolated between the unfused ends), as lineUncentred's and centre35's points:
  // the cast's radius there spans the fused blob. Set once every point is decided (in.radius may be *radiusOut).
  for (size_t k : onAxis)
    if (radiusOut) (*radiusOut)[k] = ownR[k];
  return moved;
}

// An accepted stretch's unfused ends: the stretch test fitted their sections as two tubes (decisive, the other tube
// going on beside at its calibre, the own centre within half the own radius of the point), so they go to that fit's
// own centre too; the centring left them on the blob's side (session 34 kiss38, 11108's 0/58). Returns the count moved.
size_t placeEnds(const std::vector<uint8_t>& frozen, const std::vector<Vec3>& q,
                 const std::vector<std::pair<size_t, size_t>>& runs, const std::vector<int64_t>& before,
                 const std::vector<int64_t>& after, const std::vector<std::array<TwoTubeFit, 2>>& endFit, bool debug,
                 std::vector<Vec3>& out) {
  size_t moved = 0;
  for (const auto& [first, last] : runs)
    for (size_t e = 0; e < 2; ++e) {
      const size_t j = static_cast<size_t>(e ? after[last] : before[first]);
      if (frozen[j] || out[j] != q[j]) continue;
      if (debug) std::fprintf(stderr, "[kiss38] end %zu moved %.2f\n", j, (endFit[first][e].own - q[j]).norm());
      out[j] = endFit[first][e].own, ++moved;
    }
  return moved;
}

// The volume's value at p (mm; NaN outside it).
std::function<double(const Vec3&)> valueAt(const TrilinearSampler& sample, const Vec3& spacing) {
  return [&sample, spacing](const Vec3& p) {
    const Vec3 i = p.cwiseQuotient(spacing);
    return sample.inside(i) ? double(sample.at(i)) : std::numeric_limits<double>::quiet_NaN();
  };
}

// fitTwoTubes' candidates besides a radius bump: the points drawn together (drawnTogether; partner), or touched by
// another traced path's point (touchingPaths, the rounds' own-lobe trigger) where the point's last own-lobe look found
// one lobe (`oneLobe`). Where thick slices fill the gap between two kissing tubes there is one lobe at a point's level,
// the rays centre it on the blob and it drifts across the contact (3109's path 1, 0.27 z-voxel a round; drawnTogether
// missed one point of its run of three): the fit is then asked along the contact, its run test deciding. Where the look
// found two lobes the own-lobe step already holds the point in its lobe (524, touch37's neck): no candidate by touch.
std::vector<uint8_t> fitCandidates(const JunctionInput& in, const CentrelineOptions& o, const std::vector<Vec3>& q,
                                   const std::vector<uint8_t>* oneLobe, std::vector<int64_t>& partner) {
  std::vector<uint8_t> together = drawnTogether(in, o, q, partner);
  if (!oneLobe) return together;
  const std::vector<int64_t> touching = touchingPaths(in, o, q);
  for (size_t k = 0; k < together.size() && k < touching.size() && k < oneLobe->size(); ++k)
    if (touching[k] >= 0 && (*oneLobe)[k]) together[k] = 1;
  return together;
}

// Whether the rounds' last own-lobe look found every section of the run `first`..`last` (down its plain chain) one
// lobe (`oneLobe`: rays escaped through a contact, or a touching path beside it, and the section fused - the contact
// the rounds cannot split). Such a run needs no length: twoTubeRun stands in for a second tube going on beside the own
// one (a bulge fits two discs in single sections), and here the rounds read the fused contact at each section. A
// contact a point or two long (17308's kisses, 1.29 mm slices: the chords' centre drew both points a slice towards the
// neighbour) was left where the rounds put it.
bool roundsReadFused(const JunctionInput& in, size_t first, size_t last, const std::vector<uint8_t>* oneLobe) {
  if (!oneLobe) return false;
  // Walked up from last: the run's first point may be a branch point whose first child is not the run's.
  for (size_t at = last;; at = static_cast<size_t>(in.parent[at])) {
    if (at >= oneLobe->size() || !(*oneLobe)[at]) return false;
    if (at == first) return true;
  }
}

}  // namespace

size_t fitTwoTubes(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                   const TrilinearSampler& sample, const Vec3& spacing, std::vector<Vec3>& q,
                   std::vector<double>* radiusOut, const std::vector<uint8_t>* oneLobe) {
  const std::function<double(const Vec3&)> value = valueAt(sample, spacing);
  if (!(o.fusedBumpRadii > 1) || !(o.fusedBumpReachRadii > 0) || !(o.twoTubeBic > 0) || !in.raw || o.iterations <= 0)
    return 0;
  const size_t n = q.size();
  std::vector<TwoTubeFit> fit(n);
  std::vector<double> ownR(n, 0);
  std::vector<int64_t> before(n, -1), after(n, -1);  // the narrower (unfused) points up and down the chain
  const bool debug = std::getenv("VS_KISS25_DEBUG") != nullptr;
  std::vector<int64_t> partner;
  const std::vector<uint8_t> together = fitCandidates(in, o, q, oneLobe, partner);
  std::vector<Vec3> line(n, Vec3::Zero()), chord(n, Vec3::Zero());  // per candidate: its unfused ends' line there
  for (size_t k = 1; k < n; ++k) {
    if (frozen[k] || in.children[k].size() != 1 || in.parent[k] < 0) continue;
    const double limit = in.radius[k] / o.fusedBumpRadii, reach = o.fusedBumpReachRadii * in.radius[k];
    double up = 0, down = 0;
    const auto narrower = [&](size_t j) { return in.radius[j] <= limit; };
    int64_t a = unfusedAlong(in, frozen, k, true, narrower, reach, up);
    int64_t b = a < 0 ? -1 : unfusedAlong(in, frozen, k, false, narrower, reach - up, down);
    // No bump, but drawn together with another traced path: the stretch so drawn is the fused blob, its first
    // points not so drawn up and down the chain its unfused ends.
    if (b < 0 && together[k]) {
      const auto apart = [&](size_t j) { return !together[j]; };
      a = unfusedAlong(in, frozen, k, true, apart, reach, up);
      b = a < 0 ? -1 : unfusedAlong(in, frozen, k, false, apart, reach - up, down);
    }
    if (b < 0) continue;
    const size_t ia = static_cast<size_t>(a), ib = static_cast<size_t>(b);
    before[k] = a, after[k] = b;
    const double share = up / (up + down);
    line[k] = q[ia] + (q[ib] - q[ia]) * share, chord[k] = q[ib] - q[ia];
    ownR[k] = in.radius[ia] + (in.radius[ib] - in.radius[ia]) * share;
    fit[k] = fitTwoTubeSection(q[k], (q[ib] - q[ia]).normalized(), line[k], ownR[k], in.radius[k], spacing, value,
                               o.twoTubeBic);
    // The path voxel lies in the own lumen, so the own centre lies within the own radius of that voxel's cell (its
    // centre is a whole voxel's sample, up to half the cell's diagonal from the lumen it stands for).
    fit[k].decisive = fit[k].decisive && (fit[k].own - in.raw(k)).norm() <= ownR[k] + 0.5 * spacing.norm();
  }
  // Runs of decisive sections along the chain whose two centre lines both move smoothly (neighbours' own centres,
  // and other centres, no farther apart than the points plus half that tube's radius).
  auto linked = [&](size_t k, int64_t j) {
    if (j < 0 || !fit[k].decisive || !fit[static_cast<size_t>(j)].decisive) return false;
    const size_t i = static_cast<size_t>(j);
    const double step = (q[k] - q[i]).norm();
    return (fit[k].own - fit[i].own).norm() <= step + 0.5 * std::min(ownR[k], ownR[i]) &&
           (fit[k].otherAt - fit[i].otherAt).norm() <= step + 0.5 * std::min(fit[k].other, fit[i].other);
  };
  auto down = [&](size_t k) -> int64_t { return in.children[k].size() == 1 ? in.children[k][0] : -1; };
  // The whole stretch, not a section, decides (session 30 kiss29): two tubes kiss where the other tube's course
  // through the run continues a tube seen apart from the own one past both ends, at the chain's unfused points. A
  // wide lumen's bulge, an ostium or a tangle fits two discs in each section but has no second tube going on
  // outside on both sides.
  // calibre: the least and the largest other radius of the run (its sections' median) and past its ends; endOut: the
  // end section's fit.
  auto continues = [&](size_t end, int64_t at, Vec2& calibre, TwoTubeFit* endOut) {
    if (at < 0 || frozen[static_cast<size_t>(at)]) return false;
    const size_t j = static_cast<size_t>(at);
    // The section normal to the line the run's own sections were cut along (between its unfused points): the end
    // point's neighbour on the run's side lies in the blob, so its own chord is tilted towards the other tube.
    const Vec3 t = q[static_cast<size_t>(after[end])] - q[static_cast<size_t>(before[end])];
    if (t.norm() < 1e-9) return false;
    const Vec3 guess = q[j] + (fit[end].otherAt - fit[end].own);  // the other tube's offset carried along
    const double otherR = fit[end].other, window = std::max(in.radius[end], fit[end].sep + otherR);
    const TwoTubeFit f = fitTwoTubeSection(q[j], t.normalized(), q[j], in.radius[j], window, spacing, value,
                                           o.twoTubeBic, &guess, otherR);
    // Past the contact the tubes part, so the other's offset grows; it keeps its side (within 45 degrees).
    const Vec3 was = fit[end].otherAt - fit[end].own, is = f.otherAt - f.own;
    const bool ok = f.decisive && f.other >= 0.5 * otherR && f.other <= 2 * otherR &&
                    is.dot(was) >= std::sqrt(0.5) * is.norm() * was.norm() &&
                    (f.own - q[j]).norm() <= 0.5 * in.radius[j];
    if (debug)
      std::fprintf(stderr, "[kiss29] end %zu at %zu dBic %.1f other %.2f/%.2f off %.2f own %.2f ok %d\n", end, j,
                   f.dBic, f.other, otherR, (f.otherAt - guess).norm(), (f.own - q[j]).norm(), ok);
    calibre = Vec2(std::min(calibre[0], f.other), std::max(calibre[1], f.other));
    *endOut = f;
    return ok;
  };
  std::vector<std::array<TwoTubeFit, 2>> endFit(n);
  std::vector<int8_t> stretchOk(n, -1);  // per run's first point: whether the other tube continues past both ends
  std::vector<Vec3> out = q;
  std::vector<std::pair<size_t, size_t>> runs;  // the accepted runs' first and last points
  size_t moved = 0;
  for (size_t k = 1; k < n; ++k) {
    if (ownR[k] <= 0) continue;
    int run = fit[k].decisive ? 1 : 0;
    size_t first = k, last = k;
    for (; run > 0 && linked(first, in.parent[first]); first = static_cast<size_t>(in.parent[first])) ++run;
    for (; run > 0 && linked(last, down(last)); last = static_cast<size_t>(down(last))) ++run;
    // twoTubeRun points in a row, read as the length they span on isotropic voxels (twoTubeRun - 1 of the finest
    // spacing): a chain across thick slices steps a slice, several voxels, per point (session 31 kiss35, 11508).
    // A shorter run the rounds read as a fused contact at every section needs no length (roundsReadFused; held17b).
    bool move = run >= o.twoTubeRun || (run > 0 && roundsReadFused(in, first, last, oneLobe));
    if (!move && run > 1) {
      double length = 0;
      for (size_t at = last; at != first; at = static_cast<size_t>(in.parent[at]))
        length += (q[at] - q[static_cast<size_t>(in.parent[at])]).norm();
      move = length >= (o.twoTubeRun - 1) * spacing.minCoeff();
    }
    if (move && stretchOk[first] < 0) {
      // One tube keeps its calibre across a contact a few radii long; a bulge or a lobe tapers (the head CTA's
      // wide vessel: the other disc 3.3 mm past one end, 1.0 mm at the other; the family's within a factor 1.7).
      // The run's calibre is its sections' median (session 34 kiss38): inside the fused blob one section's fit trades
      // the other radius against the shared blur and the separation (11108's 16 sections read 0.73-1.56 mm for a
      // 1.25-1.30 mm tube across 2.2 mm slices), so the least and largest section refused a true stretch.
      std::vector<double> others;
      for (size_t at = first;; at = static_cast<size_t>(down(at))) {
        others.push_back(fit[at].other);
        if (at == last) break;
      }
      Vec2 calibre = Vec2::Constant(medianInPlace(others));
      stretchOk[first] = continues(first, before[first], calibre, &endFit[first][0]) &&
                         continues(last, after[last], calibre, &endFit[first][1]) && calibre[1] <= 2 * calibre[0];
    }
    move = move && stretchOk[first] > 0;
    if (debug)
      std::fprintf(stderr,
                   "[kiss25] k %zu q %.2f %.2f %.2f own %.2f blob %.2f dBic %.1f sep %.2f other %.2f blur %.2f "
                   "shift %.2f raw %.2f decisive %d run %d move %d depthOwnBefore %.2f together %d\n",
                   k, q[k][0] / spacing[0], q[k][1] / spacing[1], q[k][2] / spacing[2], ownR[k], in.radius[k],
                   fit[k].dBic, fit[k].sep, fit[k].other, fit[k].blur, (fit[k].own - q[k]).norm(),
                   (fit[k].own - in.raw(k)).norm(), fit[k].decisive, run, move, ownR[k] - (fit[k].own - q[k]).norm(),
                   int(together[k]));
    if (move) out[k] = fit[k].own, ++moved;
    if (move && k == first) runs.emplace_back(first, last);
  }
  std::vector<std::vector<TwoTubeFit>> stretches;  // per run: its sections placed on their own disc, in chain order
  for (const auto& [first, last] : runs) {
    std::vector<TwoTubeFit> upward, downward;
    moved += extendRun(in, frozen, o, value, spacing, q, first, fit[first], ownR[first], before[first], after[last],
                       true, out, upward, debug);
    moved += extendRun(in, frozen, o, value, spacing, q, last, fit[last], ownR[last], before[first], after[last], false,
                       out, downward, debug);
    std::vector<TwoTubeFit>& s = stretches.emplace_back(upward.rbegin(), upward.rend());
    for (size_t at = first;; at = static_cast<size_t>(down(at))) {
      s.push_back(fit[at]);
      if (at == last) break;
    }
    s.insert(s.end(), downward.begin(), downward.end());
  }
  moved += placeEnds(frozen, q, runs, before, after, endFit, debug, out);
  // The other (wider) tube's points beside each accepted stretch, once every own point is placed (session 32 kref34).
  for (size_t i = 0; i < runs.size(); ++i)
    moved += placeOtherTube(in, frozen, q, stretches[i], runs[i].first, runs[i].second, debug, out);
  moved +=
      crossingOnLine(in, o, together, partner, ownR, {line, chord, before, after}, spacing, q, debug, out, radiusOut);
  q = std::move(out);
  return moved;
}

}  // namespace vs::centreline_detail
