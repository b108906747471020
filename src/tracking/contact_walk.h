// The sections and steps of the contact re-searches' walks along a tube (issue 21; contact_retrace.cpp's, moved here
// in session 38 walk124 so that the fused walk, fused_walk.cpp, shares them): the lumen at a point, a tube's
// cross-section, a walk's step onto an own centre or kept to the lumen, the step round a tight bend, distances.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "tracking/crossing_retrace.h"
#include "volume/plane_basis.h"
#include "volume/round_half.h"

namespace vs::walk {

struct Lumen {
  const NodeCost3D& cost;
  double level;
  bool at(const Vec3& p) const {
    const Geometry& g = cost.geometry;
    Index3 v;
    for (size_t ax = 0; ax < 3; ++ax) v[ax] = roundHalfAway(p[ax] / g.spacing[ax]);
    return g.contains(v) && cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= level;
  }
};

// Two unit vectors normal to d: the section plane's basis (volume/plane_basis.h), both normalised.
inline void normals(const Vec3& d, Vec3& u, Vec3& w) {
  const PlaneBasis b = unitPlaneBasis(d);
  u = b.u, w = b.v;
}

// A tube's cross-section at p normal to d: the lumen runs out from p in 8 directions give its
// radius (their mean) and its centre (each opposite pair's runs' mid-point).
struct Section {
  bool lumen = false;
  double radius = 0;
  Vec3 centre;
};
Section sectionAt(const Lumen& lu, const Vec3& p, const Vec3& d, double dt, double cap);
// The section re-centred once on its own lumen (a line a few degrees off the axis drifts from it).
Section centredSection(const Lumen& lu, const Vec3& p, const Vec3& d, double dt, double cap);

// One step of a walk along a tube (walksBackToPath, walksBesideToFork): an own section's centre taken, the walk
// turned towards it; or, through a section of no tube's own radius (fused, or cut obliquely in a tight bend), kept to
// its lumen by the centre's sideways shift without taking the centre as the tube's. Returns the next position.
Vec3 takeCentre(const Section& s, double step, Vec3& d, std::vector<Vec3>* centres);
Vec3 keepToLumen(const Vec3& q, const Vec3& side, double step, Vec3& d);

// A step round a bend as tight as the tube's own radius (issue 21, session 37: a child's U right past its fork, 10923):
// where the straight step leaves the lumen, the directions turned from d by 30, 60 and 90 degrees (8 ways round each)
// from the last own centre c, the least turn whose section one step on, normal to the turned direction, is the tube's
// own (radius 0.5-2 rOwn, centred within rOwn, as every walk's own section); of those, the best centred. A turned
// section centred within rAvoid of the polyline `avoid` (where given: another tube's walked centres) is that tube's,
// not this tube's bend, and is not taken (session 39 turn232: the tube left's walk on turning into the child it
// touches at a contact, 12232).
bool bendStep(const Lumen& lu, const Vec3& c, const Vec3& d, double step, double rOwn, double dt, double cap,
              Section* out, const std::vector<Vec3>* avoid = nullptr, double rAvoid = 0);

// The directions turned from unit d by 30, 60 and 90 degrees, 8 ways round each, least turn first (bendStep's and the
// fused walk's search round a bend): tryTurn(e, best) scores direction e, lowering best (and keeping its candidate)
// where e's is better; the first turn with any candidate ends the search. False where no turn has one.
template <class TryTurn>
bool leastTurn(const Vec3& d, TryTurn&& tryTurn) {
  Vec3 u, w;
  normals(d, u, w);
  for (int deg = 30; deg <= 90; deg += 30) {
    const double a = deg * M_PI / 180.0;
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 8; ++k) {
      const double b = k * M_PI / 4;
      tryTurn((std::cos(a) * d + std::sin(a) * (std::cos(b) * u + std::sin(b) * w)).normalized(), best);
    }
    if (best < std::numeric_limits<double>::infinity()) return true;
  }
  return false;
}

