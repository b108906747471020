#include "tracking/contact_retrace.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "tracking/box_search.h"
#include "tracking/contact_walk.h"

namespace vs {

using retrace::Box;
using retrace::mmOf;
using walk::centredSection;
using walk::keepToLumen;
using walk::Lumen;
using walk::normals;
using walk::Section;
using walk::takeCentre;
using walk::toLine;
using walk::toPolyline;

namespace {

// A tube's arm out of the contact from x along dir: straight across the other tube (`skip`), then
// followed `go` further, each step re-centred on its own section; it goes on while every section is
// lumen with the tube's own radius (within a factor of 2) and turns less than 60 degrees from dir.
// At a fork the branch entered ends at the trunk's far wall; at a bend the tube left ends at the
// entered one's. `start`: the first centred section past the contact, a point of the axis.
bool armGoesOn(const Lumen& lu, const Vec3& x, const Vec3& dir, double skip, double go, double rOwn, double dt,
               double cap, Vec3* start) {
  Vec3 q = x + skip * dir, d = dir;
  Section s = centredSection(lu, q, d, dt, cap);
  if (!s.lumen) {  // the line a little off the lumen: the 8 points within half a radius round it
    Vec3 u, w;
    normals(dir, u, w);
    for (int k = 0; k < 8 && !s.lumen; ++k) {
      const double a = k * M_PI / 4;
      s = centredSection(lu, q + 0.5 * rOwn * (std::cos(a) * u + std::sin(a) * w), d, dt, cap);
    }
  }
  if (!s.lumen) return false;
  *start = s.centre;
  const double step = std::max(dt, 0.5 * rOwn);
  q = s.centre;  // the line's own drift off the axis is no departure: the walk starts on the axis
  for (double gone = 0;; gone += step) {
    const Vec3 off = s.centre - q;
    if (s.radius < 0.5 * rOwn || s.radius > 2 * rOwn || (off - off.dot(d) * d).norm() > rOwn || d.dot(dir) < 0.5)
      return false;
    if (gone >= go) return true;
    const Vec3 prev = s.centre;
    q = prev + step * d;
    s = centredSection(lu, q, d, dt, cap);
    if (!s.lumen) return false;
    if ((s.centre - prev).norm() > 0.25 * step) d = (d + (s.centre - prev).normalized()).normalized();
  }
}

// The scan for sharp turns along a path (both contact re-searches): the span and direction steps (at least one each),
// the sections' step (half the finest spacing) and reach (6 coarsest spacings), the least turn's cosine.
struct TurnScan {
  size_t h, k;
  double vmin, vmax, dt, cap, cosTurn;
  TurnScan(const Geometry& g, const CrossingOptions& o)
      : h(static_cast<size_t>(std::max(1, o.spanSteps))),
        k(static_cast<size_t>(std::max(1, o.directionSteps))),
        vmin(g.spacing.minCoeff()),
        vmax(g.spacing.maxCoeff()),
        dt(0.5 * vmin),
        cap(6 * vmax),
        cosTurn(std::cos(o.contactTurnDeg * M_PI / 180.0)) {}
  bool fits(size_t pathSize) const { return pathSize >= 2 * (h + k) + 1; }
};

// A sharp turn of the path at point i (issue 21, both contact re-searches): the stretch left (directions over k steps,
// h steps back) and the stretch entered (h steps on) meet at contactTurnDeg or more, all four ends in the lumen, each
// stretch's outer section centred on a lumen (off the contact), the two at an angle (sin >= 0.5: a turn back along
// itself crosses at no angle); xL / xE: each tube's line at the two lines' closest approach (the contact).
struct Turn {
  Vec3 tb, ta, xL, xE;
  Section left, entered;
  double cosA = 1, sinA = 0;
};
bool sharpTurnAt(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t i, const TurnScan& ts,
                 Turn* t) {
  const size_t h = ts.h, k = ts.k;
  const double dt = ts.dt, cap = ts.cap;
  const Vec3 a0 = mmOf(g, path[i - h - k]), a1 = mmOf(g, path[i - h]), b0 = mmOf(g, path[i + h]),
             b1 = mmOf(g, path[i + h + k]);
  if ((a1 - a0).norm() <= 0 || (b1 - b0).norm() <= 0) return false;
  t->tb = (a1 - a0).normalized(), t->ta = (b1 - b0).normalized();
  if (t->tb.dot(t->ta) > ts.cosTurn) return false;
  if (!lu.at(a0) || !lu.at(a1) || !lu.at(b0) || !lu.at(b1)) return false;
  t->left = centredSection(lu, a0, t->tb, dt, cap), t->entered = centredSection(lu, b1, t->ta, dt, cap);
  if (!t->left.lumen || !t->entered.lumen) return false;
  t->cosA = t->tb.dot(t->ta), t->sinA = std::sqrt(1 - t->cosA * t->cosA);
  if (t->sinA < 0.5) return false;
  const Vec3 w0 = t->left.centre - t->entered.centre;
  const double s2 = t->sinA * t->sinA;
  t->xL = t->left.centre + (t->cosA * t->ta.dot(w0) - t->tb.dot(w0)) / s2 * t->tb;
  t->xE = t->entered.centre + (t->ta.dot(w0) - t->cosA * t->tb.dot(w0)) / s2 * t->ta;
  return true;
}

// The tube entered followed back from the contact, away from it (`skip` straight across the fused
// contact first), section by section re-centred on its own lumen and turning as it bends; sections
// that are no lumen of its own radius (a fused crossing, the crotch of a fork) are stepped over
// straight, up to `maxBad` mm at a time. It ends where its line comes back into the path's own
// lumen (within the path's radius of a path point) well before the turn: that point's index in
// *meet, the sections' centres in *centres. False where it leaves the lumen, runs longer than
// maxWalk, or meets the path only near the contact.
bool walksBackToPath(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t turn, const Vec3& x,
                     const Vec3& dir, double skip, double rOwn, double rPath, double away, size_t minBack,
                     double maxBad, double maxWalk, double dt, double cap, size_t* meet, std::vector<Vec3>* centres) {
  // The path's arc length from each point before the turn to the turn.
  std::vector<double> arc(turn + 1, 0.0);
  for (size_t j = turn; j-- > 0;) arc[j] = arc[j + 1] + (mmOf(g, path[j + 1]) - mmOf(g, path[j])).norm();
  const double step = std::max(dt, 0.5 * rOwn);
  Vec3 q = x + skip * dir, d = dir;
  double walked = skip, bad = 0;
  bool left = false;
  while (walked <= maxWalk) {
    const Section s = centredSection(lu, q, d, dt, cap);
    const Vec3 off = s.centre - q;
    const bool own = s.lumen && s.radius >= 0.5 * rOwn && s.radius <= 2 * rOwn && (off - off.dot(d) * d).norm() <= rOwn;
    Vec3 next = q + step * d;
    if (own) {
      bad = 0;
      next = takeCentre(s, step, d, centres);
    } else if (s.lumen && (bad += step) <= maxBad) {
      next = keepToLumen(q, off - off.dot(d) * d, step, d);
    } else if (!s.lumen && (bad += step) <= maxBad) {
    } else {
      return false;
    }
    // Back in the path's own lumen before the turn, having first left it (not at the contact it
    // came from): farther than `away` from every path point up to the turn.
    double nearest = std::numeric_limits<double>::infinity();
    size_t at = 0;
    for (size_t j = 0; j <= turn; ++j) {
      const double dj = (mmOf(g, path[j]) - q).norm();
      if (dj < nearest) nearest = dj, at = j;
    }
    if (nearest > away) left = true;
    if (left && nearest <= rPath && at + minBack <= turn) {
      if (walked < arc[at] || centres->empty()) return false;  // no loop: shorter than the path's own route
      *meet = at;
      return true;
    }
    q = next;
    walked += step;
  }
  return false;
}

// The tube entered followed back round a tight bend to its fork (issue 21, session 37; cross34's walk skips straight
// across the contact and leaves the lumen at a U as tight as the tube): started on its own centred section `start`
// past the turn, section by section re-centred on its own lumen as walksBackToPath, a step leaving the lumen turned
// round the bend (bendStep, steered fully onto its centre). A section centred within the tube left's lumen (within
// rOther of its axis `other`) or nearer that axis than the walk's own line is the tube left (fork35's side test) - not
// taken, stepped over straight, up to maxBad mm at a time. The loop: into the tube left at the contact, out of it on
// own centres, into it again (the fork) within rPath + rOwn of a path point before the turn - that point in *meet.
// False where it leaves the lumen, runs past maxWalk or never closes the loop. `held` (session 39, turn232: 12232's
// child b5, whose return touches the tube left where the thick slices' off-centre sections turned its direction into
// it): a missed section does not turn the walk (its direction held, the step straight on); a bend inside the contact
// ends it only where the turned centre lies in the tube left's lumen; and the loop closes only where the walk enters
// the tube left's lumen within rPath + rOwn of a path point before the turn that lies farther than the contact's reach
// (rOther + rOwn) from the turn, whether or not it touched the tube left at the contact (one closing within that reach
// closes at the contact itself); that point of entry is the walk's last centre (the child's opening at its fork).
bool walksRoundBend(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t turn, const Vec3& start,
                    const Vec3& dir, double rOwn, double rPath, const std::vector<Vec3>& other, double rOther,
                    double maxBad, double maxWalk, double dt, double cap, size_t* meet, std::vector<Vec3>* centres,
                    bool held = false) {
  const double step = std::max(dt, 0.5 * rOwn);
  Vec3 q = start, d = dir;
  double walked = 0, bad = 0;
  int phase = 0;  // 0: before the contact, 1: at the contact (in the tube left), 2: out of it on own centres
  size_t at = 0;
  while (walked <= maxWalk) {
    const Section s = centredSection(lu, q, d, dt, cap);
    const double dOther = toPolyline(s.centre, other, &at);
    const bool inLeft = !centres->empty() && (dOther < rOther || dOther < toLine(s.centre, centres->back(), d));
    Vec3 next = q + step * d;
    const Vec3 dWas = d;
    const walk::WalkStep taken = walk::stepOn(lu, s, q, inLeft, step, rOwn, dt, cap, maxBad, bad, d, centres, &next);
    if (taken == walk::WalkStep::Lost) return false;
    if (held && taken == walk::WalkStep::Missed) d = dWas, next = q + step * d;
    const bool inLeftLumen = inLeft && dOther < rOther;
    if (held && inLeftLumen) {
      double nearest = std::numeric_limits<double>::infinity();
      size_t j0 = 0;
      for (size_t j = 0; j < turn; ++j) {
        const double dj = (mmOf(g, path[j]) - q).norm();
        if (dj < nearest) nearest = dj, j0 = j;
      }
      if (nearest <= rPath + rOwn && (mmOf(g, path[j0]) - mmOf(g, path[turn])).norm() > rOther + rOwn) {
        *meet = j0;
        centres->push_back(q);  // the walk's line into the tube left: the child's opening at its fork
        return true;
      }
    }
    // Turned within the contact: the tube left's own bend or fork, no crossing (a held walk: only where the turned
    // centre lies in the tube left's lumen).
    if (taken == walk::WalkStep::Bend && phase == 1 && (!held || toPolyline(centres->back(), other, &at) < rOther))
      return false;
    const bool own = taken == walk::WalkStep::Own;
    if (phase == 0 && inLeftLumen) {
      phase = 1;
    } else if (phase == 1 && own) {
      phase = 2;
    } else if (phase == 2 && inLeftLumen && !held) {
      double nearest = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < turn; ++j) {
        const double dj = (mmOf(g, path[j]) - q).norm();
        if (dj < nearest) nearest = dj, *meet = j;
      }
      return nearest <= rPath + rOwn;
    }
    q = next;
    walked += step;
  }
  return false;
}

// A re-searched route is a tube of its own: lumen all along (holes of up to holeMm bridged) and through the walked
// tube's centre farthest from the old stretch `part` (one of the first `count` centres), which lies farther than
// minFar from it; the route passes within `reach` of that centre.
bool ownTube(const NodeCost3D& cost, double lumenLevel, const std::vector<Index3>& next,
             const std::vector<Index3>& part, const std::vector<Vec3>& centres, size_t count, double holeMm,
             double minFar, double reach) {
  const Geometry& g = cost.geometry;
  double hole = 0, longest = 0;
  for (size_t t = 1; t < next.size(); ++t) {
    const bool in = cost.node[static_cast<size_t>(g.linear(next[t][0], next[t][1], next[t][2]))] <= lumenLevel;
    hole = in ? 0 : hole + (mmOf(g, next[t]) - mmOf(g, next[t - 1])).norm();
    longest = std::max(longest, hole);
  }
  double far = 0;
  Vec3 farC = centres.front();
  for (size_t t = 0; t < count && t < centres.size(); ++t) {
    double d = std::numeric_limits<double>::infinity();
    for (const Index3& v : part) d = std::min(d, (mmOf(g, v) - centres[t]).norm());
    if (d > far) far = d, farC = centres[t];
  }
  double through = std::numeric_limits<double>::infinity();
  for (const Index3& v : next) through = std::min(through, (mmOf(g, v) - farC).norm());
  return longest <= holeMm && far > minFar && through <= reach;
}

// The tube entered followed back along itself from its own centred section `start` past the turn (a child lying
// antiparallel beside the tube left, entered through their contact: issue 21, session 36, 11930 - cross34's walk,
// started on the entered line across the contact, lands in the tube left); also the tube left followed on past the
// turn beside it. Section by section re-centred on its own lumen and turning as it bends, as walksBackToPath; a centre
// nearer the other tube's line (through cO along tO) than the walked tube's own line (the last centre along the walk)
// is the walk drifting across the contact and is not taken (fork35's "path's side" test); such sections, and those of
// no own radius, are stepped over straight, up to maxBad mm at a time. It ends where it reaches a lumen of no own
// radius for longer than that (the fork into a wider lumen: true), or leaves the lumen or runs past maxWalk (false).
// The own centres in *centres. With `avoid` (session 39, turn232: another tube's walked centres, the child walked
// first) the walk steps through stepOn - out of the lumen the least turn round its own bend (bendStep) - and a section
// or turned section centred within rAvoid of those centres is that tube's, not taken and not turned into: at a contact
// or a fork the least turn is the other tube, not the tube left's own bend (bend232), and the walk back stops at the
// fork instead of running on into the child's first arm.
bool walksBesideToFork(const Lumen& lu, const Vec3& start, const Vec3& dir, const Vec3& cO, const Vec3& tO, double rOwn,
                       double maxBad, double maxWalk, double dt, double cap, std::vector<Vec3>* centres,
                       const std::vector<Vec3>* avoid = nullptr, double rAvoid = 0) {
  const double step = std::max(dt, 0.5 * rOwn);
  Vec3 q = start, d = dir;
  double walked = 0, bad = 0;
  size_t at = 0;
  while (walked <= maxWalk) {
    const Section s = centredSection(lu, q, d, dt, cap);
    const Vec3 off = s.centre - q, side = off - off.dot(d) * d;
    const bool leftSide = !centres->empty() && toLine(s.centre, cO, tO) < toLine(s.centre, centres->back(), d);
    Vec3 next = q + step * d;
    if (avoid) {
      // The walk with the bend step (session 39, turn232): a section centred in the avoided tube is that tube's.
      const bool other = leftSide || (!avoid->empty() && toPolyline(s.centre, *avoid, &at) <= rAvoid);
      const walk::WalkStep taken =
          walk::stepOn(lu, s, q, other, step, rOwn, dt, cap, maxBad, bad, d, centres, &next, avoid, rAvoid);
      if (taken == walk::WalkStep::Lost) return s.lumen && !centres->empty();
      if (taken == walk::WalkStep::Missed && side.norm() <= 0.25 * step) next = q + step * d;
    } else {
      const bool own = s.lumen && !leftSide && s.radius >= 0.5 * rOwn && s.radius <= 2 * rOwn && side.norm() <= rOwn;
      if (own) {
        bad = 0;
        next = takeCentre(s, step, d, centres);
      } else if ((bad += step) > maxBad) {
        return s.lumen && !centres->empty();
      } else if (s.lumen && !leftSide && side.norm() > 0.25 * step) {
        next = keepToLumen(q, side, step, d);
      }
    }
    q = next;
    walked += step;
  }
  return false;
}

// The path's stretch lo..hi and the walked centres' voxels: what a re-search's box holds.
std::vector<Index3> aroundWalk(const Geometry& g, const std::vector<Index3>& path, size_t lo, size_t hi,
                               const std::vector<Vec3>& centres) {
  std::vector<Index3> around = retrace::stretch(path, lo, hi);
  for (const Vec3& c : centres) {
    Index3 v;
    for (size_t ax = 0; ax < 3; ++ax) v[ax] = static_cast<int64_t>(std::llround(c[ax] / g.spacing[ax]));
    if (g.contains(v)) around.push_back(v);
  }
  return around;
}

// Per voxel of the box, blocked: one on the entered side (side <= 0) next (26 neighbours) to one of the left side
// (side > 0), so that no step crosses from one side to the other there (NaN: neither side, open).
std::vector<uint8_t> blockedBetweenSides(const Box& bx, const std::vector<double>& side) {
  std::vector<uint8_t> blocked(static_cast<size_t>(bx.size()), 0);
  for (int64_t j = 0; j < bx.size(); ++j) {
    if (!(side[static_cast<size_t>(j)] <= 0)) continue;
    const Index3 v = bx.voxel(j);
    for (int dz = -1; dz <= 1 && !blocked[static_cast<size_t>(j)]; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Index3 q{v[0] + dx, v[1] + dy, v[2] + dz};
          if (bx.in(q) && side[static_cast<size_t>(bx.index(q))] > 0) blocked[static_cast<size_t>(j)] = 1;
        }
  }
  return blocked;
}

// A looped contact's re-search round its block (cross34's, the bend's, the contact strip's; `what` names it): the
// stretch lo..hi searched again in the box with `blocked` closed, kept where its ends are open, a route exists within
// the old cost per mm over the old length and twice `walkedMm`, it costs no more per mm than the old stretch (both run
// in the lumen: not by total cost or length), and it is a tube of its own (ownTube over the first `ownCount` centres,
// farther than `minFar` from the old stretch, `reach` round them); then spliced into the path (r accepted).
struct RoundBlock {
  const char* what;
  const char* endsWhy;  // the stretch's ends inside the block
  double walkedMm;
  const std::vector<Vec3>& centres;
  size_t ownCount;
  double minFar, reach;
};
bool routeRoundBlock(const NodeCost3D& cost, const std::vector<Index3>& path, size_t lo, size_t hi, const Box& bx,
                     const std::vector<uint8_t>& blocked, int connectivity, double lumenLevel, const CrossingOptions& o,
                     double vmin, const RoundBlock& rb, ContactRetrace* r) {
  const Geometry& g = cost.geometry;
  if (blocked[static_cast<size_t>(bx.index(path[lo]))] || blocked[static_cast<size_t>(bx.index(path[hi]))]) {
    r->why = rb.endsWhy;
    return false;
  }
  const std::vector<Index3> part = retrace::stretch(path, lo, hi);
  const double oldPart = chainCost(cost, part), oldLen = retrace::chainLength(g, part);
  double nc = 0;
  std::vector<Index3> next =
      retrace::boxPath(cost, bx, blocked, retrace::stepsFor(g, connectivity), part.front(), part.back(),
                       (1 + o.costSlack) * oldPart / oldLen * (oldLen + 2 * rb.walkedMm), &nc);
  if (next.empty()) {
    r->why = std::string("no route round ") + rb.what;
    return false;
  }
  if (nc / retrace::chainLength(g, next) > (1 + o.costSlack) * oldPart / oldLen) {
    r->why = std::string("the route round ") + rb.what + " costs more per mm";
    return false;
  }
  if (!ownTube(cost, lumenLevel, next, part, rb.centres, rb.ownCount, o.lumenHoleVoxels * vmin, rb.minFar, rb.reach)) {
    r->why = std::string("the route round ") + rb.what + " is no tube of its own";
    return false;
  }
  r->oldCost = chainCost(cost, path);
  *r = retrace::accepted(std::move(*r), oldPart, nc, retrace::spliced(path, lo, hi, next));
  return true;
}

// The tube left's walk on from its own section (walksBesideToFork, `onward`) leaves the path's stretch left before the
// turn (issue 21, session 37 bend37: 12003): one of its centres short of the turn (behind path[i] along the stretch's
// direction) lies farther than the tube left's radius from the path's points path[i - h - k] .. path[i], outside the
// lumen the path ran in - the walk took the other child at a fork right before the turn (or the tube left's own curl
// that the path cuts, 10923: there the walk on closes the loop and this is never asked).
bool leavesStretchLeft(const Geometry& g, const std::vector<Index3>& path, size_t i, const TurnScan& ts,
                       const Turn& turn, const std::vector<Vec3>& onward) {
  std::vector<Vec3> ran;
  for (size_t t = i - ts.h - ts.k; t <= i; ++t) ran.push_back(mmOf(g, path[t]));
  const Vec3 atTurn = mmOf(g, path[i]);
  size_t at = 0;
  for (const Vec3& c : onward)
    if ((c - atTurn).dot(turn.tb) < 0 && toPolyline(c, ran, &at) > turn.left.radius) return true;
  return false;
}

// The block round a walked child's bend (searchRoundBend's and searchLoopAhead's): the box round the path's stretch
// lo..hi and `walked`; each voxel within rL + a coarsest voxel of the path's points nearLo..nearHi, whose nearest walk
// centre is not the last (the fork, where the child opens into the tube left), given its side sideOf(p, dE, at) (dE
// its distance to the walk's centres, at the nearest one); the voxels between the sides blocked and the stretch routed
// round them (routeRoundBlock, named by `what` / `endsWhy`; the walk's own length and centres, rE round them).
template <class SideOf>
bool routeRoundWalk(const NodeCost3D& cost, const std::vector<Index3>& path, size_t lo, size_t hi, size_t nearLo,
                    size_t nearHi, const std::vector<Vec3>& walked, const std::vector<Vec3>& centres, double rL,
                    double rE, const TurnScan& ts, int connectivity, double lumenLevel, const CrossingOptions& o,
                    const char* what, const char* endsWhy, SideOf sideOf, ContactRetrace* r) {
  const Geometry& g = cost.geometry;
  const std::vector<Index3> around = aroundWalk(g, path, lo, hi, walked);
  const Box bx = retrace::boxAround(g, around, 0, around.size() - 1, o.marginSteps);
  if (bx.size() > (int64_t(1) << 23)) return false;
  std::vector<double> side(static_cast<size_t>(bx.size()), std::numeric_limits<double>::quiet_NaN());
  size_t at = 0;
  for (int64_t j = 0; j < bx.size(); ++j) {
    const Vec3 p = mmOf(g, bx.voxel(j));
    bool near = false;
    for (size_t t = nearLo; t <= nearHi && !near; ++t) near = (mmOf(g, path[t]) - p).norm() <= rL + ts.vmax;
    if (!near) continue;
    const double dE = toPolyline(p, centres, &at);
    if (at + 1 >= centres.size()) continue;
    side[static_cast<size_t>(j)] = sideOf(p, dE, at);
  }
  double walkedLen = 0;
  for (size_t t = 1; t < centres.size(); ++t) walkedLen += (centres[t] - centres[t - 1]).norm();
  return routeRoundBlock(cost, path, lo, hi, bx, blockedBetweenSides(bx, side), connectivity, lumenLevel, o, ts.vmin,
                         {what, endsWhy, walkedLen, centres, centres.size(), rE, rE + 0.5 * ts.vmax}, r);
}

// A turn of more than 90 degrees into a child whose tight bend (a U as tight as its radius) lies against the tube left
// right past their fork (issue 21, session 37: 10923's child 2): the child walked back round its bend to the
// fork (walksRoundBend), then the path's stretch from before the fork (path[lo]) to the turn's outer end in the child
// (path[hi]) searched again with the boundary between the walked child and the tube left blocked near the cut (within
// rL + a coarsest voxel of the path from the fork to the turn): each voxel's side, (dE - rE) - (dL - rL) to the walk's
// centres and the tube left's axis, and blocked the child's side's voxels next (26 neighbours) to one of the left side,
// so that no step crosses there (walk36's contact strip); open where the walk's nearest centre is its last (the fork,
// where the child opens into the tube left). The tube left's axis: walked from its own section back to the fork or the
// root and on past the turn (walksBesideToFork). Kept as cross34's route: by cost per mm, lumen all along, through the
// walk's farthest centre from the old stretch, which lies farther than the child's radius from it (a bend as tight as
// the tube leaves the cut by about its radius, not by the two radii of cross34's loop).
bool searchRoundBend(const NodeCost3D& cost, const std::vector<Index3>& path, size_t i, const Turn& turn,
                     const TurnScan& ts, int connectivity, double lumenLevel, const CrossingOptions& o,
                     ContactRetrace* r) {
  const Geometry& g = cost.geometry;
  const Lumen lu{cost, lumenLevel};
  const size_t h = ts.h, k = ts.k, hi = std::min(path.size() - 1, i + h + k);
  const double rL = turn.left.radius, rE = turn.entered.radius;
  const double before = retrace::chainLength(g, retrace::stretch(path, 0, i));
  std::vector<Vec3> leftAxis, onward;
  walksBesideToFork(lu, turn.left.centre, -turn.tb, turn.entered.centre, turn.ta, rL, rL + rE, before + 2 * (rL + rE),
                    ts.dt, ts.cap, &leftAxis);
  std::reverse(leftAxis.begin(), leftAxis.end());
  const size_t behind = leftAxis.size();
  walksBesideToFork(lu, turn.left.centre, turn.tb, turn.entered.centre, turn.ta, rL, rL + rE, before + 2 * (rL + rE),
                    ts.dt, ts.cap, &onward);
  leftAxis.insert(leftAxis.end(), onward.begin(), onward.end());
  if (leftAxis.size() < 2) return false;
  size_t meet = 0;
  std::vector<Vec3> centres;
  const double entered = retrace::chainLength(g, retrace::stretch(path, i, hi));
  const auto walk = [&](const std::vector<Vec3>& axis) {
    centres.clear();
    return walksRoundBend(lu, g, path, i, turn.entered.centre, -turn.ta, rE, rL, axis, rL, rL + rE,
                          entered + 2 * before + 2 * (rL + rE), ts.dt, ts.cap, &meet, &centres) &&
           meet > 0 && centres.size() >= 2;
  };
  const std::vector<Vec3> wholeAxis = leftAxis;
  // The walk on went into a sibling at the fork: the tube left's axis there is the path's own stretch left.
  const auto secondAxis = [&]() {
    if (!leavesStretchLeft(g, path, i, ts, turn, onward)) return false;
    leftAxis.resize(behind);
    for (size_t t = i - h - k + 1; t <= i - h; ++t) leftAxis.push_back(mmOf(g, path[t]));
    if (leftAxis.size() < 2 || !walk(leftAxis)) return false;
    // Two tubes, not one: no centre of the walk on within the child's radius of the walk round its bend (else the
    // tube left bends into the child itself and the path only cuts the inside of that bend - 10829, 10731, 11721).
    size_t at = 0;
    for (const Vec3& c : onward)
      if (toPolyline(c, centres, &at) <= rE) return false;
    // And a stretch of the tube left between the fork and the contact: the meet farther than the contact's reach
    // (rL + rE, cross34's "away") from the turn; a loop closing within it closes at the contact itself.
    return (mmOf(g, path[meet]) - mmOf(g, path[i])).norm() > rL + rE;
  };
  // Neither walk on own sections closes the loop: the child fused beside the tube left up to its fork (walk124).
  std::vector<Vec3> sibs;  // a fused walk's other disc per centre (NaN at its own sections' centres)
  // As the second axis's walk, its meet farther than the contact's reach from the turn (one closing within it closes
  // at the contact itself: 10403's walk split a bend's own sections and met the path 1.3 mm from the turn).
  const auto fusedWalk = [&]() {
    leftAxis = wholeAxis, centres.clear();
    return vs::walk::walksFusedRun(lu, g, path, i, turn.entered.centre, -turn.ta, rE, rL, leftAxis, rL, rL + rE,
                                   entered + 2 * before + 2 * (rL + rE), ts.dt, ts.cap, &meet, &centres, &sibs) &&
           meet > 0 && centres.size() >= 2 && (mmOf(g, path[meet]) - mmOf(g, path[i])).norm() > rL + rE;
  };
  // Where the first walk closes at the contact itself (its meet within the contact's reach rL + rE of the turn -
  // session 38 cut232: 12232's b5 drifted into b6 across the contact, b6's axis ending there), the child walked
  // with its direction held (walksRoundBend's `held`) on the whole axis, the tube left walked again back and on with
  // the bend step, never into that walk's centres (rE round them), and the child walked held again on that axis; kept
  // where it closes (session 39, turn232). Else the first walk's loop stands as before.
  bool heldRound = false;
  const auto walkRound = [&]() {
    std::vector<Vec3> first, back, on, round;
    size_t m0 = 0, m2 = 0;
    const double maxW = entered + 2 * before + 2 * (rL + rE);
    walksRoundBend(lu, g, path, i, turn.entered.centre, -turn.ta, rE, rL, wholeAxis, rL, rL + rE, maxW, ts.dt, ts.cap,
                   &m0, &first, true);
    if (first.size() < 2) return false;
    walksBesideToFork(lu, turn.left.centre, -turn.tb, turn.entered.centre, turn.ta, rL, rL + rE, before + 2 * (rL + rE),
                      ts.dt, ts.cap, &back, &first, rE);
    std::reverse(back.begin(), back.end());
    walksBesideToFork(lu, turn.left.centre, turn.tb, turn.entered.centre, turn.ta, rL, rL + rE, before + 2 * (rL + rE),
                      ts.dt, ts.cap, &on, &first, rE);
    back.insert(back.end(), on.begin(), on.end());
    if (back.size() < 2 ||
        !walksRoundBend(lu, g, path, i, turn.entered.centre, -turn.ta, rE, rL, back, rL, rL + rE, maxW, ts.dt, ts.cap,
                        &m2, &round, true) ||
        m2 == 0 || round.size() < 2)
      return false;
    leftAxis = back, centres = round, meet = m2, sibs.clear(), heldRound = true;
    return true;
  };
  bool found = walk(leftAxis);
  const bool atContact = found && (mmOf(g, path[meet]) - mmOf(g, path[i])).norm() <= rL + rE;
  if (!found) found = secondAxis() || fusedWalk();
  if (atContact && walkRound()) found = true;
  if (!found) return false;
  ++r->turns;
  const size_t lo = std::min(meet - 1, i - h - k);
  std::vector<Vec3> splitSibs;
  for (const Vec3& c : sibs)
    if (!std::isnan(c[0])) splitSibs.push_back(c);
  // Beside a fused walk's split centre the two tubes are that section's two discs: the side is the midline between
  // the walk's centres and the other discs (kiss39's midline; the tube left's walked axis runs in the fused union
  // there, not in its own tube). A fused walk's strip lies on the tube left's side (its voxels next to the child's):
  // the child's own lumen beside the fused tube left is a voxel or two across, and a strip on its side seals it; so
  // does a held walk's (its child touches the tube left over the contact's length: 12232's b5 is one slice thick
  // there).
  const auto sideOf = [&](const Vec3& p, double dE, size_t at) {
    const double s = at < sibs.size() && !std::isnan(sibs[at][0]) ? dE - toPolyline(p, splitSibs, &at)
                                                                  : (dE - rE) - (toPolyline(p, leftAxis, &at) - rL);
    return sibs.empty() && !heldRound ? s : -s;
  };
  return routeRoundWalk(cost, path, lo, hi, meet, i, centres, centres, rL, rE, ts, connectivity, lumenLevel, o,
                        "the bend's block", "the turn's ends inside the bend's block", sideOf, r);
}

// A turn of more than 90 degrees into a child lying antiparallel beside the tube left (walksBesideToFork): the path's
// stretch from its turn's outer end in the tube left (path[lo]) to its outer end in the tube entered (path[hi])
// searched again with the contact strip between the two tubes blocked, the walked tube and its fork inside the box.
// The tube left is walked on past the turn as well (its own axis there: the path hugs its wall). The strip lies only
// beside the walk's centres that touch the tube left (centre distance within the two radii and a coarsest voxel), and
// only there over more than the two radii together (an antiparallel child, not a bend). Kept as cross34's route: by
// cost per mm, lumen all along, through the walk's farthest centre from the old stretch.
bool searchBeside(const NodeCost3D& cost, const std::vector<Index3>& path, size_t i, const Turn& turn,
                  const TurnScan& ts, int connectivity, double lumenLevel, const CrossingOptions& o,
                  ContactRetrace* r) {
  const Geometry& g = cost.geometry;
  const Lumen lu{cost, lumenLevel};
  const size_t h = ts.h, k = ts.k;
  const double vmin = ts.vmin, vmax = ts.vmax, rL = turn.left.radius, rE = turn.entered.radius;
  const Vec3 cL = turn.left.centre, tb = turn.tb;
  const size_t lo = i - h - k, hi = std::min(path.size() - 1, i + h + k);
  const double before = retrace::chainLength(g, retrace::stretch(path, lo, hi));
  std::vector<Vec3> centres;
  const bool walkOk = walksBesideToFork(lu, turn.entered.centre, -turn.ta, cL, tb, rE, rL + rE,
                                        2 * before + 2 * (rL + rE), ts.dt, ts.cap, &centres);
  if (!walkOk || centres.size() < 2) return false;
  // The tube left followed on from its own section past the turn, beside the walk, as far as the walk went.
  double walkLen = 0;
  for (size_t t = 1; t < centres.size(); ++t) walkLen += (centres[t] - centres[t - 1]).norm();
  std::vector<Vec3> leftAxis;
  walksBesideToFork(lu, cL, tb, turn.entered.centre, turn.ta, rL, rL + rE, walkLen + rL + rE, ts.dt, ts.cap, &leftAxis);
  if (leftAxis.size() < 2) return false;
  size_t at = 0;
  // Beside the tube left over more than the two radii together: an antiparallel child, not a bend.
  std::vector<uint8_t> beside(centres.size(), 0);
  double besideLen = 0;
  for (size_t t = 0; t < centres.size(); ++t) {
    beside[t] = std::abs(toPolyline(centres[t], leftAxis, &at) - (rL + rE)) <= vmax;
    if (t > 0 && beside[t] && beside[t - 1]) besideLen += (centres[t] - centres[t - 1]).norm();
  }
  if (besideLen <= rL + rE) return false;
  ++r->turns;
  std::vector<Vec3> walkedBoth = centres;
  walkedBoth.insert(walkedBoth.end(), leftAxis.begin(), leftAxis.end());
  const std::vector<Index3> around = aroundWalk(g, path, lo, hi, walkedBoth);
  const Box bx = retrace::boxAround(g, around, 0, around.size() - 1, o.marginSteps);
  if (bx.size() > (int64_t(1) << 23)) return false;
  // The contact strip: in the contact zone (within a coarsest voxel of both walls, beside a touching centre), each
  // voxel's side - nearer the entered tube's wall than the left tube's (s <= 0) or not; blocked: the entered side's
  // voxels next (26 neighbours) to a voxel of the left side, so that no step crosses from one side to the other there.
  std::vector<double> side(static_cast<size_t>(bx.size()), std::numeric_limits<double>::quiet_NaN());
  for (int64_t j = 0; j < bx.size(); ++j) {
    const Vec3 p = mmOf(g, bx.voxel(j));
    const double dL = toPolyline(p, leftAxis, &at);
    if (std::abs(dL - rL) > vmax) continue;
    const double dE = toPolyline(p, centres, &at);
    if (beside[at] && std::abs(dE - rE) <= vmax) side[static_cast<size_t>(j)] = (dE - rE) - (dL - rL);
  }
  double walkedLen = (centres.back() - mmOf(g, path[lo])).norm();
  for (size_t t = 1; t < centres.size(); ++t) walkedLen += (centres[t] - centres[t - 1]).norm();
  return routeRoundBlock(cost, path, lo, hi, bx, blockedBetweenSides(bx, side), connectivity, lumenLevel, o, vmin,
                         {"the contact strip", "the turn's ends inside the contact strip", walkedLen, centres,
                          centres.size(), rL + rE, rE + 0.5 * vmax},
                         r);
}

// A turn into a child that crosses back over the tube left short of their fork (issue 21, session 38 route326: 11326's
// child 1 loops round and returns over the trunk one slice above it, ~7 mm before the fork; every path to its subtree
// steps from the trunk's wall into the child's return): the tube left walked on past the turn (its onward axis, on
// through the fork), the child walked back from its own section past the turn round its loop (walksRoundBend) until it
// comes into that onward axis again ahead of the turn, more than the contact's reach (rL + rE) along the tube left -
// the fork the path never reached (a sibling's start beside the turn closes within that reach: thin 27's b5 / b6).
// Then searchRoundBend's block (the boundary between the walked child and the tube left, within rL + a coarsest voxel
// of the path's turn stretch) and its route kept as cross34's (cost per mm, own tube).
bool searchLoopAhead(const NodeCost3D& cost, const std::vector<Index3>& path, size_t i, const Turn& turn,
                     const TurnScan& ts, int connectivity, double lumenLevel, const CrossingOptions& o,
                     ContactRetrace* r) {
  const Geometry& g = cost.geometry;
  const Lumen lu{cost, lumenLevel};
  const size_t lo = i - ts.h - ts.k, hi = std::min(path.size() - 1, i + ts.h + ts.k);
  const double rL = turn.left.radius, rE = turn.entered.radius;
  const double before = retrace::chainLength(g, retrace::stretch(path, 0, i));
  std::vector<Vec3> onward, centres;
  walksBesideToFork(lu, turn.left.centre, turn.tb, turn.entered.centre, turn.ta, rL, rL + rE, before + 2 * (rL + rE),
                    ts.dt, ts.cap, &onward);
  if (onward.size() < 2) return false;
  size_t meet = 0;  // walksRoundBend's nearest point before the turn: not asked here (rPath unbounded)
  const double entered = retrace::chainLength(g, retrace::stretch(path, i, hi));
  if (!walksRoundBend(lu, g, path, i, turn.entered.centre, -turn.ta, rE, std::numeric_limits<double>::infinity(),
                      onward, rL, rL + rE, entered + 2 * before + 2 * (rL + rE), ts.dt, ts.cap, &meet, &centres) ||
      centres.size() < 2)
    return false;
  const Vec3 close = centres.back() - mmOf(g, path[i]);
  if (close.dot(turn.tb) <= rL + rE) return false;  // ahead of the turn along the tube left, past the contact
  ++r->turns;
  std::vector<Vec3> walked = centres;
  walked.insert(walked.end(), onward.begin(), onward.end());
  const auto sideOf = [&](const Vec3& p, double dE, size_t at) {
    return (dE - rE) - (toPolyline(p, onward, &at) - rL);
  };
  return routeRoundWalk(cost, path, lo, hi, lo, hi, walked, centres, rL, rE, ts, connectivity, lumenLevel, o,
                        "the loop's block", "the turn's ends inside the loop's block", sideOf, r);
}

}  // namespace

