#include "tracking/neck_retrace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "tracking/box_search.h"
#include "tracking/neck_section.h"
#include "tracking/neck_sections.h"
#include "tracking/path_support.h"
#include "tracking/tracker.h"
#include "util/median.h"
#include "volume/sample.h"

namespace vs {

using retrace::bottleneck;
using retrace::Box;
using retrace::boxPath;
using retrace::mmOf;
using retrace::shellMedian;
using retrace::signedAt;
using retrace::stepsFor;

namespace {

// The volume's trilinear sample (the project's one sampler) at p (mm), signed so that the lumen is
// high; NaN outside.
double sampleSigned(const TrilinearSampler& sampler, const Vec3& spacing, const Vec3& p, double sign) {
  const Vec3 index = p.cwiseQuotient(spacing);
  return sampler.inside(index) ? sign * sampler.at(index) : std::numeric_limits<double>::quiet_NaN();
}

using neck_detail::Section;

// The smoothed intensity's section normal to the path at point i (tangent over +-3 points), at the
// level half-way from the point's value to the section rim's median, split into 4-connected lobes.
// Not ownLobe (own_lobe.h, the refinement's split of one fused region by a watershed at the
// caller's level, session 18): the neck needs the other lobe too (its peak, centroid and area, and
// the neck between the peaks), and takes it as the largest other component at the first level
// (0.5 .. 0.9 of the way from the rim to the own peak) where the section falls apart - a
// neighbour apart from the own tube in the smoothed image counts, where ownLobe sees only the
// anchor's component. The two differ in level, split and plane basis (results change; split1).
Section sectionAt(const VolumeF32& sm, double sign, const std::vector<Index3>& path, size_t i) {
  Section sec;
  const Geometry& g = sm.geometry();
  const TrilinearSampler sampler(sm);
  const size_t a = i >= 3 ? i - 3 : 0, b = std::min(path.size() - 1, i + 3);
  Vec3 t = mmOf(g, path[b]) - mmOf(g, path[a]);
  if (t.norm() <= 0) return sec;
  t.normalize();
  sec.t = t;
  Vec3 u = std::abs(t[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = (u - u.dot(t) * t).normalized();
  const Vec3 w(t[1] * u[2] - t[2] * u[1], t[2] * u[0] - t[0] * u[2], t[0] * u[1] - t[1] * u[0]);
  const double h = 0.5 * g.spacing.minCoeff();
  const int m = 20;  // half size 10 smallest spacings: two touching tubes of up to ~4 voxels' radius
  const int n = 2 * m + 1;
  const Vec3 c = mmOf(g, path[i]);
  std::vector<double> val(static_cast<size_t>(n * n));
  std::vector<double> rim;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double v = sampleSigned(sampler, g.spacing, c + double(x - m) * h * u + double(y - m) * h * w, sign);
      val[static_cast<size_t>(y * n + x)] = v;
      if ((x == 0 || y == 0 || x == n - 1 || y == n - 1) && std::isfinite(v)) rim.push_back(v);
    }
  const double centre = val[static_cast<size_t>(m * n + m)];
  if (rim.size() < size_t(n) || !std::isfinite(centre)) return sec;
  const double bg = medianInPlace(rim);
  // The own lobe's peak (a path voxel off its lumen's axis is lower, and a level set from it merges the lobes):
  // climbed to within a voxel of the path's voxel (climbedPeak).
  const int peakAt = climbedPeak(val, n, m, std::max(1, static_cast<int>(std::lround(g.spacing.maxCoeff() / h))));
  const double peak = val[static_cast<size_t>(peakAt)];
  // Half-way first; where the neck is filled at that level (touching tubes smoothed), higher levels
  // up to 0.8 of the way from the rim to the point's value.
  // A small tube beside a large one may never be a lobe of its own at a level set from the large
  // one's peak half-way (its neck filled) nor at a high one (its own peak lower): levels in steps.
  for (const double frac : {0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9}) {
    const double level = bg + frac * (peak - bg);
    if (!(peak > level)) return sec;
    std::vector<int> lab(static_cast<size_t>(n * n), -1);
    std::vector<int> area, top;
    std::vector<Vec3> sum;
    for (int s0 = 0; s0 < n * n; ++s0) {
      if (lab[static_cast<size_t>(s0)] >= 0 || !(val[static_cast<size_t>(s0)] >= level)) continue;
      const int l = static_cast<int>(area.size());
      area.push_back(0);
      top.push_back(s0);
      sum.push_back(Vec3::Zero());
      std::vector<int> st{s0};
      lab[static_cast<size_t>(s0)] = l;
      while (!st.empty()) {
        const int q = st.back();
        st.pop_back();
        const int qx = q % n, qy = q / n;
        area[static_cast<size_t>(l)]++;
        if (val[static_cast<size_t>(q)] > val[static_cast<size_t>(top[static_cast<size_t>(l)])])
          top[static_cast<size_t>(l)] = q;
        sum[static_cast<size_t>(l)] += c + double(qx - m) * h * u + double(qy - m) * h * w;
        const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (const auto& d : nb) {
          const int x = qx + d[0], y = qy + d[1];
          if (x < 0 || y < 0 || x >= n || y >= n) continue;
          const int r = y * n + x;
          if (lab[static_cast<size_t>(r)] < 0 && val[static_cast<size_t>(r)] >= level) {
            lab[static_cast<size_t>(r)] = l;
            st.push_back(r);
          }
        }
      }
    }
    const int own = lab[static_cast<size_t>(peakAt)];
    int other = -1;
    for (int l = 0; l < static_cast<int>(area.size()); ++l)
      if (l != own && (other < 0 || area[static_cast<size_t>(l)] > area[static_cast<size_t>(other)])) other = l;
    if (own < 0 || other < 0) continue;
    const double ao = area[static_cast<size_t>(own)], ax = area[static_cast<size_t>(other)];
    if (ax < 3 || ao < 3) continue;
    if (!rimIsBackground(val, lab, n, bg, level, own, other)) return sec;  // inside a wider lumen: no neck
    sec.two = true;
    const int tq = top[static_cast<size_t>(other)];
    sec.otherPeak = c + double(tq % n - m) * h * u + double(tq / n - m) * h * w;
    sec.ownPeak = c + double(peakAt % n - m) * h * u + double(peakAt / n - m) * h * w;
    // The neck: the lowest sample on the line between the two peaks.
    double lowest = std::numeric_limits<double>::infinity();
    for (int j = 1; j < 20; ++j) {
      const Vec3 q = sec.ownPeak + (double(j) / 20.0) * (sec.otherPeak - sec.ownPeak);
      const double v = sampleSigned(sampler, g.spacing, q, sign);
      if (std::isfinite(v) && v < lowest) lowest = v, sec.neck = q;
    }
    sec.own = sum[static_cast<size_t>(own)] / ao;
    sec.other = sum[static_cast<size_t>(other)] / ax;
    sec.rOwn = std::sqrt(ao / std::numbers::pi) * h;
    sec.rOther = std::sqrt(ax / std::numbers::pi) * h;
    return sec;
  }
  return sec;
}

struct NeckCrossing {
  bool found = false;
  size_t first = 0, last = 0, at = 0;  // the two-lobe stretch and the crossing in it
  size_t back = 0;                     // a detour's change back (followedDetour), else 0
};

// How the lobes go on from two-lobe section p to q > p (changesLobe).
enum class LobeStep { Stays, Changes, Third };

// Whether the path's lobe changed between two-lobe sections p < q: the own lobe at q sits where the
// other one was at p, sideways to the tubes (their places along the tubes differ by the points
// between). A drift goes on along the touching tubes; a tube's own hairpin turns back, its two
// limbs show as two lobes and passing the turn moves the own lobe to where the other was (thin
// seed 3: a route re-searched round a single tube's U-turn): no change where the sections' tangents
// k points before p and after q are >= 90 degrees apart.
// The lobes are followed by identity, each by its place and size: the other lobe as it was last
// seen (section po <= p; po = p unless a third structure came between). The places' test above
// also passes where the path's lobe stays what and where it was and only the section's other lobe
// is another structure (the largest other component: a third tube on the far side; sep41, the head
// CTA sinus: own lobe 0.75 mm on, the other 9.7 mm off). A change needs the path's lobe to be
// another lobe at q: off its disc at p (its sideways move larger than its radius) or swapped in
// size with the other (the crossed radii's differences' sum smaller than the straight ones', the
// places' test's form); else the other lobe at q is a third structure (Third): not a change, and
// not the lobe followed on.
LobeStep changesLobe(const std::vector<Section>& secs, size_t p, size_t po, size_t q, size_t k) {
  const Section &a = secs[p], &ao = secs[po], &b = secs[q];
  const Section &ta = secs[p >= k ? p - k : 0], &tb = secs[std::min(secs.size() - 1, q + k)];
  if (ta.t.dot(tb.t) <= 0 || a.t.dot(b.t) <= 0) return LobeStep::Stays;
  const Vec3 t = (a.t + b.t).normalized();
  const auto side = [&](const Vec3& d) { return (d - d.dot(t) * t).norm(); };
  if (!(side(b.own - ao.other) + side(b.other - a.own) < side(b.own - a.own) + side(b.other - ao.other)))
    return LobeStep::Stays;
  const bool offDisc = side(b.own - a.own) > a.rOwn;
  const bool swapped = std::abs(b.rOwn - ao.rOther) + std::abs(b.rOther - a.rOwn) <
                       std::abs(b.rOwn - a.rOwn) + std::abs(b.rOther - ao.rOther);
  return offDisc || swapped ? LobeStep::Changes : LobeStep::Third;
}

// The first crossing in the stretch [i, e]: the own lobe k points on nearer the other lobe k points
// back than its own, and the same the other way round. Not within 3k points of the stretch's start:
// a branch leaving its parent at a fork changes lobe there in the same way (the unit test's
// re-searched route into B's own bend), while a drift runs along the contact first.
size_t pairCrossing(const std::vector<Section>& secs, size_t i, size_t e, size_t k) {
  for (size_t c = i + 3 * k; c + k <= e; ++c) {
    const Section &p = secs[c - k], &q = secs[c + k];
    if (!p.two || !q.two || p.t.dot(q.t) <= 0) continue;  // a hairpin (above)
    const double d0 = (q.own - p.own).norm();
    if ((q.own - p.other).norm() < d0 && (p.own - q.other).norm() < d0) return c;
  }
  return 0;
}

// Kissing tubes' lobes are alike: within this factor in radius (followedCrossing, below).
constexpr double kNeckLikeRatio = 2.5;

// The lobes' changes through the stretch [i, e] (followedCrossing's and followedDetour's rules).
struct LobeChange {
  size_t at = 0, runBefore = 0;  // the change and the two-lobe sections since the one before it
  bool alike = false;
};

struct LobeChanges {
  std::vector<LobeChange> changes;
  bool stays = false;  // 2k two-lobe sections after the last change, or the path alone to its end
};

LobeChanges lobeChanges(const std::vector<Section>& secs, size_t i, size_t e, size_t k, size_t likeWithin,
                        double likeRatio, bool identity = false) {
  LobeChanges out;
  size_t prev = secs.size(), prevOther = secs.size(), run = 0;
  for (size_t c = i; c <= e; ++c) {
    if (!secs[c].two) continue;
    const LobeStep step =
        prev < secs.size() && c >= i + 2 * k ? changesLobe(secs, prev, prevOther, c, k) : LobeStep::Stays;
    if (step == LobeStep::Changes || (!identity && step == LobeStep::Third)) {
      LobeChange ch{c, run, false};
      run = 0;
      const auto like = [likeRatio](const Section& q) {
        return q.two && std::max(q.rOwn, q.rOther) <= likeRatio * std::min(q.rOwn, q.rOther);
      };
      bool before = like(secs[prev]), after = like(secs[c]);
      for (size_t d = prev, n = 0; d-- > i && n < likeWithin && !before;) n += secs[d].two, before = like(secs[d]);
      for (size_t d = c + 1, n = 0; d <= e && n < likeWithin && !after; ++d) n += secs[d].two, after = like(secs[d]);
      ch.alike = before && after;
      out.changes.push_back(ch);
    }
    ++run;
    prev = c;
    if (!identity || step != LobeStep::Third) prevOther = c;
  }
  // After the change, 2k two-lobe sections; or, where the tubes part, the path alone in its new tube
  // to its end (no two-lobe section after the stretch) for 2k points - it cannot change back (10209:
  // the path to B ran in A to where the tubes part and stepped into B 7 two-lobe sections before the
  // other lobe left the section).
  size_t after = e + 1;
  while (after < secs.size() && !secs[after].two) ++after;
  const size_t last = out.changes.empty() ? 0 : out.changes.back().at;
  out.stays = run >= 2 * k || (after == secs.size() && secs.size() - last >= 2 * k);
  return out;
}

// The two lobes followed through the stretch [i, e] (not within 2k points of its start, as above),
// each two-lobe section's matched to the previous one's (changesLobe). An odd number of changes is a
// crossing, at the last one: a path that touches the neck and comes back changes twice (517 at
// points 43-44, then its crossing where the tubes part; the pair test takes the touch and misses
// 10409's, where the other tube still converges). Kissing tubes are alike and the path stays in each
// for a while: the last change needs lobes within a factor `likeRatio` in radius either side, and 2k
// two-lobe sections before it and after it (a thin tree's forks, a wide lumen's split sections), or
// after it the path alone to its end (lobeChanges).
// With `likeWithin` > 0, the lobes' likeness may come from any of that many two-lobe sections
// before or after the change (541: the section through the path's voxel in the neck, next to a
// one-lobe gap, shows the other lobe at a third of the own one's radius).
size_t followedCrossing(const std::vector<Section>& secs, size_t i, size_t e, size_t k, size_t likeWithin,
                        double likeRatio, bool identity) {
  const LobeChanges lc = lobeChanges(secs, i, e, k, likeWithin, likeRatio, identity);
  if (lc.changes.size() % 2 == 0) return 0;
  const LobeChange& last = lc.changes.back();
  return last.alike && last.runBefore >= 2 * k && lc.stays ? last.at : 0;
}

// A detour (session 30): the lobes followed change twice, the path in the other tube for a run of 2k
// two-lobe sections or more in between, and as long in its own before and after - a touch of the
// neck changes twice with no run between (517), which followedCrossing reads as none (11307: the
// path to A ran in B over points 33-68, its own lobe B's there, and came back). Both changes' lobes
// alike (followedCrossing's rule). The first change; `back` the second.
size_t followedDetour(const std::vector<Section>& secs, size_t i, size_t e, size_t k, size_t likeWithin, size_t& back) {
  const LobeChanges lc = lobeChanges(secs, i, e, k, likeWithin, kNeckLikeRatio);
  if (lc.changes.size() != 2 || !lc.stays) return 0;
  const LobeChange &a = lc.changes[0], &b = lc.changes[1];
  if (!a.alike || !b.alike || a.runBefore < 2 * k || b.runBefore < 2 * k) return 0;
  back = b.at;
  return a.at;
}

NeckCrossing findNeckCrossing(const std::vector<Section>& secs, int k, int bridge, bool followed, size_t likeWithin = 0,
                              bool detour = false, double likeRatio = kNeckLikeRatio, bool identity = false) {
  NeckCrossing nc;
  const size_t np = secs.size(), ku = static_cast<size_t>(std::max(1, k));
  // Stretches of two-lobe sections, gaps of up to `bridge` points bridged (a section through a
  // voxel in the neck shows one lobe).
  size_t i = 0;
  while (i < np) {
    if (!secs[i].two) {
      ++i;
      continue;
    }
    size_t e = i, j = i + 1, gap = 0;
    for (; j < np; ++j) {
      if (secs[j].two) {
        e = j;
        gap = 0;
      } else if (++gap > static_cast<size_t>(bridge)) {
        break;
      }
    }
    size_t back = 0;
    const size_t c = detour     ? followedDetour(secs, i, e, ku, likeWithin, back)
                     : followed ? followedCrossing(secs, i, e, ku, likeWithin, likeRatio, identity)
                                : pairCrossing(secs, i, e, ku);
    if (c > 0) return {true, i, e, c, back};
    i = e + 1;
  }
  return nc;
}

// The sections with only the runs of at least 2k two-lobe sections (gaps of up to `bridge` bridged)
// left two-lobe: inside a long fused contact the section falls apart here and there into small
// lobes of noise (11108: lobes of 0.4-0.8 mm at 5 scattered points of a 43-point one-lobe stretch),
// which are not two tubes - their lobes, taken for the tubes', turn the band onto the other tube.
std::vector<Section> longRunsOnly(std::vector<Section> secs, size_t k, size_t bridge) {
  size_t i = 0;
  while (i < secs.size()) {
    if (!secs[i].two) {
      ++i;
      continue;
    }
    size_t e = i, n = 0, gap = 0;
    for (size_t j = i; j < secs.size() && gap <= bridge; ++j)
      if (secs[j].two)
        e = j, ++n, gap = 0;
      else
        ++gap;
    // The last run may be shorter where the path runs on alone to its end for 2k points from it (the
    // tubes have parted: followedCrossing's rule).
    bool lastRun = true;
    for (size_t j = e + 1; j < secs.size() && lastRun; ++j) lastRun = !secs[j].two;
    if (n < 2 * k && !(lastRun && secs.size() - i >= 2 * k))
      for (size_t j = i; j <= e; ++j) secs[j].two = false;
    i = e + 1;
  }
  return secs;
}

// memo (o.neckSections, the tracker's): sections read before on any route through the same three points.
std::vector<Section> sectionsOf(const VolumeF32& sm, double sign, const std::vector<Index3>& path,
                                NeckSectionMemo* memo) {
  std::vector<Section> secs(path.size());
  for (size_t i = 0; i < path.size(); ++i) {
    const size_t a = i >= 3 ? i - 3 : 0, b = std::min(path.size() - 1, i + 3);  // sectionAt's tangent span
    const auto read = [&] { return sectionAt(sm, sign, path, i); };
    secs[i] = memo ? memo->get(&sm, sign, {path[a], path[i], path[b]}, read) : read();
  }
  return secs;
}

// A section's piece of the neck band: the plane through the neck normal to the peaks' line (sideways
// to the tubes), `half` either side, `lateral` off the line, alongLo..alongHi along from `mid`.
struct Slab {
  bool ok = false;
  Vec3 mid{0, 0, 0}, n{0, 0, 0}, t{0, 0, 1};
  double half = 0, lateral = 0, alongLo = 0, alongHi = 0;
};

Slab slabOf(const Geometry& g, const std::vector<Index3>& full, size_t j, Section s, int k, bool tight) {
  Slab sl;
  const double vmin = g.spacing.minCoeff(), vmax = g.spacing.maxCoeff();
  // The band's slab along the tubes' direction over 3k points either side: where the path
  // crosses, its own tangent is tilted across the contact and a slab normal to it leaves the
  // straight sections' slabs a gap (the unit test's route went through it).
  const size_t ja = j > size_t(3 * k) ? j - size_t(3 * k) : 0, jb = std::min(full.size() - 1, j + size_t(3 * k));
  const Vec3 tl = mmOf(g, full[jb]) - mmOf(g, full[ja]);
  if (tl.norm() > 0) s.t = tl.normalized();
  Vec3 d = s.otherPeak - s.ownPeak;
  d -= d.dot(s.t) * s.t;
  const double dl = d.norm();
  if (dl <= 0) return sl;
  sl.t = s.t;
  sl.n = d / dl;
  // The slab sits at the path point's place along the tubes, not at the neck sample's: where the
  // path bends across the contact its sections are tilted, their necks lie up to 1.7 voxels apart
  // along the tubes, and slabs of a fixed half voxel around them left holes the re-searched route
  // took (the unit test's route crossed again at x 56-58). Along, each slab reaches half-way to
  // the neighbouring points (a diagonal step advances more than a voxel) and a quarter voxel on.
  const Vec3 pj = mmOf(g, full[j]);
  sl.mid = s.neck - (s.neck - pj).dot(s.t) * s.t;
  const double aPrev = j > 0 ? (mmOf(g, full[j - 1]) - pj).dot(s.t) : 0.0;
  const double aNext = j + 1 < full.size() ? (mmOf(g, full[j + 1]) - pj).dot(s.t) : 0.0;
  sl.alongLo = std::min({0.0, 0.5 * aPrev, 0.5 * aNext}) - 0.25 * vmax;
  sl.alongHi = std::max({0.0, 0.5 * aPrev, 0.5 * aNext}) + 0.25 * vmax;
  // sum_a |n_a| s_a either side: half that is a plane no 26-step jumps, but the planes of
  // neighbouring sections are shifted and tilted against each other (558 leaked diagonally).
  const Vec3& n = sl.n;
  const double thick = std::abs(n[0]) * g.spacing[0] + std::abs(n[1]) * g.spacing[1] + std::abs(n[2]) * g.spacing[2];
  sl.half = thick;
  if (tight) {
    // Where the tubes lie under two slices apart across thick slices (517: 3.2 mm at 1.9 mm) that
    // band covers both tubes' axes and leaves the re-search no lumen: it ends half the figure
    // short of the nearer lobe's centre, and is at least the half that no 26-step jumps. A section
    // whose lobes lie nearer the neck than that (the path's voxel in the neck) is a gap (below).
    const double peak = std::min(std::abs((s.ownPeak - sl.mid).dot(n)), std::abs((s.otherPeak - sl.mid).dot(n)));
    if (peak < 0.5 * thick + 0.5 * vmin) return sl;
    sl.half = std::max(0.5 * thick, std::min(thick, peak - 0.5 * thick));
  }
  sl.lateral = 0.5 * dl + vmax;  // the contact is narrower than the smaller tube
  sl.ok = true;
  return sl;
}

// Section q (at path point at) moved along the tubes to path point j: along the path's chord over 3k
// points either side (slabOf's direction), not the section's own tangent over 3 points, which a step
// of the path into the neck tilts - carried over a long gap its sideways part put the band on the
// other tube's axis (10209: a neck copied 22 points on lay 5 voxels off, the band cut B).
Section movedAlong(const Geometry& g, const std::vector<Index3>& full, Section q, size_t at, size_t j, int k) {
  const size_t a = at > size_t(3 * k) ? at - size_t(3 * k) : 0, b = std::min(full.size() - 1, at + size_t(3 * k));
  const Vec3 chord = mmOf(g, full[b]) - mmOf(g, full[a]);
  const Vec3 t = chord.norm() > 0 ? Vec3(chord.normalized()) : q.t;
  const Vec3 shift = (mmOf(g, full[j]) - mmOf(g, full[at])).dot(t) * t;
  q.neck += shift, q.ownPeak += shift, q.otherPeak += shift, q.own += shift, q.other += shift;
  return q;
}

double lengthMm(const Geometry& g, const std::vector<Index3>& q) {
  double l = 0;
  for (size_t i = 1; i < q.size(); ++i) l += (mmOf(g, q[i]) - mmOf(g, q[i - 1])).norm();
  return l;
}

void blockSlab(const Geometry& g, const Box& b, const Slab& sl, std::vector<uint8_t>& blocked) {
  const double vmax = g.spacing.maxCoeff();
  const double alongMax = std::max(-sl.alongLo, sl.alongHi);
  const double reachMm = std::sqrt(sl.half * sl.half + alongMax * alongMax + sl.lateral * sl.lateral) + vmax;
  Index3 c0, rr;
  for (size_t a = 0; a < 3; ++a) {
    c0[a] = static_cast<int64_t>(std::llround(sl.mid[a] / g.spacing[a]));
    rr[a] = static_cast<int64_t>(std::ceil(reachMm / g.spacing[a]));
  }
  for (int64_t z = c0[2] - rr[2]; z <= c0[2] + rr[2]; ++z)
    for (int64_t y = c0[1] - rr[1]; y <= c0[1] + rr[1]; ++y)
      for (int64_t x = c0[0] - rr[0]; x <= c0[0] + rr[0]; ++x) {
        const Index3 v{x, y, z};
        if (!b.in(v)) continue;
        const Vec3 q = mmOf(g, v) - sl.mid;
        const double along = q.dot(sl.t), across = q.dot(sl.n);
        const Vec3 side = q - along * sl.t - across * sl.n;
        if (std::abs(across) <= sl.half && along >= sl.alongLo && along <= sl.alongHi && side.norm() <= sl.lateral)
          blocked[static_cast<size_t>(b.index(v))] = 1;
      }
}

// Whether the tighter band's route keeps the old route before the crossing. The followed lobes'
// crossing is a change of tube (the pair test's may be a touch of the neck, the path in its own
// tube all along); the band lies between the lobes over the whole stretch and the route ends in
// the tube taken after the crossing, so a route round the band runs in that tube from the fork on,
// away from the old one. One that still follows the old route (within a largest spacing) at most
// of the stretch's points clear of the fork and the crossing (2k either side) went through a hole
// in the band (11308: the tight band's route ran on in A for 40 points and crossed 10 points
// before the old one; the tube left blocked instead takes B from the fork).
bool leaksAlongOld(const Geometry& g, const std::vector<Index3>& full, const NeckCrossing& nc, int k,
                   const std::vector<Index3>& route) {
  const size_t k2 = 2 * static_cast<size_t>(k);
  if (nc.at < nc.first + 2 * k2 + 1) return false;
  size_t kept = 0, n = 0;
  for (size_t j = nc.first + k2; j + k2 <= nc.at; ++j, ++n) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Index3& v : route) nearest = std::min(nearest, (mmOf(g, v) - mmOf(g, full[j])).norm());
    kept += nearest <= g.spacing.maxCoeff();
  }
  return 2 * kept > n;
}

// Whether every point of `route` lies in the lumen by intensity, whatever the node cost reads there:
// more than dipShare of the way from its local background (the shell median dipShellVoxels
// smallest spacings away) to the old part's level (its median) - the dip test's line between a
// point outside the lumen and one in it. "Above the background" alone is no lumen test: a route
// round a blocked neck through the partial-volume tissue beside a thin tree's forks or a parallel
// pair stays above it (session 31: such routes lie 0.001-0.10 of the way up; 10207's into the
// thinner tube 0.52, 11407's 0.26).
bool inLumenByIntensity(const CrossingOptions& o, double sign, const std::vector<Index3>& old,
                        const std::vector<Index3>& route) {
  const double radius = o.dipShellVoxels * o.smoothed->geometry().spacing.minCoeff();
  std::vector<double> lv;
  lv.reserve(old.size());
  for (const Index3& v : old) lv.push_back(signedAt(*o.smoothed, v, sign));
  const double level = medianInPlace(lv);
  for (const Index3& v : route) {
    const double bg = shellMedian(*o.smoothed, v, radius, sign);
    if (!(level > bg) || !(signedAt(*o.smoothed, v, sign) > bg + o.dipShare * (level - bg))) return false;
  }
  return true;
}

// The longest run of a route's voxels for which off(voxel) holds, from the run's first voxel's centre to its last
// (mm along the route).
template <class Off>
double longestRunMm(const Geometry& g, const std::vector<Index3>& route, Off off) {
  double longest = 0, run = -1;  // run: mm since the run's first voxel (negative: no run)
  for (size_t i = 0; i < route.size(); ++i) {
    if (!off(route[i])) {
      run = -1;
      continue;
    }
    run = run < 0 ? 0 : run + (mmOf(g, route[i]) - mmOf(g, route[i - 1])).norm();
    longest = std::max(longest, run);
  }
  return longest;
}

// What a neck route's stretch without lumen is measured against: the path support test's least such stretch
// (path_support.h), and the node cost's lumen level.
double supportStretchMm(const Geometry& g) {
  const PathSupportOptions support;
  return std::max(support.minLengthMm, support.minSpacings * g.spacing.maxCoeff());
}
double lumenLevelOf(const NodeCost3D& cost, const CrossingOptions& o) {
  return std::isnan(o.lumenLevel) ? lumenCostThreshold(cost) : o.lumenLevel;
}
bool costAbove(const NodeCost3D& cost, double level, const Index3& v) {
  return double(cost.node[size_t(cost.geometry.linear(v[0], v[1], v[2]))]) > level;
}

// The longest run of a route's voxels that lie in no lumen, from its first voxel's centre to its last (mm along the
// route): the node cost above the lumen level and the smoothed value not more than dipShare of the way from its local
// background to the old part's level (inLumenByIntensity's line) - the path support test's stretch without lumen
// (path_support.h).
double longestOffLumenMm(const NodeCost3D& cost, const CrossingOptions& o, double sign, double level,
                         const std::vector<Index3>& old, const std::vector<Index3>& route) {
  const Geometry& g = cost.geometry;
  const double radius = o.dipShellVoxels * o.smoothed->geometry().spacing.minCoeff();
  std::vector<double> lv;
  lv.reserve(old.size());
  for (const Index3& v : old) lv.push_back(signedAt(*o.smoothed, v, sign));
  const double lumen = medianInPlace(lv);
  return longestRunMm(g, route, [&](const Index3& v) {
    if (!costAbove(cost, level, v)) return false;
    const double bg = shellMedian(*o.smoothed, v, radius, sign);
    return !(signedAt(*o.smoothed, v, sign) > bg + o.dipShare * (lumen - bg));
  });
}

// What the re-search blocks: the band across the neck (the pair test's), the tighter band (the
// followed lobes'), the tube the path runs in before the crossing, from the neck through the path
// and beyond it, with the search from the path's start (the third try, below), or the same for the
// tube a detour takes, between its two changes (followedDetour).
enum class Band { Full, Tight, OwnTube, Detour };

// The neck re-search for one crossing found.
NeckRetrace searchAcrossNeck(const NodeCost3D& cost, const std::vector<Index3>& full, int connectivity,
                             const CrossingOptions& o, const std::vector<Section>& secsIn, const NeckCrossing& nc,
                             Band band) {
  NeckRetrace r;
  const bool tight = band == Band::Tight, ownTube = band == Band::OwnTube, detour = band == Band::Detour;
  const bool tube = ownTube || detour;  // a tube blocked, not a band between the tubes
  // The tighter band's neck: where two discs of the lobes' areas round their centroids touch. The
  // lowest sample between the peaks wanders across a shallow valley (touching tubes, noise), and
  // a band that thin must not (517: slabs on the other tube's axis).
  std::vector<Section> secs = secsIn;
  if (tight)
    for (Section& q : secs)
      if (q.two)
        q.ownPeak = q.own, q.otherPeak = q.other, q.neck = q.own + q.rOwn / (q.rOwn + q.rOther) * (q.other - q.own);
  r.crossings = 1;
  const Geometry& g = cost.geometry;
  const int k = std::max(1, o.neckLobeSteps);
  // From before the stretch (before the fork the other tube left from) to some points past the
  // crossing; the box holds the whole stretch (the ends move off the blocked neck below). With the
  // tube left blocked, from the path's start: the only place known to lie before the fork of the
  // tube to take (10507: the path to B runs in A from the fork, 15 points before the stretch).
  size_t lo = ownTube ? 0 : nc.first > size_t(2 * k) ? nc.first - size_t(2 * k) : 0;
  size_t hi = std::min(full.size() - 1, (detour ? nc.back : nc.at) + size_t(2 * k));
  const size_t boxHi = std::min(full.size() - 1, std::max(hi, nc.last) + size_t(2 * k));
  const Box b = retrace::boxAround(g, full, lo, boxHi);
  if (b.size() > (int64_t(1) << 23)) {
    r.why = "box too large";
    return r;
  }
  // The neck in every two-lobe section of the stretch (slabOf). Sections in the stretch's bridged
  // gaps (the path in the neck shows one lobe - exactly where it crosses) take the last two-lobe
  // section's neck, moved along its tangent to the path's point (the tighter band: interpolated).
  std::vector<uint8_t> blocked(static_cast<size_t>(b.size()), 0);
  size_t lastTwo = nc.first;
  for (size_t j = nc.first; j <= nc.last; ++j) {
    Slab sl;
    if (secs[j].two) {
      sl = slabOf(g, full, j, secs[j], k, tight);
      if (sl.ok || !tight) lastTwo = j;
      if (!sl.ok && !tight) continue;  // no sideways line between the peaks
    }
    if (!sl.ok) {
      Section s = movedAlong(g, full, secs[lastTwo], lastTwo, j, k);
      // The tighter band's gaps and the tube left's: between the usable sections either side (the
      // tubes bend sideways over a gap; 517's copies of the last section lay on the other tube's
      // axis; 541's, blocking the tube left, covered B where it comes down a slice in the gap).
      size_t next = j + 1;
      while ((tight || tube) && next <= nc.last && !(secs[next].two && slabOf(g, full, next, secs[next], k, tight).ok))
        ++next;
      if ((tight || tube) && next <= nc.last && lastTwo < j) {
        Section b2 = movedAlong(g, full, secs[next], next, j, k);
        if (changesLobe(secs, lastTwo, lastTwo, next, size_t(k)) == LobeStep::Changes)
          std::swap(b2.ownPeak, b2.otherPeak);  // the crossing itself
        const double w = double(j - lastTwo) / double(next - lastTwo);
        s.neck = (1 - w) * s.neck + w * b2.neck;
        s.ownPeak = (1 - w) * s.ownPeak + w * b2.ownPeak;
        s.otherPeak = (1 - w) * s.otherPeak + w * b2.otherPeak;
      }
      sl = slabOf(g, full, j, s, k, tight);
      if (!sl.ok) continue;
    }
    if (tube) {
      // The tube left, before the crossing: from the neck through the path's voxel and two largest
      // spacings beyond it. Where the tubes' axes lie in neighbouring thick slices no band between
      // them is both closed to 26-steps and clear of the tube to take (10507, 541); the tube left
      // is, and the route must reach the other tube round the band's start, by its own fork. A
      // detour's: the tube taken between its changes, the route kept in the own one.
      if (ownTube ? j >= nc.at : j < nc.at || j >= nc.back) continue;
      const double ext = std::abs((mmOf(g, full[j]) - sl.mid).dot(sl.n)) + 2 * g.spacing.maxCoeff();
      sl.mid -= 0.5 * ext * sl.n;
      sl.half = 0.5 * ext;
    }
    // The full band lays no slab on the stretch's first k points where the other tube came into the section there
    // (a fork's crotch, as pairCrossing's 3k; 6707: a slab on the fork tied two routes one voxel apart).
    if (band != Band::Full || nc.first == 0 || j >= nc.first + size_t(k)) blockSlab(g, b, sl, blocked);
  }
  // The search's ends off the neck: an end left inside the band and unblocked would be a hole in it
  // (the route would come along the tube left and step into the end from beside it).
  while (lo > 0 && blocked[static_cast<size_t>(b.index(full[lo]))]) --lo;
  while (hi < boxHi && blocked[static_cast<size_t>(b.index(full[hi]))]) ++hi;
  if (blocked[static_cast<size_t>(b.index(full[lo]))] || blocked[static_cast<size_t>(b.index(full[hi]))]) {
    r.why = "the path's ends lie in the neck";
    return r;
  }
  const std::vector<Index3> part = retrace::stretch(full, lo, hi);
  const double oldPart = chainCost(cost, part);
  r.oldCost = chainCost(cost, full);
  double c = 0;
  // A detour's route is held to the own tube's cost per mm (below), not the old part's: the tube
  // taken may be far cheaper (11307: B, 2.4 mm in radius across 2.2 mm slices, 0.001 per mm; A,
  // 1.5 mm, 0.06 after the detour; A's route costs 2x the old part, 0.018 per mm).
  const double limit = detour ? std::numeric_limits<double>::max() : (1 + o.neckCostSlack) * oldPart;
  std::vector<Index3> next = boxPath(cost, b, blocked, stepsFor(g, connectivity), part.front(), part.back(), limit, &c);
  if (next.empty() && !detour && o.neckByIntensity)
    next = lumenRoute(cost, o, b, blocked, connectivity, part, &c, &r.why);
  if (next.empty()) {
    if (r.why.empty()) r.why = "no route within the cost slack with the neck blocked";
    return r;
  }
  if (detour) {
    const std::vector<Index3> before = retrace::stretch(full, lo, nc.at), after = retrace::stretch(full, nc.back, hi);
    const double ownPerMm =
        (chainCost(cost, before) + chainCost(cost, after)) / (lengthMm(g, before) + lengthMm(g, after));
    if (c / lengthMm(g, next) > (1 + o.neckCostSlack) * ownPerMm) {
      r.why = "the route in the own tube costs more per mm than the own tube's stretches either side";
      return r;
    }
  }
  if (next == part) {
    r.why = "the same route";
    return r;
  }
  // The followed test's route must take a tube of its own: somewhere two largest spacings from the
  // old part (the other tube's bend away before the contact). A thin tree's fork passed with the
  // band leaves a route shifted by a voxel at the same cost (550, 523: nothing to correct).
  if (band != Band::Full) {
    if (retrace::farthestFrom(g, next, part) < 2 * g.spacing.maxCoeff()) {
      r.why = "the new route stays beside the old one";
      return r;
    }
  }
  if (band == Band::Tight && leaksAlongOld(g, full, nc, k, next)) {
    r.why = "the new route runs on along the old one before the crossing (through a hole in the band)";
    return r;
  }
  const double sign = o.brightLumen ? 1.0 : -1.0;
  // A neck re-search moves a path from one touching tube into the other: both routes run in lumens. A route that
  // crosses the background further than the old part does and at least as far as the support test reports is no
  // route in a tube (11723: the own tube left blocked, the route to a branch end that curls back ran in the sibling
  // and hopped 9 mm through the background, within the cost slack).
  const double level = lumenLevelOf(cost, o);
  const double hop = longestOffLumenMm(cost, o, sign, level, part, next);
  if (hop >= supportStretchMm(g) && hop > longestOffLumenMm(cost, o, sign, level, part, part)) {
    r.why = "the new route crosses the background (" + std::to_string(hop) + " mm)";
    return r;
  }
  std::vector<Index3> p = retrace::spliced(full, lo, hi, next);
  const std::vector<Section> secsNew = sectionsOf(*o.smoothed, sign, p, o.neckSections);
  NeckCrossing again = findNeckCrossing(secsNew, k, o.neckBridge, band != Band::Full);
  if (!again.found && detour) again = findNeckCrossing(secsNew, k, 2 * o.neckBridge, true, size_t(k), true);
  if (again.found) {
    r.why = "the new route crosses too (point " + std::to_string(again.at) + " of " + std::to_string(p.size()) +
            "; searched " + std::to_string(lo) + "-" + std::to_string(hi) + ")";
    return r;
  }
  return retrace::accepted(std::move(r), oldPart, c, std::move(p));
}

}  // namespace

