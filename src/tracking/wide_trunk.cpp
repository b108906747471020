// Wide trunks and the daughters that leave them (wide_trunk.h).
#include "tracking/wide_trunk.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/daughter_tube.h"
#include "util/parallel.h"

namespace vs::centreline_detail {

bool ballCentre(const TrilinearSampler& sample, const Vec3& spacing, Vec3& c, double rhoMm, double level,
                BallScratch& sc) {
  const Vec3 inv = spacing.cwiseInverse();
  if (!(rhoMm > 0) || !sample.inside(c.cwiseProduct(inv))) return false;
  const double value = sample.at(c.cwiseProduct(inv));
  if (!(value != level)) return false;
  const bool bright = value > level;
  const double h = std::max(spacing.minCoeff(), rhoMm / 8);
  const int m = static_cast<int>(std::ceil(rhoMm / h)), w = 2 * m + 1;
  const size_t cells = static_cast<size_t>(w) * static_cast<size_t>(w) * static_cast<size_t>(w);
  auto id = [&](int i, int j, int k) { return static_cast<int32_t>((k * w + j) * w + i); };
  Vec3 x = c;
  for (int it = 0; it < 20; ++it) {
    sc.lumen.assign(cells, 0);
    for (int k = 0; k < w; ++k)
      for (int j = 0; j < w; ++j)
        for (int i = 0; i < w; ++i) {
          const Vec3 d = h * Vec3(i - m, j - m, k - m);
          if (d.squaredNorm() > rhoMm * rhoMm) continue;
          const Vec3 p = (x + d).cwiseProduct(inv);
          if (!sample.inside(p)) continue;
          const double v = sample.at(p);
          sc.lumen[static_cast<size_t>(id(i, j, k))] = bright ? v > level : v < level;
        }
    const int32_t start = id(m, m, m);
    if (!sc.lumen[static_cast<size_t>(start)]) break;  // the centroid left the lumen: keep the last
    // The component holding the centre (6-connected), marked 2; its centroid.
    sc.stack.assign(1, start);
    sc.lumen[static_cast<size_t>(start)] = 2;
    Vec3 sum(0, 0, 0);
    double count = 0;
    while (!sc.stack.empty()) {
      const int32_t s = sc.stack.back();
      sc.stack.pop_back();
      const int i = s % w, j = (s / w) % w, k = s / (w * w);
      sum += Vec3(i - m, j - m, k - m), count += 1;
      const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
      for (const auto& o : nb) {
        const int a = i + o[0], b = j + o[1], e = k + o[2];
        if (a < 0 || b < 0 || e < 0 || a >= w || b >= w || e >= w) continue;
        const int32_t t = id(a, b, e);
        if (sc.lumen[static_cast<size_t>(t)] != 1) continue;
        sc.lumen[static_cast<size_t>(t)] = 2;
        sc.stack.push_back(t);
      }
    }
    const Vec3 shift = (h / count) * sum;
    x += shift;
    if (shift.norm() < 0.02 * spacing.minCoeff()) break;
  }
  c = x;
  return true;
}

bool onTrunkAxis(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& J, const Vec3& dir, double trunkMm,
                 double level, BallScratch& sc) {
  const Vec3 e = dir.normalized();
  auto stays = [&](const Vec3& x, bool across) {
    Vec3 at = x;
    if (!ballCentre(sample, spacing, at, trunkMm, level, sc)) return false;
    Vec3 shift = at - x;
    if (across) shift -= shift.dot(e) * e;
    return shift.norm() <= spacing.minCoeff();
  };
  return stays(J, true) && (stays(J + trunkMm * e, false) || stays(J - trunkMm * e, false));
}

// wide_trunk.h
double lumenClearance(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, double level, double maxMm) {
  const Vec3 inv = spacing.cwiseInverse();
  const bool bright = sample.at(c.cwiseProduct(inv)) > level;
  const double step = 0.5 * spacing.minCoeff();
  double best = maxMm;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const Vec3 d = Vec3(dx, dy, dz).normalized();
        for (double r = step; r < best; r += step) {
          const Vec3 p = (c + r * d).cwiseProduct(inv);
          if (!sample.inside(p)) break;
          const double v = sample.at(p);
          if (bright ? v <= level : v >= level) {
            best = r;
            break;
          }
        }
      }
  return best;
}

namespace {

constexpr size_t linePoints = 5;
constexpr size_t axisPoints = 12;  // the daughter's axis: a line fitted through up to this many points
constexpr size_t skipPoints = 2;   // ... but its first ones (their rays see the ostium)

// The line through pts (least squares): its centroid and unit direction, oriented from the first
// point to the last. False with fewer than 2 points or no extent.
bool fitLine(const std::vector<Vec3>& pts, Vec3& centre, Vec3& dir) {
  if (pts.size() < 2) return false;
  centre = Vec3(0, 0, 0);
  for (const Vec3& p : pts) centre += p;
  centre /= static_cast<double>(pts.size());
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const Vec3& p : pts) m += (p - centre) * (p - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m);
  dir = es.eigenvectors().col(2);
  if (!(es.eigenvalues()[2] > 0)) return false;
  if (dir.dot(pts.back() - pts.front()) < 0) dir = -dir;
  return true;
}
constexpr double ballRadii = 1.0;
constexpr double axisTolVoxels = 0.75;  // fitAxis: a point farther off its daughter's chord is left out

