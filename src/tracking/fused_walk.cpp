// The child walked back through its stretch fused beside the tube left, on a run of two-disc sections (issue 21,
// session 38 walk124; see contact_walk.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/box_search.h"
#include "tracking/contact_walk.h"

namespace vs::walk {

namespace {

// A fused section at q normal to d split into two discs (session 37 merged37's split): twoDiscs' fit on the walk's
// lumen - the widest of 8 chords through q, discs of the own radius (half the narrowest chord where larger) at its two
// ends, their centres' separation at least half a voxel and half the radius and at most both radii, the narrowest
// chord at most 2.5 x the own radius - and fused37's smear test (the centres more than one voxel of the grid apart).
// *disc: the disc nearer the walk's own line (through the last centre c along d), *sib the other; the other must lie
// nearer the tube left's axis than the walk's disc, and the walk's disc nearer its own line than that axis (fork35's
// side test).
bool splitSection(const Lumen& lu, const Vec3& q, const Vec3& d, const Vec3& c, const std::vector<Vec3>& other,
                  double rOwn, double dt, double cap, Vec3* disc, Vec3* sib) {
  const Vec3& spacing = lu.cost.geometry.spacing;
  Vec3 u, w;
  normals(d, u, w);
  double widest = 0, narrowest = std::numeric_limits<double>::infinity(), plus = 0, minus = 0;
  Vec3 e = u;
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 8;
    const Vec3 ek = std::cos(a) * u + std::sin(a) * w;
    double run[2] = {0, 0};
    for (int sgn = 0; sgn < 2; ++sgn) {
      const Vec3 dir = sgn == 0 ? ek : Vec3(-ek);
      while (run[sgn] < cap && lu.at(q + (run[sgn] + dt) * dir)) run[sgn] += dt;
      if (run[sgn] >= cap) return false;  // no wall within reach
    }
    if (run[0] + run[1] > widest) widest = run[0] + run[1], plus = run[0], minus = run[1], e = ek;
    narrowest = std::min(narrowest, run[0] + run[1]);
  }
  const double r = std::max(rOwn, 0.5 * narrowest), sep = widest - 2 * r;
  if (sep < std::max(0.5 * spacing.minCoeff(), 0.5 * r) || sep > 2 * r || narrowest > 2.5 * rOwn) return false;
  const Vec3 ePlus = q + (plus - r) * e, eMinus = q - (minus - r) * e;
  if ((ePlus - eMinus).cwiseQuotient(spacing).norm() <= 1) return false;  // one lumen smeared over the grid
  const bool plusOwn = toLine(ePlus, c, d) <= toLine(eMinus, c, d);
  *disc = plusOwn ? ePlus : eMinus;
  *sib = plusOwn ? eMinus : ePlus;
  size_t at = 0;
  const double dOwn = toPolyline(*disc, other, &at);
  return toPolyline(*sib, other, &at) < dOwn && toLine(*disc, c, d) < dOwn;
}

// A step round a tight bend through fused sections: bendStep's turned directions from the last own centre c, the
// least turn whose section one step on splits (splitSection) with the walk's disc within rOwn of the turned line; of
// those, the best centred.
bool splitBend(const Lumen& lu, const Vec3& c, const Vec3& d, const std::vector<Vec3>& other, double step, double rOwn,
               double dt, double cap, Vec3* disc, Vec3* sib) {
  return leastTurn(d, [&](const Vec3& e, double& best) {
    const Vec3 q = c + step * e;
    Vec3 p, s;
    if (!lu.at(q) || !splitSection(lu, q, e, c, other, rOwn, dt, cap, &p, &s)) return;
    const double off = toLine(p, c, e);
    if (off <= rOwn && off < best) best = off, *disc = p, *sib = s;
  });
}

// The median radius of the centred sections through the path's points lo..hi, each normal to the path's chord
// through its two neighbours (sections out of the lumen left out; 0 where none): a tube's own radius along a stretch,
// its oblique or fused sections' outliers passed over.
double stretchRadius(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t lo, size_t hi,
                     double dt, double cap) {
  std::vector<double> radii;
  for (size_t j = lo; j <= hi; ++j) {
    const Vec3 chord =
        retrace::mmOf(g, path[std::min(j + 1, path.size() - 1)]) - retrace::mmOf(g, path[j > 0 ? j - 1 : j]);
    if (chord.norm() <= 0) continue;
    const Section s = centredSection(lu, retrace::mmOf(g, path[j]), chord.normalized(), dt, cap);
    if (s.lumen) radii.push_back(s.radius);
  }
  if (radii.empty()) return 0;
  std::sort(radii.begin(), radii.end());
  const size_t n = radii.size();
  return n % 2 ? radii[n / 2] : 0.5 * (radii[n / 2 - 1] + radii[n / 2]);
}

}  // namespace

