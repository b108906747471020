#include "tracking/fused_fork.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/box_search.h"
#include "tracking/contact_walk.h"

namespace vs {

using retrace::Box;
using retrace::mmOf;
using retrace::mmOfChain;
using walk::centredSection;
using walk::Lumen;
using walk::Section;
using walk::toPolyline;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The median radius of the chain's centred sections at its points lo..hi, each normal to the chain's direction
// over k steps either side; 0 where none is lumen.
double medianRadius(const Lumen& lu, const Geometry& g, const std::vector<Index3>& chain, size_t lo, size_t hi,
                    size_t k, double dt, double cap) {
  std::vector<double> r;
  for (size_t j = lo; j <= hi && j < chain.size(); ++j) {
    const size_t a = j >= k ? j - k : 0, b = std::min(chain.size() - 1, j + k);
    const Vec3 d = mmOf(g, chain[b]) - mmOf(g, chain[a]);
    if (d.norm() <= 0) continue;
    const Section s = centredSection(lu, mmOf(g, chain[j]), d.normalized(), dt, cap);
    if (s.lumen) r.push_back(s.radius);
  }
  if (r.empty()) return 0;
  std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
  return r[r.size() / 2];
}

// The own child's tube walked back from the entry x along dir (towards the fork) with the walks' step (contact_walk.h
// stepOn: an own section - radius 0.5-2 rOwn, centred within rOwn - taken and the walk turned towards it; out of the
// lumen the least turn round the child's own bend; a section of no own radius stepped over keeping to its lumen's
// sideways centre, up to maxBad mm at a time). It ends where it comes within rP of the shared chain (path[0..c-1]) or
// of its last point continued along the trunk's direction (over k steps) by rP (session 40 fork331: the discrete
// branch point may lie short of the junction - 12331's by 2.8 voxels, the walk passing the junction 4 mm from it - and
// the junction lies within the trunk's radius of the chain's end): that point's index in *meet, the own sections'
// centres in *centres. The meeting is judged at the sample before its section is read (session 40 fork331b: the
// section there lies in the junction, centred on the union of the trunk and both children - on 11423 it
// fell inside the sibling's tube past the crotch its chain cuts, where fork35's side test, read against that chain,
// does not see it - and is not the own child's). False where it leaves the lumen or runs longer than maxWalk.
bool walksToSharedChain(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t c, size_t k,
                        const Vec3& x, const Vec3& dir, double rOwn, double rP, double maxBad, double maxWalk,
                        double dt, double cap, size_t* meet, std::vector<Vec3>* centres) {
  const double step = std::max(dt, 0.5 * rOwn);
  Vec3 q = x, d = dir;
  double walked = 0, bad = 0;
  while (walked <= maxWalk) {
    double nearest = kInf;
    size_t at = 0;
    for (size_t j = 0; j < c; ++j) {
      const double dj = (mmOf(g, path[j]) - q).norm();
      if (dj < nearest) nearest = dj, at = j;
    }
    {  // the chain's last point continued along the trunk by rP
      const Vec3 a = mmOf(g, path[c - 1]), t = (a - mmOf(g, path[c - 1 - k])).normalized();
      const double u = std::clamp((q - a).dot(t), 0.0, rP);
      if ((a + u * t - q).norm() < nearest) nearest = (a + u * t - q).norm(), at = c - 1;
    }
    if (nearest <= rP && !centres->empty()) {
      *meet = at;
      return true;
    }
    const Section s = centredSection(lu, q, d, dt, cap);
    Vec3 next = q + step * d;
    if (walk::stepOn(lu, s, q, false, step, rOwn, dt, cap, maxBad, bad, d, centres, &next) == walk::WalkStep::Lost)
      return false;
    q = next;
    walked += step;
  }
  return false;
}

}  // namespace