// The daughter's axis: the line through pts, refitted without its farthest point while that lies more
// than tolMm off the line and more than linePoints remain; pts keeps the points the line rests on. A
// point near the ostium that its rays centred towards the trunk (10506, 1.76 mm slices: 6 voxels off)
// tilts the chord, and J, where the chord meets the trunk's axis, moves along that axis by as much; a
// daughter's bend beyond the wall leaves its points within a fraction of a voxel of their chord.
bool fitAxis(std::vector<Vec3>& pts, double tolMm, Vec3& centre, Vec3& dir) {
  if (!fitLine(pts, centre, dir)) return false;
  while (pts.size() > linePoints) {
    size_t worst = 0;
    double far = -1;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Vec3 v = pts[i] - centre;
      const double off = (v - v.dot(dir) * dir).norm();
      if (off > far) far = off, worst = i;
    }
    if (far <= tolMm) break;
    pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(worst));
    if (!fitLine(pts, centre, dir)) return false;
  }
  return true;
}

// J: the point of the line (ac, ea) nearest the line through G along ed; false where it is not behind
// G along ed (or the lines are near parallel).
bool nearestOnLine(const Vec3& ac, const Vec3& ea, const Vec3& G, const Vec3& ed, Vec3& J) {
  const Vec3 w = G - ac;
  const double cs = ed.dot(ea), den = 1 - cs * cs;
  const double t = den > 0.05 ? (cs * ea.dot(w) - ed.dot(w)) / den : 0;  // along the daughter's axis
  J = ac + (ea.dot(w) + t * cs) * ea;
  return t < 0;
}

// J: the trunk's axis point nearest the daughter's axis (G, unit direction ed outward), followed
// back from a trunk radius behind G (wide_trunk.h). False where a point of the line is not lumen
// or J does not lie behind G.
bool trunkJunction(const WideTrunkInput& in, const Vec3& G, const Vec3& ed, double trunkMm, double level,
                   BallScratch& sc, Vec3& J) {
  const double rho = ballRadii * trunkMm;
  Vec3 A = G - trunkMm * ed;
  if (!ballCentre(in.sample, in.spacing, A, rho, level, sc)) return false;
  for (int it = 0; it < 3; ++it) {
    const double t = (A - G).dot(ed);
    if (t >= 0) return false;
    A = G + t * ed;
    if (!ballCentre(in.sample, in.spacing, A, rho, level, sc)) return false;
  }
  J = A;
  return (J - G).dot(ed) < -in.spacing.minCoeff();
}

// J on the trunk's axis (ac, ea) from the daughter's course in the trunk's cylindrical coordinates: its
// points' position along the axis against their distance from it, a line carried back to distance 0. A
// daughter that turns round the trunk (along its wall) keeps that course straight, while a chord through
// its points tilts sideways and its nearest approach to the axis moves along it (10804: 3.4 voxels, a
// daughter of radius 1.75 voxels bending where it leaves a trunk of 18.5). False where the points lie at
// one distance from the axis (a daughter along the trunk). `leave`, where given, stays out of the fit.
// Points nearer the axis than wallMm (the trunk's wall and a daughter radius beyond it) stay out too where
// at least 3 others span minSpanMm: their sections still take in the trunk's lumen through the ostium, so
// their rays pull them towards it, and the nearest point has the fit's longest lever to the axis (10906:
// the first point 0.8 voxel low along the axis put J 1.55 voxels off; without the two within the daughter's
// radius of the wall 0.1).
bool axialJunction(const std::vector<Vec3>& pts, const Vec3* leave, const std::vector<Vec3>& opening, const Vec3& ac,
                   const Vec3& ea, double minSpanMm, double wallMm, Vec3& J) {
  auto fit = [&](double fromMm, Vec3& at) {
    double n = 0, sr = 0, sa = 0, srr = 0, sra = 0, lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto add = [&](const Vec3& p) {
      const Vec3 v = p - ac;
      const double a = v.dot(ea), r = (v - a * ea).norm();
      n += 1;
      sr += r, sa += a, srr += r * r, sra += r * a, lo = std::min(lo, r), hi = std::max(hi, r);
    };
    for (const Vec3& p : pts) {
      if (leave && p == *leave) continue;
      const Vec3 v = p - ac;
      if ((v - v.dot(ea) * ea).norm() >= fromMm) add(p);
    }
    for (const Vec3& p : opening) add(p);
    const double den = n * srr - sr * sr;
    if (n < 3 || !(hi - lo >= minSpanMm) || !(den > 0)) return false;
    const double m = (n * sra - sr * sa) / den, h = (sa - m * sr) / n;
    at = ac + h * ea;
    return true;
  };
  return fit(wallMm, J) || fit(0, J);
}

// The daughter's radius (or level): the median of its line's points' radii (levels) but its first ones'
// (skipPoints: their sections take in the ostium and read the trunk's radius).
double daughterMedian(const std::vector<double>& perPoint, const std::vector<size_t>& line) {
  std::vector<double> r;
  for (size_t i = skipPoints; i < line.size(); ++i) r.push_back(perPoint[line[i]]);
  if (r.empty()) return 0;
  std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
  return r[r.size() / 2];
}