bool walksFusedRun(const Lumen& lu, const Geometry& g, const std::vector<Index3>& path, size_t turn, const Vec3& start,
                   const Vec3& dir, double rOwn, double rPath, const std::vector<Vec3>& other, double rOther,
                   double maxBad, double maxWalk, double dt, double cap, size_t* meet, std::vector<Vec3>* centres,
                   std::vector<Vec3>* sibs) {
  const double step = std::max(dt, 0.5 * rOwn), vmax = g.spacing.maxCoeff();
  Vec3 q = start, d = dir;
  double walked = 0, bad = 0, runMm = 0;
  bool contact = false;
  std::vector<Vec3> own, sib;  // the run's two discs, section by section
  const Vec3 nan = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  sibs->clear();
  size_t at = 0;
  // The run ends: the loop closes at its last disc where the run is longer than the contact's reach.
  const auto closes = [&]() {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < turn; ++j) {
      const double dj = (retrace::mmOf(g, path[j]) - own.back()).norm();
      if (dj < nearest) nearest = dj, *meet = j;
    }
    if (nearest > rPath + rOwn) return false;
    // Every split's other disc is the tube left's: within its radius of the path's stretch from the meet to the turn
    // (the path ran in the tube left beside the child's fused stretch and through the contact), not a third tube's
    // nor a wall's.
    std::vector<Vec3> ran;
    for (size_t j = *meet; j <= turn; ++j) ran.push_back(retrace::mmOf(g, path[j]));
    size_t near = 0;
    for (const Vec3& e : *sibs)
      if (!std::isnan(e[0]) && toPolyline(e, ran, &near) > rOther) return false;
    // And the run's own discs are not the path's: each farther than the child's radius from that stretch (the path
    // ran beside the child's fused stretch, not in it - else the walk split the path's own tube round its bend).
    for (const Vec3& e : own)
      if (toPolyline(e, ran, &near) <= rOwn) return false;
    // And the walk is not inside the tube left: where the tube left's walked axis runs through every one of the
    // run's own discs (within the own radius of each, or the tube left's own radius where wider), the walk left the
    // child through its fork and split the tube left's own sections (10929: b5's walk ran on into its parent b2, cut
    // obliquely on thick slices; 11729: a thin child, its walk on into b5, the axis just outside the child's radius
    // but inside b5's); beside a fused sibling the axis runs through the union and leaves some of the child's discs
    // (12124: 3 of 8 outside its own radius, 1 of 8 outside the tube left's 2.51 mm). The tube left's own radius: the
    // median of its sections along the path's stretch (the tube the path ran in), not rOther, the section at the turn -
    // there it spans both tubes where they are fused (12124).
    const double rInside = std::max(rOwn, stretchRadius(lu, g, path, *meet, turn, dt, cap));
    size_t onAxis = 0;
    for (const Vec3& e : own)
      if (toPolyline(e, other, &near) <= rInside) ++onAxis;
    if (onAxis == own.size()) return false;
    return true;
  };
  while (walked <= maxWalk) {
    const Section s = centredSection(lu, q, d, dt, cap);
    const double dOther = toPolyline(s.centre, other, &at);
    Vec3 next = q + step * d, disc, other2;
    if (contact && !centres->empty() && s.lumen) {
      const bool split = splitSection(lu, q, d, centres->back(), other, rOwn, dt, cap, &disc, &other2) ||
                         splitBend(lu, centres->back(), d, other, step, rOwn, dt, cap, &disc, &other2);
      const bool goesOn =
          own.empty() || ((disc - own.back()).norm() <= step + vmax && (other2 - sib.back()).norm() <= step + vmax);
      if (split) {
        if (!goesOn) own.clear(), sib.clear(), runMm = 0;  // a new run starts here
        sibs->resize(centres->size(), nan);
        if (!own.empty()) runMm += (disc - own.back()).norm();
        own.push_back(disc), sib.push_back(other2);
        bad = 0;
        Section b;
        b.centre = disc;
        next = takeCentre(b, step, d, centres);
        sibs->push_back(other2);
        q = next;
        walked += step;
        continue;
      }
      if (runMm > rOwn + rOther) return sibs->resize(centres->size(), nan), closes();  // the run's end: the fork
      own.clear(), sib.clear(), runMm = 0;
    }
    const bool inLeft = !centres->empty() && (dOther < rOther || dOther < toLine(s.centre, centres->back(), d));
    if (stepOn(lu, s, q, inLeft, step, rOwn, dt, cap, maxBad, bad, d, centres, &next) == WalkStep::Lost) return false;
    contact = contact || (inLeft && dOther < rOther);
    q = next;
    walked += step;
  }
  return false;
}

}  // namespace vs::walk