namespace {

// The parting as the first reading has it, for the second (retraceFromJoinedSection).
struct FusedParting {
  bool read = false;
  size_t c = 0, e = 0;
  double rS = 0, rOwn = 0;
  double longArcBound = 0;  // refused: the path beside its sibling for longer than this fork's stretch (mm; 0: not)
};

FusedForkRetrace retraceFusedForkFirst(const NodeCost3D& cost, const std::vector<Index3>& path,
                                       const std::vector<Index3>& sibling, int connectivity, double lumenLevel,
                                       const CrossingOptions& o, FusedParting* pt) {
  FusedForkRetrace r;
  const Geometry& g = cost.geometry;
  if (!o.enabled) return r;
  const size_t h = static_cast<size_t>(std::max(1, o.spanSteps)),
               k = static_cast<size_t>(std::max(1, o.directionSteps));
  const double vmin = g.spacing.minCoeff(), vmax = g.spacing.maxCoeff(), dt = 0.5 * vmin, cap = 6 * vmax;
  const Lumen lu{cost, lumenLevel};
  // The parting c: the first voxel where the two chains differ.
  size_t c = 0;
  while (c < path.size() && c < sibling.size() && path[c] == sibling[c]) ++c;
  if (c < h + k + 1 || c + h + k >= path.size() || c + h + k >= sibling.size()) return r;
  // The sibling's radius just past the parting, the shared chain's just before it.
  const double rS = medianRadius(lu, g, sibling, c, c + h + k, k, dt, cap);
  const double rP = medianRadius(lu, g, path, c - h - k, c - 1, k, dt, cap);
  if (rS <= 0 || rP <= 0) return r;
  // The path's fused stretch: from the parting while its points lie within 2 rS of the sibling's chain (the walls
  // overlapping); the entry e into its own child: its first point farther.
  const std::vector<Vec3> sib = mmOfChain(g, sibling, c - 1, sibling.size() - 1);
  size_t e = c;
  while (e < path.size() && toPolyline(mmOf(g, path[e]), sib) <= 2 * rS) ++e;
  if (e + h + k >= path.size()) return r;
  const double rOwn = medianRadius(lu, g, path, e, e + h + k, k, dt, cap);
  const Vec3 x = mmOf(g, path[e]), toward = x - mmOf(g, path[e + k]);
  if (rOwn <= 0 || toward.norm() <= 0) return r;
  // A fork's fused stretch: children at an angle part within a few radii of their junction. A path beside its sibling
  // for longer than twice the parent's, the sibling's and its own radius together shares a lumen over a length
  // (kissing or parallel tubes: the other re-searches').
  const double arc = retrace::chainLength(g, retrace::stretch(path, c - 1, e));
  if (arc > (pt->longArcBound = 2 * (rP + rS + rOwn))) return r;
  *pt = FusedParting{true, c, e, rS, rOwn};
  // The own child's tube walked back from the entry to the shared chain.
  size_t meet = 0;
  std::vector<Vec3> centres;
  if (!walksToSharedChain(lu, g, path, c, k, x, toward.normalized(), rOwn, rP, rP + rOwn, 2 * arc + 2 * (rP + rOwn), dt,
                          cap, &meet, &centres) ||
      meet == 0)
    return r;
  r.walked = true;
  // A tube of its own: the walk's farthest centre from the path's fused stretch lies beyond the own radius and half a
  // finest voxel (a walk back along the path itself stays within them: the path's voxels may hug its wall).
  const std::vector<Index3> fused = retrace::stretch(path, c - 1, e);
  double far = 0;
  Vec3 farC = centres.front();
  for (const Vec3& q : centres) {
    double d = kInf;
    for (const Index3& v : fused) d = std::min(d, (mmOf(g, v) - q).norm());
    if (d > far) far = d, farC = q;
  }
  // The path's side of the union: every walked centre nearer the path's fused stretch than the sibling's chain (a walk
  // that drifts into the sibling's lumen follows the sibling, not the own child).
  const std::vector<Vec3> sibPast = mmOfChain(g, sibling, c, sibling.size() - 1),
                          ownPast = mmOfChain(g, path, c - 1, e);
  size_t sibSide = 0;
  for (const Vec3& q : centres) sibSide += toPolyline(q, sibPast) < toPolyline(q, ownPast);
  if (sibSide > 0) {
    r.why = "the walk drifts into the sibling's lumen";
    return r;
  }
  if (far <= rOwn + 0.5 * vmin) {
    r.why = "the own child's tube is the path's";
    return r;
  }
  // The sibling's fused tube: its chain from the parting to its point nearest the entry, h + k on; and the path's own
  // fused stretch (the chord through the union).
  size_t nearS = c;
  double dNear = kInf;
  for (size_t j = c; j < sibling.size(); ++j) {
    const double d = (mmOf(g, sibling[j]) - x).norm();
    if (d < dNear) dNear = d, nearS = j;
  }
  const size_t sEnd = std::min(sibling.size() - 1, nearS + h + k);
  // The chord blocked only where it lies farther than the own radius from the walked centres: a stretch of the old
  // route within it is in the own tube already (session 40 fork331b: 11423's path 1 ran in its own child along its
  // wall, its sibling's chain cutting the crotch through that child's start; with its whole chord blocked the route
  // was pushed off its start across the junction).
  const std::vector<Vec3> sibTube = mmOfChain(g, sibling, c, sEnd);
  std::vector<Vec3> chord;
  for (size_t j = c; j <= e; ++j)
    if (toPolyline(mmOf(g, path[j]), centres) > rOwn) chord.push_back(mmOf(g, path[j]));
  const size_t lo0 = meet > 2 * (h + k) ? meet - 2 * (h + k) : 0, hi = std::min(path.size() - 1, e + h + k);
  std::vector<Index3> around = retrace::stretch(path, lo0, hi);
  for (size_t j = c; j <= sEnd; ++j) around.push_back(sibling[j]);
  for (const Vec3& q : centres) {
    Index3 v;
    for (size_t ax = 0; ax < 3; ++ax) v[ax] = static_cast<int64_t>(std::llround(q[ax] / g.spacing[ax]));
    if (g.contains(v)) around.push_back(v);
  }
  const Box bx = retrace::boxAround(g, around, 0, around.size() - 1, o.marginSteps);
  if (bx.size() > (int64_t(1) << 23)) return r;
  // Blocked: the sibling's tube and the chord (the sibling's radius + half a coarsest voxel round either) where they
  // lie nearer the sibling's chain or the chord than the walked centres or the shared chain up to the walk's meeting
  // point - the own child's part of the fused union, and the trunk it leaves, left open (session 40 fork331: with the
  // trunk blocked, 11825's route left the shared chain 4 points early round the trunk's outer wall and its fork was
  // traced 8.5 voxels off).
  const double rBlock = rS + 0.5 * vmax;
  std::vector<Vec3> open = centres;
  for (size_t j = meet + 1; j-- > lo0;) open.push_back(mmOf(g, path[j]));
  std::vector<uint8_t> blocked(static_cast<size_t>(bx.size()), 0);
  for (int64_t j = 0; j < bx.size(); ++j) {
    const Vec3 p = mmOf(g, bx.voxel(j));
    const double dS = std::min(toPolyline(p, sibTube), toPolyline(p, chord));
    if (dS > rBlock) continue;
    if (toPolyline(p, open) > dS) blocked[static_cast<size_t>(j)] = 1;
  }
  // Searched from the shared chain's last point outside the block before the walk's meeting point.
  size_t lo = meet - 1;
  while (lo > lo0 && blocked[static_cast<size_t>(bx.index(path[lo]))]) --lo;
  if (blocked[static_cast<size_t>(bx.index(path[lo]))] || blocked[static_cast<size_t>(bx.index(path[hi]))]) {
    r.why = "the shared chain or the entry inside the block";
    return r;
  }
  centres.push_back(mmOf(g, path[meet]));  // the walked length: with its way into the shared chain
  const std::vector<Index3> part = retrace::stretch(path, lo, hi);
  const double oldPart = chainCost(cost, part), oldLen = retrace::chainLength(g, part);
  double walkedLen = 0;
  for (size_t t = 1; t < centres.size(); ++t) walkedLen += (centres[t] - centres[t - 1]).norm();
  double nc = 0;
  std::vector<Index3> next =
      retrace::boxPath(cost, bx, blocked, retrace::stepsFor(g, connectivity), part.front(), part.back(),
                       (1 + o.costSlack) * oldPart / oldLen * (oldLen + 2 * walkedLen), &nc);
  if (next.empty()) {
    r.why = "no route round the block";
    return r;
  }
  const double newLen = retrace::chainLength(g, next);
  // Both routes at the cost floor (the chord the cheaper): judged by cost per mm, not by total cost or length.
  double hole = 0, longest = 0;
  for (size_t t = 1; t < next.size(); ++t) {
    const bool in = cost.node[static_cast<size_t>(g.linear(next[t][0], next[t][1], next[t][2]))] <= lumenLevel;
    hole = in ? 0 : hole + (mmOf(g, next[t]) - mmOf(g, next[t - 1])).norm();
    longest = std::max(longest, hole);
  }
  double through = kInf;
  for (const Index3& v : next) through = std::min(through, (mmOf(g, v) - farC).norm());
  if (nc / newLen > (1 + o.costSlack) * oldPart / oldLen) {
    r.why = "the route round the block costs more per mm";
    return r;
  }
  // A route of its own: farther than the own radius from the old stretch somewhere, and through the walked tube.
  if (longest > o.lumenHoleVoxels * vmin || through > rOwn + 0.5 * vmax ||
      retrace::farthestFrom(g, next, part) <= rOwn) {
    r.why = "the route round the block is no tube of its own";
    return r;
  }
  r.oldCost = chainCost(cost, path);
  return retrace::accepted(std::move(r), oldPart, nc, retrace::spliced(path, lo, hi, next));
}

// The sibling as the path's chain while the path runs within a voxel (the coarsest spacing) of the sibling's chain past
// their first differing voxel, then the sibling's own chain from its point nearest the path's last such voxel; false
// where the path leaves the sibling at once or never, or where that run is no longer than minRun mm.
bool siblingJoinedWhileAdjacent(const Geometry& g, const std::vector<Index3>& path, const std::vector<Index3>& sibling,
                                double minRun, std::vector<Index3>* joined) {
  size_t c = 0;
  while (c < path.size() && c < sibling.size() && path[c] == sibling[c]) ++c;
  if (c == 0 || c >= path.size() || c >= sibling.size()) return false;
  const double vmax = g.spacing.maxCoeff();
  const std::vector<Vec3> sib = mmOfChain(g, sibling, c - 1, sibling.size() - 1);
  size_t j = c, nearS = c - 1;
  for (size_t n = 0; j < path.size(); ++j) {
    if (toPolyline(mmOf(g, path[j]), sib, &n) > vmax) break;
    nearS = c - 1 + n;
  }
  if (j == c || j >= path.size() || nearS + 1 >= sibling.size()) return false;
  if (retrace::chainLength(g, retrace::stretch(path, c - 1, j - 1)) <= minRun) return false;
  joined->assign(path.begin(), path.begin() + static_cast<std::ptrdiff_t>(j));
  joined->insert(joined->end(), sibling.begin() + static_cast<std::ptrdiff_t>(nearS + 1), sibling.end());
  return (*joined)[j] != path[j];
}

// Whether a route passes one voxel twice: it runs back along itself. A search's own route never does; a spliced one
// does where the new stretch reached the kept route beyond the splice's end and came back along it to that end (issue
// 21, session 51 contact: 13308's path 1 - forkE's route ran 25 voxels down the wide sibling's far wall round its
// block, entered the own thin child 7 voxels past the entry stretch's end and ran back up the child to it; the path to
// the child's far end cannot pass the child's own stretch twice).
bool passesOneVoxelTwice(const std::vector<Index3>& route) {
  std::vector<Index3> sorted = route;
  std::sort(sorted.begin(), sorted.end());
  return std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
}

}  // namespace