// One step of a walk on the child's own sections (walksRoundBend's and walksFusedRun's): s the centred section at q
// normal to d, inLeft whether it is the tube left's (fork35's side test). An own section (lumen, radius 0.5-2 rOwn,
// centred within rOwn) is taken (takeCentre); out of the lumen, the least turn round a bend (bendStep, steered fully
// onto its centre); else the step is a miss, counted into bad (Lost past maxBad) and, in a lumen not the tube left's,
// kept to it (keepToLumen). *next: the next sample (q + step d where nothing else moves it); d and centres updated.
// avoid / rAvoid: bendStep's (no turn into that tube).
enum class WalkStep { Own, Bend, Missed, Lost };
WalkStep stepOn(const Lumen& lu, const Section& s, const Vec3& q, bool inLeft, double step, double rOwn, double dt,
                double cap, double maxBad, double& bad, Vec3& d, std::vector<Vec3>* centres, Vec3* next,
                const std::vector<Vec3>* avoid = nullptr, double rAvoid = 0);

// The distance from p to the line through c along unit d; and to the polyline through pts (its nearest point's index
// in *nearest where given).
double toLine(const Vec3& p, const Vec3& c, const Vec3& d);
double toPolyline(const Vec3& p, const std::vector<Vec3>& pts, size_t* nearest = nullptr);

}  // namespace vs::walk

namespace vs::walk {

// The child walked back through the stretch where it runs fused beside the tube left (issue 21, session 38 walk124:
// 12124's child b1, one lumen with its sibling over its whole first arm and its U's bottom, so that no walk on own
// sections - walksRoundBend - reaches its fork). Started as walksRoundBend on the child's own section `start` past the
// turn, own sections taken, a step leaving the lumen turned round the bend (bendStep), others stepped over straight up
// to maxBad mm at a time, until it meets the tube left's lumen (within rOther of its axis `other`: the contact). From
// there on a lumen section is first tried as two discs (splitSection: twoDiscs' bounds and fused37's smear test, the
// walk's disc on its own line and the other nearer the tube left's axis; or the least turned one that splits,
// splitBend) and the walk takes its own disc. Splits count as a run only while each section's two discs lie within a
// step and a coarsest voxel of the section before's (run37's chain: two tubes going on side by side; a split that does
// not continue the run starts a new one - round the U's bottom the discs jump as the walk turns). A lumen section that
// does not split ends the run: where the run is longer than the contact's reach (rOwn + rOther, twoDiscRun's junction
// reach), that is the fork, where the two lumens join, and the loop closes there if the run's last disc lies within
// rPath + rOwn of a path point before the turn (that point in *meet) and every split's other disc lies within rOther of
// the path's stretch from the meet to the turn (the other disc is the tube left, in which the path ran - not a third
// tube nor a wall) and each of the run's own discs farther than rOwn from it (the path ran beside the child's fused
// stretch, not in it: else the walk split the path's own tube round its bend) and the tube left's axis `other` runs
// outside the own radius - or the tube left's own radius where wider, the median section along the path's stretch
// from the meet to the turn (session 38 axis729, 11729's thin child) - of at least one of the run's own discs (else
// the walk is inside the tube left: through the child's fork into it, splitting its oblique sections - session 38
// walk124b, 10929); a shorter run is dropped and the walk goes on. *sibs: per centre the split's other disc (NaN at own
// sections' centres). False where it never closes (the walk out of the lumen for over maxBad mm, or past maxWalk).
bool walksFusedRun(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t turn, const Vec3& start,
                   const Vec3& dir, double rOwn, double rPath, const std::vector<Vec3>& other, double rOther,
                   double maxBad, double maxWalk, double dt, double cap, size_t* meet, std::vector<Vec3>* centres,
                   std::vector<Vec3>* sibs);

}  // namespace vs::walk
