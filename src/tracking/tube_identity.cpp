// The tube's identity along a route by the width of the lobe it runs in (issue 21, session 41 tieA, tieA2).
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "tracking/box_search.h"
#include "tracking/neck_retrace.h"
#include "util/median.h"

namespace vs {

namespace {

// Whether the two tubes a route's sections cut read as two widths at all: the median of the two lobes' radius
// difference over every two-lobe section along the route is larger than the section grid's step (the step under which
// one section's difference is not read) and than its own scatter along the route (median absolute deviation). A
// near-equal pair across thick slices reads the lobe nearer a slice wider, and which one wanders along the pair: its
// differences are read on some sections and not on others, their median under the step (tieA2, 3109).
bool widthsApart(const std::vector<LobeWidths>& w, double step) {
  std::vector<double> d;
  for (const LobeWidths& s : w)
    if (s.two) d.push_back(std::abs(s.rOwn - s.rOther));
  if (d.empty()) return false;
  const double m = medianOf(d);
  for (double& x : d) x = std::abs(x - m);
  return m > step && m > medianOf(d);
}

}  // namespace

// Where two touching tubes of unlike width are cut by the neck re-search's sections (two lobes), the path's own lobe
// is the thinner or the wider one. A route that crosses a contact the thick slices fuse shows no lobe change where it
// crosses (the sections there have one lobe) but its own lobe is the other width before and after. Read only where the
// route's two-lobe sections show two widths (widthsApart); then each two-lobe section's identity: the thinner or the
// wider lobe, where the two radii differ by more than the section's sampling step (sectionAt's grid, half the finest
// spacing: a difference under it is not read); runs of one identity shorter than 2k such sections are flicker (kissA's
// run rule); a change counted between two runs of 2k or more.
namespace {

// A run of 2k or more two-lobe sections of one width identity (+1 the wider lobe, -1 the thinner): sections first..last
// of the route.
struct WidthRun {
  size_t first = 0, last = 0;
  int id = 0;
};

// Each section's width identity: +1 where its own lobe is the wider, -1 the thinner, 0 where it is not read (one lobe,
// or its two radii within `step` of each other).
std::vector<int> widthIds(const std::vector<LobeWidths>& w, double step) {
  std::vector<int> ids(w.size(), 0);
  for (size_t i = 0; i < w.size(); ++i)
    if (w[i].two && std::abs(w[i].rOwn - w[i].rOther) > step) ids[i] = w[i].rOwn > w[i].rOther ? 1 : -1;
  return ids;
}

// A displacement's length across the tubes at two-lobe sections p and q (off their mean tangent).
struct Sideways {
  Vec3 t;
  Sideways(const LobeWidths& p, const LobeWidths& q) : t((p.t + q.t).normalized()) {}
  double operator()(const Vec3& d) const { return (d - d.dot(t) * t).norm(); }
};

// Whether the lobes at two-lobe sections p (before) and q crossed sideways to the tubes between them: the own lobe at q
// where the other lobe was at p, and the other where the own was (changesLobe's test by place, neck_retrace.cpp).
bool lobesCrossed(const LobeWidths& p, const LobeWidths& q) {
  const Sideways side(p, q);
  return side(q.own - p.other) + side(q.other - p.own) < side(q.own - p.own) + side(q.other - p.other);
}

// Whether the route went over into the other tube between two-lobe sections p and q, read by place alone: the lobes
// crossed (lobesCrossed), the own lobe at q lies off the own lobe's disc at p (sideways farther than its radius,
// onOwnDisc's measure) - the route's lobe moved - and on the other lobe's at p (within the two lobes' radii: the same
// tube). Where the own lobe stayed, the crossing is the other lobe's: a third structure on the far side, or the
// sections' planes turned at a bend (thin 10425: the own lobe 0.41 mm from where it was, the other 15 mm across;
// 11723: 0.17 mm and 21 mm); where it moved but not onto the other lobe, the route turned and the other lobe is
// another structure (thin 16427: 80 degrees between the two sections, the own lobe 11.1 mm from the other's place,
// their radii 3.8) - none of them changed tube.
bool wentOver(const LobeWidths& p, const LobeWidths& q) {
  if (!lobesCrossed(p, q)) return false;
  const Sideways side(p, q);
  return side(q.own - p.own) > p.rOwn && side(q.own - p.other) <= p.rOther + q.rOwn;
}

// Each two-lobe section's identity by place, where the two widths are not read (a near-equal pair): the first two-lobe
// section's lobe +1, and the identity changes at every two-lobe section where the route went over against the one
// before (wentOver) - the route's own lobe now where the other was: the route went over into the other tube, across a
// gap of one-lobe sections (a contact the thick slices fuse) or between two sections. The two tubes of a pair do not
// swap sides where the route stays in one of them (8809: path 1 from the fork in b1, b2 beside it, then over at their
// contact where the sections showed one lobe for 13 points; 4310: parallel tubes, the route over through the gap a
// thick slice thins; their radii apart by 0.24 / 0.16 voxel, under the section grid's step).
std::vector<int> placeIds(const std::vector<LobeWidths>& w) {
  std::vector<int> ids(w.size(), 0);
  int id = 1;
  const LobeWidths* prev = nullptr;
  for (size_t i = 0; i < w.size(); ++i) {
    if (!w[i].two) continue;
    if (prev && wentOver(*prev, w[i])) id = -id;
    ids[i] = id, prev = &w[i];
  }
  return ids;
}

// Each run of one identity among sections from..end (sections of id 0 skipped), in order, with the number of sections
// read in it: onRun(run, n), the last run too.
template <class OnRun>
void forEachIdentityRun(const std::vector<int>& ids, size_t from, OnRun onRun) {
  WidthRun cur;
  size_t n = 0;
  for (size_t i = from; i < ids.size(); ++i) {
    if (ids[i] == 0) continue;
    if (ids[i] != cur.id) onRun(cur, n), cur = {i, i, ids[i]}, n = 0;
    cur.last = i;
    ++n;
  }
  onRun(cur, n);
}

// The route's identity per section: by width where the route's two-lobe sections show two widths (widthsApart), else by
// place where `byPlace` (retraceByWidth's reading), else none.
struct IdentityReading {
  std::vector<int> ids;
  bool byPlace = false;
};

IdentityReading readIdentity(const std::vector<LobeWidths>& w, const CrossingOptions& o, bool byPlace) {
  const double step = w.empty() ? 0.0 : 0.5 * o.smoothed->geometry().spacing.minCoeff();
  if (widthsApart(w, step)) return {widthIds(w, step), false};
  if (byPlace) return {placeIds(w), true};
  return {};
}

// The runs of 2k or more sections of one identity (kissA's run rule: shorter runs are flicker), in order.
std::vector<WidthRun> longRuns(const IdentityReading& id, const CrossingOptions& o) {
  const size_t k = size_t(std::max(1, o.neckLobeSteps));
  std::vector<WidthRun> runs;
  forEachIdentityRun(id.ids, 0, [&](const WidthRun& run, size_t n) {
    if (n >= 2 * k) runs.push_back(run);
  });
  return runs;
}

// The route's runs read by width (tubeWidthChanges' reading), in order; empty where the widths are not read.
std::vector<WidthRun> widthRuns(const std::vector<LobeWidths>& w, const CrossingOptions& o) {
  return longRuns(readIdentity(w, o, false), o);
}

// Whether two runs of unlike width are the same two tubes with the route's lobe swapped, by size and by place
// (changesLobe's two tests, neck_retrace.cpp): each lobe's median radius over one run nearer the other lobe's over the
// other run than its own, and the lobes at a's last section and b's first crossed sideways to the tubes (the own lobe
// where the other was). A route through a tree's fork or a wide lumen's reads its own lobe the parent's width, then the
// child's, beside other structures: not a change between two touching tubes (thin 25, wide 10404).
// Read by place (a near-equal pair), the sizes are not read: the place test alone (wentOver).
bool swappedBetween(const std::vector<LobeWidths>& w, const WidthRun& a, const WidthRun& b, bool byPlace) {
  if (byPlace) return wentOver(w[a.last], w[b.first]);
  const auto medians = [&](const WidthRun& run) {
    std::vector<double> own, other;
    for (size_t i = run.first; i <= run.last; ++i)
      if (w[i].two) own.push_back(w[i].rOwn), other.push_back(w[i].rOther);
    return std::pair<double, double>{medianOf(own), medianOf(other)};
  };
  const auto [ownA, otherA] = medians(a);
  const auto [ownB, otherB] = medians(b);
  const bool sizes =
      std::abs(ownB - otherA) + std::abs(otherB - ownA) < std::abs(ownB - ownA) + std::abs(otherB - otherA);
  return sizes && lobesCrossed(w[a.last], w[b.first]);
}

// The route's runs read by width with its end's run: after the last run of 2k sections or more, the last run of k or
// more sections (the pair test's count) of the other identity, where the route ends in it (no run of k after it). The
// target lies in the route's own tube, so the stretch of two lobes nearest it is the own tube beside the other where
// the two part; a route that came along the other tube from the fork crosses into its own only there, and that
// stretch is as long as the tubes run side by side after the crossing - often under 2k (kind A's "drift at depart":
// 14809 path 1 in the wide neighbour over 33 sections, its own thin lobe over the last 7). Flicker (2k) is read
// between two runs the route has both sides of; the end has one. Read only where the two lobes swap against the run
// before it (swappedBetween: the route crossed into the other lobe); an end whose other lobe is a third structure or
// the neighbour's fading end reads its own lobe the wider without a crossing (8307 path 0: own 1.0-1.4 mm beside
// 0.5-0.9 over its last 5 sections, its lobe where it was).
std::vector<WidthRun> withEndRun(const std::vector<LobeWidths>& w, const CrossingOptions& o,
                                 const IdentityReading& id) {
  std::vector<WidthRun> runs = longRuns(id, o);
  if (runs.empty()) return runs;
  const size_t k = size_t(std::max(1, o.neckLobeSteps));
  WidthRun end;
  bool any = false;
  forEachIdentityRun(id.ids, runs.back().last + 1, [&](const WidthRun& run, size_t n) {
    if (n >= k) end = run, any = true;
  });
  if (any && end.id != runs.back().id && swappedBetween(w, runs.back(), end, id.byPlace)) runs.push_back(end);
  return runs;
}

// The sections read for the route's own tube only where the route's point lies in its own lobe's disc (sideways to the
// section, within the lobe's radius: changesLobe's "off its disc" measure). sectionAt takes the own lobe at the highest
// sample within a largest spacing of the path's voxel; on thick slices that can be the wide neighbour's peak, and the
// section then reads the neighbour's lobe as the route's and the route's own thin tube as the small other lobe, while
// the route has not moved (7108 path 0: straight in its own tube, read wide from point 38 on, own lobe's centroid 2.5
// mm off the route, its disc 1.2-1.8 mm; 7309 back to main's line too, not probed).
std::vector<LobeWidths> onOwnDisc(std::vector<LobeWidths> w, const std::vector<Index3>& path, const Geometry& g) {
  for (size_t i = 0; i < w.size() && i < path.size(); ++i) {
    if (!w[i].two) continue;
    const Vec3 d = retrace::mmOf(g, path[i]) - w[i].own;
    if ((d - d.dot(w[i].t) * w[i].t).norm() > w[i].rOwn) w[i].two = false;
  }
  return w;
}

// The sections read for width with a fork's crotch left out: the first k points of the route's first stretch of
// two-lobe sections (gaps of up to the bridge bridged, the pair test's stretches) where it does not start at the
// route's first point. Along a route from before the fork the first place another tube comes into the section is the
// fork the route's tube leaves its sibling at, and there the two lobes are the parent's and the branch's at the
// crotch, not two tubes side by side. The pair test's full band lays no slab there (searchAcrossNeck, kindA7); the
// width reading reads the same points alike, so the two readers of the crotch agree (11808: a route one voxel sideways
// round the crotch read a change of width the band's route did not). A later stretch starts where the tubes show side
// by side again after a one-lobe gap - a fused contact, or where they part - and is read whole (7908: the route's
// change back into its own tube where the tubes part, at a stretch's first points).
std::vector<LobeWidths> withoutCrotch(std::vector<LobeWidths> w, const CrossingOptions& o) {
  const size_t k = size_t(std::max(1, o.neckLobeSteps)), bridge = size_t(std::max(0, o.neckBridge));
  size_t i = 0;
  while (i < w.size() && !w[i].two) ++i;
  if (i == 0 || i == w.size()) return w;
  size_t e = i;
  for (size_t j = i + 1, gap = 0; j < w.size(); ++j)
    if (w[j].two)
      e = j, gap = 0;
    else if (++gap > bridge)
      break;
  for (size_t j = i; j < i + k && j <= e; ++j) w[j].two = false;
  return w;
}

std::vector<LobeWidths> widthsAlong(const std::vector<Index3>& path, const CrossingOptions& o) {
  return withoutCrotch(lobeWidthsAlong(path, o), o);
}

int changesOf(const std::vector<WidthRun>& runs) {
  int changes = 0;
  for (size_t i = 1; i < runs.size(); ++i) changes += runs[i].id != runs[i - 1].id;
  return changes;
}

}  // namespace

// Where two touching tubes of unlike width are cut by the neck re-search's sections (two lobes), the path's own lobe
// is the thinner or the wider one. A route that crosses a contact the thick slices fuse shows no lobe change where it
// crosses (the sections there have one lobe) but its own lobe is the other width before and after. Read only where the
// route's two-lobe sections show two widths (widthsApart); then each two-lobe section's identity: the thinner or the
// wider lobe, where the two radii differ by more than the section's sampling step (sectionAt's grid, half the finest
// spacing: a difference under it is not read); runs of one identity shorter than 2k such sections are flicker (kissA's
// run rule); a change counted between two runs of 2k or more, and only where the two lobes swapped between them
// (swappedBetween, retraceByWidth's own test: by size, and by place the own lobe where the other was). A route that
// keeps to one tube reads its lobe wider beside one structure and thinner beside another without the lobes swapping
// (issue 21, session 51 contact: 19608's path 1 re-searched into its own thin tube B reads B wider where B bends out
// over A - the section tilted with B cuts A at its edge, 0.7-1.0 mm - and thinner where B lies beside A, its lobe in
// B's place all along; counted as a change, the neck re-search's route into B was refused for changing tube more
// often than the route through A, whose crossing at the fused contact reads no change at all).
int tubeWidthChanges(const std::vector<Index3>& path, const CrossingOptions& o) {
  const std::vector<LobeWidths> w = widthsAlong(path, o);
  const std::vector<WidthRun> runs = widthRuns(w, o);
  int changes = 0;
  for (size_t i = 1; i < runs.size(); ++i)
    changes += runs[i].id != runs[i - 1].id && swappedBetween(w, runs[i - 1], runs[i], false);
  return changes;
}

namespace {

// Blocks, at route point j, the disc of section s's own lobe: round its centroid normal to the section's tangent, its
// radius the lobe's own and a largest spacing more (slabOf's lateral margin) but not past the other lobe's disc; along
// the route half-way to the neighbouring points and a quarter of a largest spacing on (slabOf's); not past `bound`
// either (mm from the lobe's centroid: a carried disc's, below).
void blockOwnLobe(const Geometry& g, const retrace::Box& b, const std::vector<Index3>& path, size_t j,
                  const LobeWidths& s, double bound, std::vector<uint8_t>& blocked) {
  using retrace::mmOf;
  const double vmax = g.spacing.maxCoeff();
  const Vec3 t = s.t, pj = mmOf(g, path[j]);
  Vec3 side = s.other - s.own;
  side -= side.dot(t) * t;
  const double r = std::min({s.rOwn + vmax, side.norm() - s.rOther, bound});
  if (r <= 0) return;
  const Vec3 c = s.own - (s.own - pj).dot(t) * t;  // the lobe's centre at the point's place along the tubes
  const double aPrev = j > 0 ? (mmOf(g, path[j - 1]) - pj).dot(t) : 0.0;
  const double aNext = j + 1 < path.size() ? (mmOf(g, path[j + 1]) - pj).dot(t) : 0.0;
  const double lo = std::min({0.0, 0.5 * aPrev, 0.5 * aNext}) - 0.25 * vmax;
  const double hi = std::max({0.0, 0.5 * aPrev, 0.5 * aNext}) + 0.25 * vmax;
  const double reach = std::sqrt(r * r + std::max(-lo, hi) * std::max(-lo, hi)) + vmax;
  Index3 c0, rr;
  for (size_t a = 0; a < 3; ++a) {
    c0[a] = static_cast<int64_t>(std::llround(c[a] / g.spacing[a]));
    rr[a] = static_cast<int64_t>(std::ceil(reach / g.spacing[a]));
  }
  for (int64_t z = c0[2] - rr[2]; z <= c0[2] + rr[2]; ++z)
    for (int64_t y = c0[1] - rr[1]; y <= c0[1] + rr[1]; ++y)
      for (int64_t x = c0[0] - rr[0]; x <= c0[0] + rr[0]; ++x) {
        const Index3 v{x, y, z};
        if (!b.in(v)) continue;
        const Vec3 q = mmOf(g, v) - c;
        const double along = q.dot(t);
        if (along >= lo && along <= hi && (q - along * t).norm() <= r) blocked[size_t(b.index(v))] = 1;
      }
}

}  // namespace

// The route ends in its own tube (the target's); the stretches read in the other width are the neighbour's. Their
// sections' own lobes blocked (sections between two-lobe ones inside such a stretch carry the last two-lobe one's disc
// along the route: a one-lobe section is the pair fused, and the route runs in the lobe it ran in at the last two-lobe
// section, so the disc keeps its place beside the route - not along that section's tangent, which at a bend points
// across the neighbour - and is bounded by the other lobe at both ends of the gap, the tubes as near as the nearer end
// shows them; carried along the tangent with the margin bounded at the gap's start only, it covered the thin tube of
// 15408 / 15708 and the blocked route ran through the background, refused), the route from the path's start -
// the one place known to lie before the fork of the tube to take, as the neck re-search's own-tube try - to 2k points
// past the last such stretch.
RetraceOutcome retraceByWidth(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                              const CrossingOptions& o, bool* startBlocked) {
  RetraceOutcome r;
  if (!o.enabled || !o.smoothed || path.size() < 8 || o.smoothed->geometry().dims != cost.geometry.dims) return r;
  const Geometry& g = cost.geometry;
  const std::vector<LobeWidths> w = onOwnDisc(widthsAlong(path, o), path, g);
  const IdentityReading id = readIdentity(w, o, true);
  const std::vector<WidthRun> runs = withEndRun(w, o, id);
  const int changes = changesOf(runs);
  if (changes == 0) return r;
  for (size_t i = 1; i < runs.size(); ++i)
    if (runs[i].id != runs[i - 1].id && !swappedBetween(w, runs[i - 1], runs[i], id.byPlace)) {
      r.why = "the route's widths change without the two lobes swapping";
      return r;
    }
  const size_t k = size_t(std::max(1, o.neckLobeSteps));
  size_t hi = 0;
  for (const WidthRun& run : runs)
    if (run.id != runs.back().id) hi = std::max(hi, run.last);
  const size_t boxHi = std::min(path.size() - 1, hi + 4 * k);
  hi = std::min(path.size() - 1, hi + 2 * k);
  const retrace::Box b = retrace::boxAround(g, path, 0, boxHi);
  if (b.size() > (int64_t(1) << 23)) return r;
  std::vector<uint8_t> blocked(size_t(b.size()), 0);
  for (const WidthRun& run : runs) {
    if (run.id == runs.back().id) continue;
    size_t last = run.first, next = run.first;  // next: the two-lobe section ending the current gap (or the run's end)
    double gapBound = HUGE_VAL;
    for (size_t j = run.first; j <= run.last; ++j) {
      if (w[j].two) last = j;
      LobeWidths s = w[last];
      double bound = HUGE_VAL;  // a one-lobe point: the disc rides with the route, bounded at the gap's far end too
      if (j != last) {
        if (next < j) {  // a new gap: its far end and bound read once for all its points
          next = j;
          while (next < run.last && !w[next].two) ++next;
          const LobeWidths& q = w[next];
          Vec3 apart = q.other - q.own;
          apart -= apart.dot(q.t) * q.t;
          gapBound = apart.norm() - q.rOther;
        }
        bound = gapBound;
      }
      const Vec3 shift = retrace::mmOf(g, path[j]) - retrace::mmOf(g, path[last]);
      s.own += shift, s.other += shift;
      blockOwnLobe(g, b, path, j, s, bound, blocked);
    }
  }
  while (hi < boxHi && blocked[size_t(b.index(path[hi]))]) ++hi;
  if (startBlocked) *startBlocked = blocked[size_t(b.index(path[0]))] != 0;
  if (blocked[size_t(b.index(path[0]))] || blocked[size_t(b.index(path[hi]))]) {
    r.why = "the path's ends lie in the blocked lobe";
    return r;
  }
  const std::vector<Index3> part = retrace::stretch(path, 0, hi);
  const double oldPart = chainCost(cost, part);
  r.oldCost = chainCost(cost, path);
  double c = 0;
  std::vector<Index3> next = retrace::boxPath(cost, b, blocked, retrace::stepsFor(g, connectivity), part.front(),
                                              part.back(), (1 + o.neckCostSlack) * oldPart, &c);
  // The route the cost slack refuses held to the lumen by intensity (the neck re-search's lumenRoute): the change of
  // width read with the route's end is the tube's identity, and the own tube the route left may read dear in the cost
  // beside a brighter neighbour (kind A's "dear own tube": its axis between the surroundings and the lumen, its local
  // background read on the pair's own fringe) while it stays a lumen by intensity.
  if (next.empty()) next = lumenRoute(cost, o, b, blocked, connectivity, part, &c, &r.why);
  if (next.empty()) {
    if (r.why.empty()) r.why = "no route within the cost slack with the other width's lobe blocked";
    return r;
  }
  // A route that takes the other tube lies somewhere two largest spacings from the old one (the neck re-search's test):
  // one shifted by a voxel at the same cost read its sections' widths otherwise, not another tube (12508: a thin
  // tube's own route read wider over 13 sections, its re-search one voxel off at the fork).
  if (retrace::farthestFrom(g, next, part) < 2 * g.spacing.maxCoeff()) {
    r.why = "the new route stays beside the old one";
    return r;
  }
  std::vector<Index3> p = retrace::spliced(path, 0, hi, next);
  const std::vector<LobeWidths> wNew = onOwnDisc(widthsAlong(p, o), p, g);
  // The new route read as the old one was (by width, or by place where the old route's widths were not read).
  const IdentityReading idNew = id.byPlace ? IdentityReading{placeIds(wNew), true} : readIdentity(wNew, o, false);
  if (changesOf(withEndRun(wNew, o, idNew)) >= changes) {
    r.why = "the new route changes tube as often";
    return r;
  }
  return retrace::accepted(std::move(r), oldPart, c, std::move(p));
}

}  // namespace vs