// The route refused by the cost slack, held to the lumen by intensity instead (session 31): among
// the voxels at or above the widest route's bottleneck with the neck blocked, kept when no point
// of it lies outside the lumen by intensity (inLumenByIntensity) and it is not much longer than
// the old part. A tube half-way between two thick slices under a bias field reads as background in the node cost
// (11407: B's contact stretch, node cost 1.0) but stays above its surroundings in intensity.
std::vector<Index3> lumenRoute(const NodeCost3D& cost, const CrossingOptions& o, const Box& b,
                               std::vector<uint8_t> blocked, int connectivity, const std::vector<Index3>& part,
                               double* c, std::string* why) {
  const double sign = o.brightLumen ? 1.0 : -1.0;
  const Geometry& g = cost.geometry;
  const std::vector<retrace::Step> steps = stepsFor(g, connectivity);
  const double widest = bottleneck(*o.smoothed, sign, b, steps, part.front(), part.back(), blocked);
  for (int64_t i = 0; i < b.size(); ++i)
    if (signedAt(*o.smoothed, b.voxel(i), sign) < widest) blocked[static_cast<size_t>(i)] = 1;
  std::vector<Index3> next =
      boxPath(cost, b, blocked, steps, part.front(), part.back(), std::numeric_limits<double>::infinity(), c);
  if (next.empty() || !inLumenByIntensity(o, sign, part, next) ||
      retrace::chainLength(g, next) > (1 + o.lengthSlack) * retrace::chainLength(g, part)) {
    *why = "no route within the cost slack with the neck blocked, none in the lumen by intensity";
    return {};
  }
  if (o.neckByIntensityInHole) {
    const double level = lumenLevelOf(cost, o);
    if (longestRunMm(g, next, [&](const Index3& v) { return costAbove(cost, level, v); }) < supportStretchMm(g)) {
      *why =
          "no route within the cost slack with the neck blocked; the one in the lumen by intensity has no stretch the "
          "cost reads as no lumen";
      return {};
    }
  }
  return next;
}