ContactRetrace retraceAcrossContact(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                    double lumenLevel, const CrossingOptions& o) {
  ContactRetrace r;
  const Geometry& g = cost.geometry;
  const TurnScan ts(g, o);
  if (!o.enabled || !ts.fits(path.size())) return r;
  const size_t h = ts.h, k = ts.k;
  const double vmax = ts.vmax, dt = ts.dt, cap = ts.cap;
  const Lumen lu{cost, lumenLevel};
  for (size_t i = h + k; i + h + k < path.size(); ++i) {
    // Each tube's line: its stretch's direction through its outer end's section centre (off the
    // contact); the contact at the two lines' closest approach.
    Turn turn;
    if (!sharpTurnAt(lu, g, path, i, ts, &turn)) continue;
    const Vec3 &tb = turn.tb, &ta = turn.ta, &xL = turn.xL, &xE = turn.xE;
    const Section &sL = turn.left, &sE = turn.entered;
    const double rL = sL.radius, rE = sE.radius, sinA = turn.sinA;
    // A crossing, not a fork or a bend: each tube's own section (its radius, centred on its line)
    // goes on at both sides of the contact, contactReachRadii of its own radii beyond the other
    // tube's wall. At a fork the branch entered ends at the trunk's wall; at a bend neither goes on.
    const double skL = rE / sinA + 0.5 * rL, skE = rL / sinA + 0.5 * rE, goL = o.contactReachRadii * rL,
                 goE = o.contactReachRadii * rE;
    Vec3 cL1, cL2, cE1, cE2;
    const bool okL1 = armGoesOn(lu, xL, -tb, skL, goL, rL, dt, cap, &cL1),
               okL2 = armGoesOn(lu, xL, tb, skL, goL, rL, dt, cap, &cL2),
               okE1 = armGoesOn(lu, xE, -ta, skE, goE, rE, dt, cap, &cE1),
               okE2 = armGoesOn(lu, xE, ta, skE, goE, rE, dt, cap, &cE2);
    if (!(okL1 && okL2 && okE1 && okE2)) continue;
    ++r.turns;
    // The two axes through the arms' first centres on either side (off the fused contact); the block
    // a slab half-way between them, normal to their common normal, reaching two fifths of the way to
    // each axis (at least one voxel's extent across it, so no step leaks through) and as wide as the
    // two radii together: it cuts the fused lumen between the tubes and leaves each tube's own lumen
    // open, so the tube entered can still be followed through the contact (a disc across the tube
    // left, session 25's cross1, also blocked part of it: 10301 96.8 % against 99.2 %).
    const Vec3 aL = (cL2 - cL1).normalized(), aE = (cE2 - cE1).normalized();
    Vec3 n = aL.cross(aE);
    if (n.norm() < 0.5) continue;  // the axes nearly parallel: no crossing at an angle
    n.normalize();
    const Vec3 u0 = cL1 - cE1;
    const double b = aL.dot(aE), den = 1 - b * b, tl = (b * aE.dot(u0) - aL.dot(u0)) / den,
                 te = (aE.dot(u0) - b * aL.dot(u0)) / den;
    const Vec3 mid = 0.5 * ((cL1 + tl * aL) + (cE1 + te * aE));
    const double sep = std::abs((cE1 - cL1).dot(n));
    const double ext = std::abs(n[0]) * g.spacing[0] + std::abs(n[1]) * g.spacing[1] + std::abs(n[2]) * g.spacing[2];
    const double half = std::max(0.4 * sep, 0.5 * ext), R = rL + rE;
    const size_t back = 3 * (h + k);
    const size_t lo = i > back ? i - back : 0, hi = std::min(path.size() - 1, i + back);
    const Box bx = retrace::boxAround(g, path, lo, hi, o.dipBoxVoxels);
    if (bx.size() > (int64_t(1) << 23)) continue;
    std::vector<uint8_t> blocked(static_cast<size_t>(bx.size()), 0);
    for (int64_t j = 0; j < bx.size(); ++j) {
      const Vec3 dq = mmOf(g, bx.voxel(j)) - mid;
      const double al = dq.dot(n);
      if (std::abs(al) <= half && (dq - al * n).norm() <= R) blocked[static_cast<size_t>(j)] = 1;
    }
    if (blocked[static_cast<size_t>(bx.index(path[lo]))] || blocked[static_cast<size_t>(bx.index(path[hi]))]) continue;
    const std::vector<Index3> part = retrace::stretch(path, lo, hi);
    const double oldPart = chainCost(cost, part);
    double nc = 0;
    std::vector<Index3> next = retrace::boxPath(cost, bx, blocked, retrace::stepsFor(g, connectivity), part.front(),
                                                part.back(), (1 + o.neckCostSlack) * oldPart, &nc);
    if (next.empty() || retrace::farthestFrom(g, next, part) < 2 * vmax) {
      r.why = "no route of its own round the block";
      continue;
    }
    r.oldCost = chainCost(cost, path);
    return retrace::accepted(std::move(r), oldPart, nc, retrace::spliced(path, lo, hi, next));
  }
  return r;
}

