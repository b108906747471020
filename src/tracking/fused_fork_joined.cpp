// The fused-fork re-search's second reading of the parting (issue 21, session 43 forkE): the own child read from its
// far end back, section by section, to its first section joined with the sibling (fused_fork.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/box_search.h"
#include "tracking/contact_walk.h"
#include "tracking/fused_fork.h"

namespace vs {

using retrace::Box;
using retrace::mmOf;
using retrace::mmOfChain;
using walk::centredSection;
using walk::Lumen;
using walk::Section;
using walk::toPolyline;

namespace {

// The centred section at the chain's point j, normal to the chain over k steps either side.
Section sectionOn(const Lumen& lu, const Geometry& g, const std::vector<Index3>& chain, size_t j, size_t k, double dt,
                  double cap) {
  const size_t a = j >= k ? j - k : 0, b = std::min(chain.size() - 1, j + k);
  const Vec3 d = mmOf(g, chain[b]) - mmOf(g, chain[a]);
  return d.norm() > 0 ? centredSection(lu, mmOf(g, chain[j]), d.normalized(), dt, cap) : Section{};
}

// Which of two routes parting at c crossed into its own child: the one that ran up the other child's start turns at
// its entry from that child's direction into its own, while the one that kept to its child runs on along it. Each
// route's turn: its fused stretch (from the parting to its entry, the first point farther than twice the other
// child's radius from the other chain) against its own child's direction past the entry (the centred sections at the
// entry and h + k on). ownBack: the path's child's direction, pointing back (from the section at e and h + k on).
// The turn tells the crosser only where the children leave the fused stretch at an angle, their directions past the
// entries nearer perpendicular than parallel (over 45 degrees apart): nearer parallel, the route that crossed can step
// sideways across a contact between two limbs running the same way without turning (forkF's hairpin, 7321: b1's
// return limb beside b2's start, its paths to b1's children run straight on while b2's route bends past the kiss).
// True where the sibling turns more; false where the sibling's direction cannot be read or the children run nearer
// parallel.
bool siblingTurnsMoreAtItsEntry(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path,
                                const std::vector<Index3>& sibling, size_t c, size_t e, double rOwn,
                                const Vec3& ownBack, size_t h, size_t k, double dt, double cap) {
  if (sibling.size() <= c + k + 1) return false;
  const std::vector<Vec3> pathPast = mmOfChain(g, path, c - 1, path.size() - 1);
  size_t eS = c;
  while (eS < sibling.size() && toPolyline(mmOf(g, sibling[eS]), pathPast) <= 2 * rOwn) ++eS;
  const size_t farS = std::min(sibling.size() - 1 - k, eS + h + k);
  if (farS <= eS) return false;
  const Section ss = sectionOn(lu, g, sibling, eS, k, dt, cap), sf = sectionOn(lu, g, sibling, farS, k, dt, cap);
  if (!ss.lumen || !sf.lumen || (sf.centre - ss.centre).norm() <= 0) return false;
  const Vec3 sibOn = (sf.centre - ss.centre).normalized();
  if (-ownBack.dot(sibOn) > std::sqrt(0.5)) return false;
  const Vec3 ownFused = mmOf(g, path[e]) - mmOf(g, path[c - 1]),
             sibFused = mmOf(g, sibling[eS]) - mmOf(g, sibling[c - 1]);
  if (ownFused.norm() <= 0 || sibFused.norm() <= 0) return false;
  const double ownRunsOn = -ownFused.normalized().dot(ownBack), sibRunsOn = sibFused.normalized().dot(sibOn);
  return sibRunsOn < ownRunsOn;
}

}  // namespace

FusedForkRetrace retraceFromJoinedSection(const NodeCost3D& cost, const std::vector<Index3>& path,
                                          const std::vector<Index3>& sibling, size_t c, size_t e, double rS,
                                          double rOwn, int connectivity, double lumenLevel, const CrossingOptions& o) {
  FusedForkRetrace r;
  const Geometry& g = cost.geometry;
  const size_t h = static_cast<size_t>(std::max(1, o.spanSteps)),
               k = static_cast<size_t>(std::max(1, o.directionSteps));
  const double vmin = g.spacing.minCoeff(), vmax = g.spacing.maxCoeff(), dt = 0.5 * vmin, cap = 6 * vmax;
  const Lumen lu{cost, lumenLevel};
  const size_t far = std::min(path.size() - 1 - k, e + h + k);
  if (far <= e || c < 1) return r;
  // The own child read back from its far end (past the entry, one tube): each path point's centred section is joined
  // with the sibling where the sibling's chain past the parting runs within the section's radius and the sibling's
  // of its centre (the two walls touching). j1: the first joined section; j0: the last of that joined run.
  const std::vector<Vec3> sibPast = mmOfChain(g, sibling, c, sibling.size() - 1);
  size_t j1 = 0, j0 = 0;
  bool inRun = false;
  for (size_t j = far + 1; j-- > k;) {
    const Section s = sectionOn(lu, g, path, j, k, dt, cap);
    // Before the parting only the sibling's own sections (radius 0.5-2 rS, the walks' own-section bound): the run
    // stops where the shared chain's section is the parent's, not the sibling's start (11804: a wide trunk).
    const bool own = j >= c || (s.radius >= 0.5 * rS && s.radius <= 2 * rS);
    const bool joined = s.lumen && own && toPolyline(s.centre, sibPast) <= s.radius + rS;
    if (joined && !inRun) inRun = true, j1 = j;
    if (inRun && !joined) break;
    if (joined) j0 = j;
  }
  // Only a joined run that reaches back before the chains' parting is new: the paths to both children share it.
  if (!inRun || j0 + 1 >= c || j1 < c) return r;
  // The own child's axis past the entry (its sections at e and far): the shared stretch j0..c-1 is cut through the
  // sibling's start only where it lies off that axis continued back - beyond the own radius at every point (the path
  // whose own child continues the shared stretch, the sibling's own, is left as it is).
  const Section se = sectionOn(lu, g, path, e, k, dt, cap), sf = sectionOn(lu, g, path, far, k, dt, cap);
  if (!se.lumen || !sf.lumen || (se.centre - sf.centre).norm() <= 0) return r;
  const Vec3 axis = (se.centre - sf.centre).normalized();
  for (size_t j = j0; j < c; ++j) {
    const Vec3 q = mmOf(g, path[j]) - se.centre;
    if ((q - q.dot(axis) * axis).norm() <= rOwn) return r;
  }
  // The reading takes the sibling as the route that kept to its own child and the path as the one that cut through
  // the sibling's start. Where the sibling is the one that crossed (its search ran up the path's child's start), its
  // chain's tube covers the path's own start and the route round it runs in the sibling's lumen (16731's path 1, in
  // its own child, went 9 voxels into the sibling's): left as it is.
  if (siblingTurnsMoreAtItsEntry(lu, g, path, sibling, c, e, rOwn, axis, h, k, dt, cap)) return r;
  // Blocked: the sibling's chain from the joined run's back end to its point nearest the entry, h + k on, within the
  // sibling's radius and half a coarsest voxel, where nearer it than the shared chain before the run or the path from
  // its first joined section on (the trunk and the own child left open).
  size_t nearS = c;
  double dNear = std::numeric_limits<double>::infinity();
  for (size_t j = c; j < sibling.size(); ++j) {
    const double d = (mmOf(g, sibling[j]) - mmOf(g, path[e])).norm();
    if (d < dNear) dNear = d, nearS = j;
  }
  const size_t sEnd = std::min(sibling.size() - 1, nearS + h + k);
  const size_t lo0 = j0 > 2 * (h + k) ? j0 - 2 * (h + k) : 0, hi = std::min(path.size() - 1, e + h + k);
  const std::vector<Vec3> sibTube = mmOfChain(g, sibling, j0, sEnd);
  const std::vector<Vec3> trunk = mmOfChain(g, path, lo0, j0 - 1), own = mmOfChain(g, path, j1, hi);
  std::vector<Index3> around = retrace::stretch(path, lo0, hi);
  for (size_t j = j0; j <= sEnd; ++j) around.push_back(sibling[j]);
  // The box holds every detour the search's budget allows (a route at most twice the joined run longer than the old
  // one strays at most the joined run's length from it).
  const double joinedLen = retrace::chainLength(g, retrace::stretch(path, j0, j1));
  const Box bx = retrace::boxAround(g, around, 0, around.size() - 1, std::max(o.marginSteps, joinedLen / vmin));
  if (bx.size() > (int64_t(1) << 23)) return r;
  const double rBlock = rS + 0.5 * vmax;
  std::vector<uint8_t> blocked(static_cast<size_t>(bx.size()), 0);
  for (int64_t j = 0; j < bx.size(); ++j) {
    const Vec3 p = mmOf(g, bx.voxel(j));
    const double dS = toPolyline(p, sibTube);
    if (dS <= rBlock && std::min(toPolyline(p, trunk), toPolyline(p, own)) > dS) blocked[static_cast<size_t>(j)] = 1;
  }
  size_t lo = j0 - 1;
  while (lo > lo0 && blocked[static_cast<size_t>(bx.index(path[lo]))]) --lo;
  if (blocked[static_cast<size_t>(bx.index(path[lo]))] || blocked[static_cast<size_t>(bx.index(path[hi]))]) return r;
  const std::vector<Index3> part = retrace::stretch(path, lo, hi);
  const double oldPart = chainCost(cost, part), oldLen = retrace::chainLength(g, part);
  double nc = 0;
  std::vector<Index3> next =
      retrace::boxPath(cost, bx, blocked, retrace::stepsFor(g, connectivity), part.front(), part.back(),
                       (1 + o.costSlack) * oldPart / oldLen * (oldLen + 2 * joinedLen), &nc);
  if (next.empty()) return r;
  const double newLen = retrace::chainLength(g, next);
  double hole = 0, longest = 0;
  for (size_t t = 1; t < next.size(); ++t) {
    const bool in = cost.node[static_cast<size_t>(g.linear(next[t][0], next[t][1], next[t][2]))] <= lumenLevel;
    hole = in ? 0 : hole + (mmOf(g, next[t]) - mmOf(g, next[t - 1])).norm();
    longest = std::max(longest, hole);
  }
  if (nc / newLen > (1 + o.costSlack) * oldPart / oldLen || longest > o.lumenHoleVoxels * vmin ||
      retrace::farthestFrom(g, next, part) <= rOwn)
    return r;
  // A tube of its own: the new route off the old one (farther than the own radius from it) runs through the own
  // child's clean tube somewhere - a section of lumen, radius 0.5-2 rOwn (the walks' own-section bound) and not joined
  // with the sibling's chain (12501's swing; a route through the far side of an ordinary junction runs in the union).
  const std::vector<Vec3> sibAll = mmOfChain(g, sibling, j0, sibling.size() - 1);
  const std::vector<Vec3> oldMm = mmOfChain(g, part, 0, part.size() - 1);
  bool clean = false;
  for (size_t t = 0; t < next.size() && !clean; ++t) {
    const Vec3 q = mmOf(g, next[t]);
    double dOld = std::numeric_limits<double>::infinity();
    for (const Vec3& w : oldMm) dOld = std::min(dOld, (w - q).norm());
    if (dOld <= rOwn) continue;
    const Section s = sectionOn(lu, g, next, t, k, dt, cap);
    clean = s.lumen && s.radius >= 0.5 * rOwn && s.radius <= 2 * rOwn && toPolyline(s.centre, sibAll) > s.radius + rS;
  }
  if (!clean) return r;
  r.oldCost = chainCost(cost, path);
  return retrace::accepted(std::move(r), oldPart, nc, retrace::spliced(path, lo, hi, next));
}

}  // namespace vs