std::vector<LobeWidths> lobeWidthsAlong(const std::vector<Index3>& path, const CrossingOptions& o) {
  if (!o.enabled || !o.smoothed || path.size() < 8) return {};
  const std::vector<Section> runs =
      longRunsOnly(sectionsOf(*o.smoothed, o.brightLumen ? 1.0 : -1.0, path, o.neckSections),
                   size_t(std::max(1, o.neckLobeSteps)), size_t(o.neckBridge));
  std::vector<LobeWidths> w(runs.size());
  for (size_t i = 0; i < runs.size(); ++i)
    w[i] = {runs[i].two, runs[i].rOwn, runs[i].rOther, runs[i].own, runs[i].other, runs[i].t};
  return w;
}

NeckRetrace retraceAcrossNeck(const NodeCost3D& cost, const std::vector<Index3>& full, int connectivity,
                              const CrossingOptions& o) {
  if (!o.enabled || !o.smoothed || full.size() < 8 || o.smoothed->geometry().dims != cost.geometry.dims) return {};
  const std::vector<Section> secs = sectionsOf(*o.smoothed, o.brightLumen ? 1.0 : -1.0, full, o.neckSections);
  const int k = std::max(1, o.neckLobeSteps);
  // First the pair test and the full band (session 20); where that finds no crossing or no route,
  // the lobes followed through the stretch and the tighter band (session 21).
  NeckRetrace r;
  const NeckCrossing pair = findNeckCrossing(secs, k, o.neckBridge, false);
  if (pair.found) r = searchAcrossNeck(cost, full, connectivity, o, secs, pair, Band::Full);
  if (r.changed) return r;
  const NeckCrossing followed = findNeckCrossing(secs, k, o.neckBridge, true);
  if (followed.found) {
    NeckRetrace second = searchAcrossNeck(cost, full, connectivity, o, secs, followed, Band::Tight);
    if (second.changed) return second;
    r.why = pair.found ? r.why + "; followed: " + second.why : second.why;
  }
  // Third (session 22): both refused or no crossing found - the tube left blocked before the
  // crossing, searched from the path's start (Band::OwnTube). Its crossing: the followed test's,
  // else the followed test across gaps of twice the bridge, the lobes' likeness taken from up to k
  // two-lobe sections off the change (10507: the section before the change is the path's voxel in
  // the neck; 541: the path crosses in a 10-point one-lobe gap). Not the pair test's: on A's own
  // path it takes a touch for a crossing (517, 521, 522), and with A blocked the route took B.
  NeckCrossing at = followed.found
                        ? findNeckCrossing(secs, k, o.neckBridge, true, 0, false, kNeckLikeRatio, true)
                        : findNeckCrossing(secs, k, 2 * o.neckBridge, true, size_t(k), false, kNeckLikeRatio, true);
  // Last (session 28): a contact fused over any length - the tubes in neighbouring thick slices,
  // no neck in any section of it (11108: gap 0.08 of a 2.2 mm slice; the path to the thinner tube
  // ran 43 points along the wider one's axis, one lobe, and its lobe had changed between the runs
  // of two-lobe sections before and after). The lobes followed from run to run, each run of 2k
  // two-lobe sections or more; what lies between is the fused stretch the band is carried over.
  const std::vector<Section> runs = at.found ? secs : longRunsOnly(secs, size_t(k), size_t(o.neckBridge));
  if (!at.found)
    at = findNeckCrossing(runs, k, static_cast<int>(full.size()), true, size_t(k), false, kNeckLikeRatio, true);
  if (at.found) {
    NeckRetrace third = searchAcrossNeck(cost, full, connectivity, o, runs, at, Band::OwnTube);
    if (third.changed) return third;
    r.why = r.why + "; own tube: " + third.why;
  }
  // Then (session 31) the same across lobes up to neckUnlikeRatio apart in radius: a thin tube
  // kissing a wider one across thick slices shows a lobe a third of the other's (10207: B 0.5-1.0 mm
  // beside A's 2.3-2.9 mm). The node cost reads such a tube as dimmer than the wider one all along
  // (partial volume), so the slack against a route in the wider one is no guard there (10207: the
  // truth's centreline 1.31x the path's); its route is held to the lumen by intensity instead.
  if (!at.found && o.neckUnlikeRatio > kNeckLikeRatio) {
    const NeckCrossing unlike =
        findNeckCrossing(secs, k, 2 * o.neckBridge, true, size_t(k), false, o.neckUnlikeRatio, true);
    if (unlike.found) {
      CrossingOptions byIntensity = o;
      byIntensity.neckByIntensity = true;
      NeckRetrace u = searchAcrossNeck(cost, full, connectivity, byIntensity, secs, unlike, Band::OwnTube);
      if (u.changed) return u;
      r.why = r.why + "; unlike tubes: " + u.why;
    }
  }
  // Last (session 30): a detour into the other tube and back (followedDetour; an even count of
  // changes, which every test above reads as none), the tube taken in between blocked. Across the
  // third try's gaps and likeness.
  const NeckCrossing detour = findNeckCrossing(secs, k, 2 * o.neckBridge, true, size_t(k), true);
  if (!detour.found) return r;
  NeckRetrace d = searchAcrossNeck(cost, full, connectivity, o, secs, detour, Band::Detour);
  if (!d.changed) d.why = r.why + "; detour: " + d.why;
  return d;
}

}  // namespace vs