// Whether p (mm) lies on the lumen's side of the level: side the root's polarity, or where that is unknown the side of
// a point known to be lumen (lumenSide).
bool onLumenSide(const TrilinearSampler& sample, const Vec3& spacing, int side, const Vec3& p, double level) {
  return side * (sample.at(p.cwiseQuotient(spacing)) - level) > 0;
}
int lumenSide(const WideTrunkInput& in, const Vec3& lumenPoint, double level) {
  if (in.polarity != 0) return in.polarity;
  return in.sample.at(lumenPoint.cwiseQuotient(in.spacing)) > level ? 1 : -1;
}

// J deep in the trunk (half its radius from the wall by its level) and J -> G in the lumen: else the
// axes found are not this junction's (the aorta MRA: a J 20 mm off the aorta's axis). J -> G's last
// daughter radius before G may read down to the daughter's own level (the median of its line's) where
// that is the lower: G, carried back from the daughter's straight distal course, lies up to its radius off
// where the daughter bends past the wall - on its wall, where a thin daughter dimmer than its trunk reads
// under the trunk's level (11006: 128.5 at G against 132.7, the rest 161-212; refused, its first points
// were left 1.8-4.2 voxels off). Not unchecked: G's own voxel is what refuses a wrong J on the real volumes
// (that stretch left out: a head CTA daughter placed across the background, 2 points out of the vessel).
bool junctionInLumen(const TrilinearSampler& sample, const Vec3& spacing, const PlacedJunction& d, const Vec3& J,
                     const Vec3& G) {
  const double level = d.level, trunkMm = d.trunkMm;
  // J on the lumen's side of the level (the root's polarity; where unknown, the side of the trunk's point
  // before the daughter): lumenClearance and ballCentre (trunkJunction) work on either side, so a daughter's
  // axis carried back past the trunk found a J in the background and placed the daughter's points across it
  // (the aorta MRA from 69,350,15: J 19 mm off the aorta's axis, 11 points reading 100-180 against a
  // background of 240 and a lumen of 870-1400).
  const bool bright = d.side > 0;
  if (!onLumenSide(sample, spacing, d.side, J, level)) return false;
  if (lumenClearance(sample, spacing, J, level, trunkMm) < 0.5 * trunkMm) return false;
  const double len = (G - J).norm(), stepMm = spacing.minCoeff();
  const double nearG = bright ? std::min(level, d.ownLevel) : std::max(level, d.ownLevel);
  // J -> G's points outside the trunk (beyond its radius from its axis, or where that is not known from J:
  // placeWideTrunk's inTrunk) are the daughter's own lumen, at its own level: a thin daughter dimmer than its trunk
  // reads under the trunk's level from its opening in the wall on (3204: 124.4 against 124.1, 0.8 mm beyond the
  // trunk's radius).
  auto outside = [&](const Vec3& x) {
    const Vec3 v = x - (d.found ? d.ac : J);
    return (d.found ? (v - v.dot(d.ea) * d.ea).norm() : v.norm()) > trunkMm;
  };
  for (double t = 0; t <= len; t += stepMm) {
    const Vec3 x = J + (t / std::max(len, 1e-9)) * (G - J);
    const double v = sample.at(x.cwiseQuotient(spacing));
    const double at = t > len - d.daughterMm || outside(x) ? nearG : level;
    if (bright ? v <= at : v >= at) return false;
  }
  return true;
}

// A daughter's junction (its axes and first point given) with axialJunction's and junctionInLumen's
// parameters: the trunk's level, radius and point before the daughter, the daughter's line.
PlacedJunction junctionOf(const WideTrunkInput& in, PlacedJunction d, const Vec3& trunkPoint, double level,
                          double trunkMm, const std::vector<size_t>& line) {
  d.minSpanMm = in.spacing.minCoeff();
  d.daughterMm = daughterMedian(in.radiusMm, line), d.ownLevel = daughterMedian(in.sectionLevel, line);
  d.wallMm = trunkMm + d.daughterMm, d.level = level, d.trunkMm = trunkMm;
  // The lumen's side of the level (where the polarity is unknown, the side of the trunk's point).
  d.side = lumenSide(in, trunkPoint, level);
  return d;
}

// A point put on the daughter's line (through dc along ed), and the j-th of m points spaced evenly on J -> G: the
// junction's placement, first by placeWideTrunk and again by replaceJunctions.
Vec3 onDaughterLine(const Vec3& dc, const Vec3& ed, const Vec3& x) { return dc + (x - dc).dot(ed) * ed; }
Vec3 onJunctionLine(const Vec3& J, const Vec3& G, size_t j, size_t m) {
  return J + (static_cast<double>(j + 1) / static_cast<double>(m + 1)) * (G - J);
}

// J -> G runs on to the daughter's first fitted point beyond the trunk's wall (`beyond`) rather than along the
// chord (dc, ed; G its point at the daughter's first point `first`): a daughter that bends beyond the wall tilts
// its chord (up to 20 degrees on the family), and a tilted chord puts G beside the daughter (514, 537 on
// linePoints points: 1.5 voxels), whose first points outside are centred by their own rays.
void runToBeyond(const Vec3& J, const Vec3& beyond, const Vec3& first, Vec3& dc, Vec3& ed, Vec3& G) {
  const Vec3 to = beyond - J;
  if (to.dot(ed) > 0 && to.norm() > (G - J).norm()) dc = J, ed = to.normalized(), G = onDaughterLine(J, ed, first);
}