ContactRetrace retraceLoopedContact(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                    double lumenLevel, const CrossingOptions& o, LoopedTurnMemo* memo) {
  ContactRetrace r;
  const Geometry& g = cost.geometry;
  const TurnScan ts(g, o);
  if (!o.enabled || !ts.fits(path.size())) return r;
  const size_t h = ts.h, k = ts.k;
  const double vmin = ts.vmin, vmax = ts.vmax, dt = ts.dt, cap = ts.cap;
  const Lumen lu{cost, lumenLevel};
  // A point asked is remembered as refused when the next is asked (a kept route returns before that).
  const std::vector<int32_t> prefix = memo ? memo->prefixes(g, path) : std::vector<int32_t>{};
  int32_t asked = -1;
  const auto refuseAsked = [&] {
    if (asked >= 0) memo->refuse(asked);
  };
  for (size_t i = h + k; i + h + k < path.size(); ++i) {
    if (memo) {
      refuseAsked();
      asked = prefix[i + h + k];
      if (memo->refused(asked)) {
        ++memo->reused, asked = -1;
        continue;
      }
    }
    Turn turn;
    if (!sharpTurnAt(lu, g, path, i, ts, &turn)) continue;
    const Vec3 &ta = turn.ta, &xE = turn.xE;
    const double rL = turn.left.radius, rE = turn.entered.radius, sinA = turn.sinA;
    // The tube entered, followed back from the contact: does it lead back to the path before the
    // turn (the fork the path came from), a tube of its own all the way? Asked at a turn back only (more
    // than 90 degrees, as the walks below): where the path bends by less, the two stretches' lines meet
    // outside the bend's outer wall, and the walk back from there follows whatever lies beyond the path's
    // own tube (12232: a sibling's U beside the bend, walked to the fork, the right route cut into it).
    size_t meet = 0;
    std::vector<Vec3> centres;
    const double before = retrace::chainLength(g, retrace::stretch(path, 0, i));
    if (turn.cosA >= 0 ||
        !walksBackToPath(lu, g, path, i, xE, -ta, rL / sinA + 0.5 * rE, rE, rL, rL + rE, h, rL + rE,
                         2 * before + 2 * (rL + rE), dt, cap, &meet, &centres) ||
        meet == 0) {
      // A turn back (more than 90 degrees): into a child whose tight bend lies against the tube left, walked round the
      // bend to its fork; else into a child beside the tube left, walked on its own side to its fork.
      if (turn.cosA < 0 && (searchRoundBend(cost, path, i, turn, ts, connectivity, lumenLevel, o, &r) ||
                            searchBeside(cost, path, i, turn, ts, connectivity, lumenLevel, o, &r)))
        return r;
      // Any turn: into a child crossing back over the tube left short of their fork, walked round to that fork.
      if (searchLoopAhead(cost, path, i, turn, ts, connectivity, lumenLevel, o, &r)) return r;
      continue;
    }
    ++r.turns;
    // Searched again from the fork into the tube entered: the path's own stretch from the fork to
    // the turn blocked across its lumen, the walked tube (and its way into the path's lumen at the
    // fork) left open.
    const size_t lo = meet - 1, hi = std::min(path.size() - 1, i + h + k);
    const Vec3 last = centres.back(), atFork = mmOf(g, path[lo]);
    const int n = std::max(1, static_cast<int>(std::ceil((atFork - last).norm() / dt)));
    for (int s = 1; s <= n; ++s) centres.push_back(last + (atFork - last) * (double(s) / n));
    const std::vector<Index3> around = aroundWalk(g, path, lo, hi, centres);
    const Box bx = retrace::boxAround(g, around, 0, around.size() - 1, o.marginSteps);
    if (bx.size() > (int64_t(1) << 23)) continue;
    const double rBlock = rL + vmax, rOpen = rE + 0.5 * vmax;
    std::vector<uint8_t> blocked(static_cast<size_t>(bx.size()), 0);
    for (int64_t j = 0; j < bx.size(); ++j) {
      const Vec3 p = mmOf(g, bx.voxel(j));
      bool near = false;
      for (size_t t = meet; t + h <= i && !near; ++t) near = (mmOf(g, path[t]) - p).norm() <= rBlock;
      if (!near) continue;
      bool open = false;
      for (size_t t = 0; t < centres.size() && !open; ++t) open = (centres[t] - p).norm() <= rOpen;
      if (!open) blocked[static_cast<size_t>(j)] = 1;
    }
    // Both routes run in the lumen (at the cost floor, the shortcut the cheaper): the new one is judged by its cost per
    // mm; a tube of its own through the walked tube's farthest section from the old route (of the centres before the
    // last n).
    if (routeRoundBlock(cost, path, lo, hi, bx, blocked, connectivity, lumenLevel, o, vmin,
                        {"the block", "the fork or the tube entered inside the block", retrace::chainLength(g, around),
                         centres, centres.size() - std::min(static_cast<size_t>(n), centres.size()), rL + rE, rOpen},
                        &r))
      return r;
  }
  refuseAsked();
  return r;
}

}  // namespace vs