// A fused fork read twice: where the walk back from the entry finds no route, the own child read from its far end back
// to its first section joined with the sibling (fused_fork_joined.cpp, session 43 forkE).
FusedForkRetrace retraceFusedFork(const NodeCost3D& cost, const std::vector<Index3>& path,
                                  const std::vector<Index3>& sibling, int connectivity, double lumenLevel,
                                  const CrossingOptions& o) {
  FusedParting pt;
  FusedForkRetrace r = retraceFusedForkFirst(cost, path, sibling, connectivity, lumenLevel, o, &pt);
  // Two chains through one lumen differ by a voxel wherever the cost ties, so their first differing voxel may lie long
  // before the fork and the stretch from it read as two tubes side by side (8702: the paths to both children a voxel
  // apart in the trunk 9 voxels before the fork, the path cutting through its sibling's start measured from there).
  // Where the first reading refused the stretch for its length and the chains run within a voxel of each other for
  // longer than that bound themselves - one route, not two tubes side by side - the parting is read again where the
  // path leaves the sibling's chain by more than a voxel: the sibling taken as the path's own chain up to there. (A
  // shorter tie leaves the refusal as it was: 14825's and 16125's 2-6 voxel ties re-read were LOST.)
  std::vector<Index3> joined;
  if (!r.changed && !pt.read && pt.longArcBound > 0 &&
      siblingJoinedWhileAdjacent(cost.geometry, path, sibling, pt.longArcBound, &joined)) {
    FusedParting again;
    FusedForkRetrace r2 = retraceFusedForkFirst(cost, path, joined, connectivity, lumenLevel, o, &again);
    if (r2.changed || again.read) r = std::move(r2), pt = again;
  }
  if (r.changed || !pt.read) return r;
  const std::vector<Index3>& sib = joined.empty() ? sibling : joined;
  FusedForkRetrace second =
      retraceFromJoinedSection(cost, path, sib, pt.c, pt.e, pt.rS, pt.rOwn, connectivity, lumenLevel, o);
  // A second reading whose route runs back along itself is no tube's route (passesOneVoxelTwice): left as it was.
  if (!second.changed || passesOneVoxelTwice(second.voxels)) return r;
  second.walked = r.walked;
  return second;
}

}  // namespace vs