// The indices of `line` whose points (q) are pts' (copies of them: equal).
std::vector<size_t> indicesOf(const std::vector<size_t>& line, const std::vector<Vec3>& q,
                              const std::vector<Vec3>& pts) {
  std::vector<size_t> out;
  for (const Vec3& x : pts)
    for (size_t k : line)
      if (q[k] == x) {
        out.push_back(k);
        break;
      }
  return out;
}

// The daughter's own lumen from its first point c: up to axisPoints points that are not wide along a
// chain without branches; empty where fewer than linePoints.
std::vector<size_t> daughterLine(const std::vector<uint8_t>& wide, const std::vector<std::vector<int32_t>>& children,
                                 size_t c) {
  std::vector<size_t> line{c};
  for (size_t k = c; line.size() < axisPoints && children[k].size() == 1;) {
    k = static_cast<size_t>(children[k][0]);
    if (wide[k]) break;
    line.push_back(k);
  }
  // A daughter whose path ends this near the trunk (16004: its target 4 points past the wall) has no more points: its
  // axis still rests on the two past the skipped ones (fitAxis' fewest). Unplaced, its points inside the trunk were
  // left to sections that slid them along the trunk's axis, 17 voxels past J (8 on the trunk's continuation).
  if (line.size() < (children[line.back()].empty() ? skipPoints + 2 : linePoints)) line.clear();
  return line;
}

// The ball centres of the axis points (placeWideTrunk's `axial`) within reachMm of G: those of the
// first kind, and those of the second where the first are fewer than linePoints.
std::vector<Vec3> axisPointsNear(const std::vector<uint8_t>& axial, const std::vector<uint8_t>& wide,
                                 const std::vector<Vec3>& centre, const Vec3& G, double reachMm) {
  std::vector<Vec3> axis;
  for (const uint8_t kind : {1, 2}) {
    if (axis.size() >= linePoints) break;
    for (size_t k = 0; k < axial.size(); ++k)
      if (axial[k] == kind && wide[k] && (centre[k] - G).norm() < reachMm) axis.push_back(centre[k]);
  }
  return axis;
}

// A wide point's trunk radius: the median section radius of the wide points within `reach` tree
// steps of it (its own section may be cut short at an ostium).
double medianWideRadius(const WideTrunkInput& in, const std::vector<int32_t>& parent,
                        const std::vector<std::vector<int32_t>>& children, size_t k0) {
  constexpr int reach = 6;
  std::vector<double> r;
  std::vector<std::pair<size_t, int>> todo{{k0, 0}};
  std::vector<size_t> seen{k0};
  while (!todo.empty()) {
    const auto [k, d] = todo.back();
    todo.pop_back();
    if (in.wide[k]) r.push_back(in.radiusMm[k]);
    if (d == reach) continue;
    std::vector<size_t> nb(children[k].begin(), children[k].end());
    if (parent[k] >= 0) nb.push_back(static_cast<size_t>(parent[k]));
    for (size_t j : nb)
      if (std::find(seen.begin(), seen.end(), j) == seen.end()) seen.push_back(j), todo.emplace_back(j, d + 1);
  }
  if (r.empty()) return in.radiusMm[k0];
  std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
  return r[r.size() / 2];
}

// The chain from the root to p (root first); its own points (after its last branch point) from `own`
// on.
std::pair<std::vector<size_t>, size_t> rootChain(const std::vector<int32_t>& parent,
                                                 const std::vector<std::vector<int32_t>>& children, size_t p) {
  std::vector<size_t> chain;
  for (size_t k = p;; k = static_cast<size_t>(parent[k])) {
    chain.push_back(k);
    if (parent[k] < 0) break;
  }
  std::reverse(chain.begin(), chain.end());
  size_t own = chain.size();
  while (own > 1 && children[chain[own - 1]].size() == 1) --own;
  return {chain, own};
}

// The chain's last point on the near side of J along the trunk's axis ea (the side of its first point
// within reachMm of J), where the chain passes J before `near` or at it; else `near`. A path may run on up
// the axis past its junction and come back to its daughter (10406, the axis across 1.65 mm slices: its last
// point before J 1.8 voxels short of it, the next four up to 4.2 voxels past it); `near`, its point
// nearest J, is then on the way back, and the four stayed on the trunk's axis beyond the junction. `near`
// itself may be past J (its point nearest J on the far side: 10206, 1.1 voxels past J on 2.69 mm slices):
// left on the axis, it lay past the junction, on the trunk beyond it (2.7 voxels off, on a neighbour).
size_t beforeAxisPass(const std::vector<size_t>& chain, const std::vector<Vec3>& target, const Vec3& J, const Vec3& ea,
                      double reachMm, size_t near) {
  size_t e = 0;
  while (e < near && (target[chain[e]] - J).norm() > reachMm) ++e;
  const double s0 = e < near ? (target[chain[e]] - J).dot(ea) : 0;
  if (s0 == 0) return near;
  for (size_t k = e + 1; k <= near; ++k)
    if ((target[chain[k]] - J).dot(ea) * s0 <= 0) return k - 1;
  return near;
}

// The chain's first point within stepMm of its point nearest J.
size_t firstNearest(const std::vector<size_t>& chain, const std::vector<Vec3>& target, const Vec3& J, double stepMm) {
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t k : chain) nearest = std::min(nearest, (target[k] - J).norm());
  size_t near = 0;
  while (near + 1 < chain.size() && (target[chain[near]] - J).norm() > nearest + stepMm) ++near;
  return near;
}

// Past J (the chain's point `near`): the daughter's, returned in order. Shared points there (before the
// chain's own from `own`) are copied for it (`copy`; the originals stay), and the daughter's first point c
// (or the chain's first own point) re-parented to the last copy.
template <class Copy>
std::vector<size_t> pastJunction(const std::vector<size_t>& chain, size_t own, size_t near, size_t c,
                                 std::vector<int32_t>& parent, std::vector<std::vector<int32_t>>& children,
                                 Copy&& copy) {
  std::vector<size_t> seq;
  if (near + 1 < own) {
    size_t prev = chain[near];
    for (size_t i = near + 1; i < own; ++i) {
      const size_t id = copy(chain[i]);
      parent[id] = static_cast<int32_t>(prev);
      children[prev].push_back(static_cast<int32_t>(id));
      seq.push_back(id);
      prev = id;
    }
    const size_t x = own < chain.size() ? chain[own] : c, from = static_cast<size_t>(parent[x]);
    children[from].erase(std::find(children[from].begin(), children[from].end(), static_cast<int32_t>(x)));
    parent[x] = static_cast<int32_t>(prev);
    children[prev].push_back(static_cast<int32_t>(x));
  }
  for (size_t i = std::max(near + 1, own); i < chain.size(); ++i) seq.push_back(chain[i]);
  return seq;
}

// The daughter's own lumen walked back to the trunk's wall (openingCourse) from its chord's first point outside the
// trunk (not the path's end), on the daughter's axis (d's dc, ed).
template <class InTrunk>
std::vector<Vec3> openingFrom(const WideTrunkInput& in, const PlacedJunction& d, const std::vector<Vec3>& chord,
                              const Vec3* end, const Vec3& J, InTrunk&& inTrunk) {
  for (const Vec3& x : chord)
    if (!inTrunk(x) && !(end && x == *end))
      return openingCourse(in.sample, in.spacing, onDaughterLine(d.dc, d.ed, x), d.ed, J, d.daughterMm, d.ownLevel,
                           d.side);
  return {};
}

// placeWideTrunk's result: moved points to their targets, frozen, placed 1; kept ones (a trunk radius in
// `kept`) placed 2. Returns the count moved.
size_t commitPlaced(const std::vector<uint8_t>& moved, const std::vector<Vec3>& target, const std::vector<double>& kept,
                    const std::vector<uint8_t>& ownLumen, std::vector<Vec3>& q, std::vector<uint8_t>& frozen,
                    std::vector<uint8_t>& placed) {
  size_t count = 0;
  for (size_t k = 1; k < q.size(); ++k)
    if (moved[k])
      q[k] = target[k], frozen[k] = 1, placed[k] = 1, ++count;
    else if (kept[k] > 0)
      placed[k] = 2;
    else if (ownLumen[k])
      placed[k] = 3;
  return count;
}

}  // namespace

void keepWideRuns(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                  std::vector<uint8_t>& wide) {
  const size_t n = wide.size();
  std::vector<int32_t> run(n, -1);
  std::vector<size_t> members, stack;
  for (size_t s = 0; s < n; ++s) {
    if (!wide[s] || run[s] >= 0) continue;
    members.clear();
    stack.assign(1, s);
    run[s] = static_cast<int32_t>(s);
    while (!stack.empty()) {
      const size_t k = stack.back();
      stack.pop_back();
      members.push_back(k);
      auto visit = [&](int32_t j) {
        if (j >= 0 && wide[static_cast<size_t>(j)] && run[static_cast<size_t>(j)] < 0)
          run[static_cast<size_t>(j)] = static_cast<int32_t>(s), stack.push_back(static_cast<size_t>(j));
      };
      visit(parent[k]);
      for (int32_t c : children[k]) visit(c);
      // Through the root: it is never cast, so never wide, but the trace starts in its lumen, so the
      // runs that leave it along two of its children are one trunk through it (a daughter whose path
      // parts from the others at the root had its run of a few points in the trunk cleared as a
      // flicker, and its first points were centred between the trunk's axis and the daughter).
      if (const int32_t r = parent[k]; r >= 0 && parent[static_cast<size_t>(r)] < 0 && !wide[static_cast<size_t>(r)])
        for (int32_t c : children[static_cast<size_t>(r)]) visit(c);
    }
    if (members.size() < linePoints)
      for (size_t k : members) wide[k] = 0;
  }
}

namespace {

// A placed daughter's ostium (ostiumRadii): `o` with its axis and J -> G's points, to which its first points on its
// line, the trunk's axis points near G (axisPointsNear's, as indices) and its next point, in its own lumen, added.
PlacedOstium placedOstium(PlacedOstium o, const std::vector<size_t>& line, size_t onLine,
                          const std::vector<uint8_t>& axial, const std::vector<uint8_t>& wide,
                          const std::vector<Vec3>& centre, const Vec3& G, double trunkMm) {
  o.line.insert(o.line.end(), line.begin(), line.begin() + static_cast<std::ptrdiff_t>(std::min(onLine, line.size())));
  for (size_t k = 0; k < axial.size() && k < wide.size(); ++k)
    if (axial[k] && wide[k] && (centre[k] - G).norm() < 2.5 * trunkMm) o.trunk.push_back(k);
  if (onLine < line.size()) o.own = line[onLine];
  return o;
}

}  // namespace

size_t placeWideTrunk(const WideTrunkInput& in, std::vector<int32_t>& parent,
                      std::vector<std::vector<int32_t>>& children, std::vector<Vec3>& q, std::vector<uint8_t>& frozen,
                      std::vector<uint8_t>& placed, const std::function<size_t(size_t)>& copy,
                      std::vector<double>& kept, std::vector<PlacedJunction>* junctions,
                      std::vector<PlacedOstium>* ostia) {
  const size_t n = q.size();
  std::vector<Vec3> target = q;
  std::vector<uint8_t> moved(n, 0);
  // Per point: its ball's centre (`centre`) is the trunk's axis (1: it moved there, 2: its rays centred
  // it); not for a point a daughter's placement put on J -> G (it would tilt the next daughter's axis).
  std::vector<uint8_t> axial(n, 0);
  std::vector<Vec3> centre = q;
  std::vector<double> keptMm(n, 0.0);   // per point kept (axial 2): its trunk's radius
  std::vector<uint8_t> ownLumen(n, 0);  // per point: a placed daughter's, beyond the trunk's wall (placed 3)
  auto trunkRadius = [&](size_t k0) { return medianWideRadius(in, parent, children, k0); };
  auto ball = [&](size_t k, double rMm, double level, BallScratch& sc) {
    // ... where it lies deeper in the lumen than before (a ball that takes in a neighbouring lumen
    // through a wall fainter than the level would pull the point towards that wall). A point its rays
    // centred (the ball moves it by at most a quarter radius) stays (kept) unless its ball's centre lies
    // deeper (its section tilted by a path along the wall: 525, 535, 1-2 voxels off); its ball's centre
    // is an axis point of a second kind, used where the first are too few (10506: 2-4 near a daughter).
    // A centre is taken only where it is itself lumen (on the lumen's side of the level: the root's polarity,
    // where unknown the point's own side - junctionInLumen's test): lumenClearance measures a centre beyond the
    // level on its own side, the background's, so a centre just outside ties with a point just inside (one
    // clearance step each: head CTA 40,113,41 path 0 point 118, 0.27 = 0.27 mm, value 97 against level 114).
    Vec3 c = q[k];
    if (!ballCentre(in.sample, in.spacing, c, ballRadii * rMm, level, sc)) return;
    if (!onLumenSide(in.sample, in.spacing, lumenSide(in, q[k], level), c, level)) return;
    const double clC = lumenClearance(in.sample, in.spacing, c, level, rMm);
    const double clQ = lumenClearance(in.sample, in.spacing, q[k], level, rMm);
    if (in.wide[k] == 2 && (c - q[k]).norm() <= 0.25 * rMm && clC <= clQ)
      centre[k] = c, axial[k] = 2, keptMm[k] = rMm;
    else if (clC >= clQ)
      target[k] = c, centre[k] = c, moved[k] = 1, axial[k] = 1;
  };
  parallelFor(
      1, static_cast<int64_t>(n),
      [&](int64_t b, int64_t e) {
        BallScratch sc;
        for (int64_t i = b; i < e; ++i) {
          const size_t k = static_cast<size_t>(i);
          if (in.wide[k]) ball(k, trunkRadius(k), in.sectionLevel[k], sc);
        }
      },
      16);
  BallScratch sc;
  for (size_t c = 1; c < n; ++c) {
    const int32_t pi = parent[c];
    if (pi <= 0 || !in.wide[static_cast<size_t>(pi)] || in.wide[c]) continue;
    const size_t p = static_cast<size_t>(pi);
    const std::vector<size_t> line = daughterLine(in.wide, children, c);
    if (line.empty()) continue;
    std::vector<Vec3> pts;
    for (size_t i = skipPoints; i < line.size(); ++i) pts.push_back(q[line[i]]);
    Vec3 dc, ed;
    if (!fitAxis(pts, axisTolVoxels * in.spacing.minCoeff(), dc, ed)) continue;
    Vec3 G = onDaughterLine(dc, ed, q[c]);  // the daughter's axis at its first point
    Vec3 J(0, 0, 0);
    const double trunkMm = trunkRadius(p);
    // Where the trunk's axis near G is given by the points centred on it (those the ball moved; where
    // they are too few, those the rays centred too: all of them tilted an aorta MRA daughter's J, 1.1 ->
    // 8.5 % side by side), J is where the daughter's axis passes nearest to that line; else it is
    // followed back by ballCentre.
    const std::vector<Vec3> axis = axisPointsNear(axial, in.wide, centre, G, 2.5 * trunkMm);
    Vec3 ac, ea;
    // J from the fitted line only where that line is the trunk's axis near J (wide_trunk.h: few
    // points, or points the ball left off the axis, tilt it across the trunk).
    auto onAxis = [&](const Vec3& g, const Vec3& e, Vec3& j) {
      return nearestOnLine(ac, ea, g, e, j) &&
             onTrunkAxis(in.sample, in.spacing, j, ea, trunkMm, in.sectionLevel[p], sc);
    };
    const bool found = axis.size() >= linePoints && fitLine(axis, ac, ea) && onAxis(G, ed, J);
    if (!found && !trunkJunction(in, G, ed, trunkMm, in.sectionLevel[p], sc, J)) continue;
    // Inside the trunk: within its radius of the trunk's axis, or (where that axis is not known: a
    // trunk shorter than its diameter or two, whose ends move the ball off J +- a radius) of J.
    auto inTrunk = [&](const Vec3& x) {
      return found ? (x - ac - (x - ac).dot(ea) * ea).norm() <= trunkMm : (x - J).norm() <= trunkMm;
    };
    // The daughter's first points that are not wide may still lie in the trunk (their rays found a
    // wall): its axis then through its points outside the trunk.
    std::vector<Vec3> beyond;
    for (const Vec3& x : pts)
      if (!inTrunk(x)) beyond.push_back(x);
    Vec3 dc2, ed2, J2;
    const std::vector<Vec3>* chord = &pts;  // the points the daughter's axis rests on
    if (beyond.size() >= 3 && beyond.size() < pts.size() && fitLine(beyond, dc2, ed2)) {
      const Vec3 G2 = dc2 + (q[c] - dc2).dot(ed2) * ed2;
      if (found ? onAxis(G2, ed2, J2) : trunkJunction(in, G2, ed2, trunkMm, in.sectionLevel[p], sc, J2))
        dc = dc2, ed = ed2, G = G2, J = J2, chord = &beyond;
    }
    // Along a found axis, J's place on it from the daughter's axial course (axialJunction), without the
    // path's end: centred in the tube's closed end and never smoothed, it is the chord's least sure point,
    // and its lever is the longest (with it 10804 97.4 %, 552 86.7 % within a voxel; without 100, 98.6).
    const Vec3* end = children[line.back()].empty() ? &q[line.back()] : nullptr;
    PlacedJunction axes;
    axes.ac = ac, axes.ea = ea, axes.dc = dc, axes.ed = ed, axes.first = q[c], axes.found = found;
    PlacedJunction d = junctionOf(in, std::move(axes), q[p], in.sectionLevel[p], trunkMm, line);
    Vec3 Jc;
    if (found) d.opening = openingFrom(in, d, *chord, end, J, inTrunk);
    const bool byCourse = found && axialJunction(*chord, end, d.opening, ac, ea, d.minSpanMm, d.wallMm, Jc);
    if (byCourse) J = Jc;
    if (!junctionInLumen(in.sample, in.spacing, d, J, G)) continue;
    // Not on a chord of fewer points (J is least sure there, and a line from it to one point carries its error
    // across the whole trunk).
    if (pts.size() >= linePoints) {
      size_t i0 = 0;
      while (i0 + 1 < pts.size() && inTrunk(pts[i0])) ++i0;
      d.beyond = indicesOf(line, q, {pts[i0]}).front();
      runToBeyond(J, pts[i0], q[c], dc, ed, G);
    }
    const auto [chain, own] = rootChain(parent, children, p);
    for (size_t i = own; i < chain.size(); ++i)
      if (!moved[chain[i]]) ball(chain[i], trunkMm, in.sectionLevel[p], sc);
    // The chain reaches J at its first point within a voxel of its nearest, or at its last before it
    // passes J along a found axis (a chain that overshoots along the axis is the daughter's from there).
    size_t near = firstNearest(chain, target, J, in.spacing.minCoeff());
    if (found) near = beforeAxisPass(chain, target, J, ea, 2 * trunkMm, near);
    const std::vector<size_t> seq = pastJunction(chain, own, near, c, parent, children, [&](size_t k) {
      const size_t id = copy(k);
      target.push_back(q[id]), centre.push_back(q[id]);
      moved.push_back(0), axial.push_back(0), keptMm.push_back(0), ownLumen.push_back(0);
      return id;
    });
    // The daughter's first points (their rays see the ostium), and those after them still inside the
    // trunk (their rays centre them in the trunk's section: the final centring moved one of 10506's
    // 7 voxels off), go onto its axis.
    size_t onLine = skipPoints;
    while (onLine < line.size() && inTrunk(q[line[onLine]])) ++onLine;
    for (size_t i = 0; i < onLine && i < line.size(); ++i) {
      target[line[i]] = onDaughterLine(dc, ed, q[line[i]]);
      moved[line[i]] = 1, axial[line[i]] = 0;
    }
    for (size_t i = onLine; i < line.size(); ++i) ownLumen[line[i]] = 1;
    const size_t m = seq.size();
    for (size_t j = 0; j < m; ++j) {
      target[seq[j]] = onJunctionLine(J, G, j, m);
      moved[seq[j]] = 1, axial[seq[j]] = 0;
    }
    if (ostia)
      ostia->push_back(placedOstium({found ? ac : J, found ? ea : Vec3(Vec3::Zero()), seq, {}, {}}, line, onLine, axial,
                                    in.wide, centre, G, trunkMm));
    if (!byCourse || !junctions) continue;
    d.chord = indicesOf(line, q, *chord), d.end = end ? line.back() : SIZE_MAX, d.seq = seq;
    d.onLine.assign(line.begin(), line.begin() + static_cast<std::ptrdiff_t>(std::min(onLine, line.size())));
    for (size_t k : d.onLine) d.onLineFrom.push_back(q[k]);
    junctions->push_back(std::move(d));
  }
  kept = std::move(keptMm);
  return commitPlaced(moved, target, kept, ownLumen, q, frozen, placed);
}

size_t replaceJunctions(const TrilinearSampler& sample, const Vec3& spacing,
                        const std::vector<PlacedJunction>& junctions, std::vector<Vec3>& q) {
  size_t count = 0;
  for (const PlacedJunction& d : junctions) {
    std::vector<Vec3> pts;
    for (size_t k : d.chord) pts.push_back(q[k]);
    Vec3 J, dc = d.dc, ed = d.ed;
    const Vec3* end = d.end != SIZE_MAX ? &q[d.end] : nullptr;
    // The chord's points onto the daughter's axis as fitted to the voxels (daughter_tube.h), where it fits: the
    // centred points of a daughter thinner than a slice sit on plateaus along it, levered 16-26 mm to J.
    std::vector<Vec3> chord;
    for (const Vec3& x : pts)
      if (!(end && x == *end)) chord.push_back(x);
    if (Vec3 tc, te; fitDaughterTube(sample, spacing, chord, d.ac, d.ea, d.trunkMm, d.daughterMm, d.side, tc, te)) {
      for (Vec3& x : chord) x = onDaughterLine(tc, te, x);
      pts = std::move(chord), end = nullptr;
    }
    if (!axialJunction(pts, end, d.opening, d.ac, d.ea, d.minSpanMm, d.wallMm, J)) continue;
    Vec3 G = onDaughterLine(dc, ed, d.first);
    if (!junctionInLumen(sample, spacing, d, J, G)) continue;
    if (d.beyond != SIZE_MAX) runToBeyond(J, q[d.beyond], d.first, dc, ed, G);
    for (size_t i = 0; i < d.onLine.size(); ++i) q[d.onLine[i]] = onDaughterLine(dc, ed, d.onLineFrom[i]);
    const size_t m = d.seq.size();
    for (size_t j = 0; j < m; ++j) q[d.seq[j]] = onJunctionLine(J, G, j, m);
    ++count;
  }
  return count;
}

// Placed 2 (centreline.h: wideTrunk): a faded trunk's far end (525, 535, 514) lies above the global lumen
// level by cost, so confineToLumen's pull took its points back to their path voxels at the wall (wide12);
// a trachea's points near the carina, kept too, are moved by the final centring towards the wall (wide12 /
// wide13: -896.8 HU against the -900 bar). Placed 3: a daughter dimmer than its trunk reads as not-lumen by
// the cost just past the wall where the search route hugs the ostium's trunk side, and the pull took its
// first points centred on its axis (0.03-0.05 voxel) back towards the ostium (11006: 1.1-1.4 voxels).
void unkeepShallow(const TrilinearSampler& sample, const Vec3& spacing, const std::vector<Vec3>& q,
                   const std::vector<double>& keptMm, const std::vector<double>& level,
                   const std::vector<double>& radiiMm, int polarity, std::vector<uint8_t>& placed) {
  constexpr double depthRadii = 0.5;
  for (size_t k = 0; k < placed.size() && k < keptMm.size() && k < q.size(); ++k) {
    if (placed[k] != 2 && placed[k] != 3) continue;
    const double r = placed[k] == 2 ? keptMm[k] : radiiMm[k];
    const bool lumenSide = polarity * (sample.at(q[k].cwiseQuotient(spacing)) - level[k]) > 0;
    const bool deep = lumenSide && lumenClearance(sample, spacing, q[k], level[k], r) >= depthRadii * r;
    placed[k] = !deep ? 0 : placed[k] == 3 ? 1 : 2;
  }
}

void ostiumRadii(const std::vector<Vec3>& q, const std::vector<PlacedOstium>& ostia, double voxelMm,
                 std::vector<double>& radiiMm) {
  const auto median = [&](const std::vector<size_t>& points) {
    std::vector<double> r;
    for (size_t k : points) r.push_back(radiiMm[k]);
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    return r[r.size() / 2];
  };
  for (const PlacedOstium& o : ostia) {
    if (o.trunk.empty() || o.own == SIZE_MAX) continue;
    const double wallMm = median(o.trunk) - 0.5 * voxelMm, daughterMm = radiiMm[o.own];
    for (size_t k : o.line) {
      const Vec3 v = q[k] - o.centre;
      const double beyondMm = (v - v.dot(o.dir) * o.dir).norm() - wallMm;
      if (beyondMm >= 0 && radiiMm[k] > std::max(beyondMm, daughterMm + 0.5 * voxelMm)) radiiMm[k] = daughterMm;
    }
  }
}

}  // namespace vs::centreline_detail
