#include "tracking/centreline.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "features/features3d.h"
#include "features/vesselness.h"
#include "tracking/centreline_junctions.h"
#include "tracking/cross_section.h"
#include "tracking/own_lobe.h"
#include "tracking/ray_walls.h"
#include "tracking/wide_trunk.h"
#include "util/parallel.h"
#include "volume/plane_basis.h"

namespace vs {

namespace {

// Rays live in "physical index" space q = index * spacing (mm, axis-aligned): distances are mm.
// Samples are taken at the continuous index q / spacing.
struct RayField {
  TrilinearSampler sample;
  Vec3 spacing, invSpacing;
  Vec3 hiIndex;                    // largest index inside the volume
  double capMm = 0;                // longest ray length (the volume's diagonal)
  std::vector<double> cosA, sinA;  // the rays' angles in the normal plane (an even count >= 4)
  bool inside(const Vec3& q) const { return sample.inside(q.cwiseProduct(invSpacing)); }
  // The largest r <= rMax with index + r * d inside the volume (d: index units per mm).
  double rayEnd(const Vec3& index, const Vec3& d, double rMax) const {
    double r = rMax;
    for (int a = 0; a < 3; ++a) {
      if (d[a] > 0) r = std::min(r, (hiIndex[a] - index[a]) / d[a]);
      if (d[a] < 0) r = std::min(r, -index[a] / d[a]);
    }
    return std::max(r, 0.0);
  }
};

// Buffers of castRays, one set per worker (no allocation per point).
struct RayScratch {
  std::vector<Vec3> dirs, dirsIndex;  // unit directions (mm), the same in index units per mm
  std::vector<double> far, end, radius, found;
};

struct RayResult {
  int hits = 0;
  int rays = 0;          // rays marched
  int escaped = 0;       // marched rays without a crossing or more than twice the median long
  Vec3 offset{0, 0, 0};  // least-squares centre offset from the chord midpoints
  double medianRadius = 0;
  double medianChord = 0;  // of the chords with both rays crossing
  double longestRay = 0;   // of the rays that crossed
  bool nearWall = false;   // centred by castRays' rule 2 (hits 0: its radius is left as before)
};

// Touching lumens (issue 21, kissing vessels; session 14 kiss4): two tubes that touch or nearly
// touch are one region above the half-way level, so a ray from one tube's centre runs through the
// neck into the other and the chords pull the point towards the pair's middle. A ray whose value,
// on the lumen side of the level, first falls `depth` below the most lumen-like value it has seen
// and then rises `depth` above the least lumen-like value after that has crossed a saddle between
// two lumens: it ends at that least lumen-like sample (the neck), as if it crossed the wall there.
class SaddleStop {
 public:
  SaddleStop(double centre, bool bright, double depth) : bright_(bright), depth_(depth), best_(lumenward(centre)) {}
  // The next sample (at r along the ray, not yet beyond the level); true at a saddle (`neck()`).
  // Samples are `step` apart.
  bool feed(double r, double val, double step) {
    const double x = lumenward(val);
    if (!(depth_ > 0)) return false;
    if (justLow_) afterLow_ = x, justLow_ = false;
    if (!fell_) {
      if (x > best_) best_ = x;
      if (best_ - x >= depth_) fell_ = true, setLow(r, x);
    } else if (x < low_) {
      setLow(r, x);
    }
    last_ = x;
    step_ = step;
    return fell_ && x - low_ >= depth_;
  }
  // The neck: the least lumen-like sample, moved to the vertex of the parabola through it and its
  // two neighbours (the samples are a voxel apart, the neck under one wide).
  double neck() const {
    const double curv = beforeLow_ - 2 * low_ + afterLow_;
    const double shift = curv > 0 ? std::clamp(0.5 * (beforeLow_ - afterLow_) / curv, -0.5, 0.5) : 0.0;
    return neck_ + shift * step_;
  }

 private:
  double lumenward(double v) const { return bright_ ? v : -v; }
  void setLow(double r, double x) { beforeLow_ = last_, low_ = x, neck_ = r, afterLow_ = x, justLow_ = true; }
  bool bright_;
  double depth_, best_, last_ = best_, low_ = 0, neck_ = 0, beforeLow_ = 0, afterLow_ = 0, step_ = 0;
  bool fell_ = false, justLow_ = false;
};

// Marches the rays of sc.dirsIndex from ci (index) out to length `len` (mm) to their first crossing
// of `level` (sc.radius, -1 where none; sc.found), or to a saddle (SaddleStop, saddle depth
// `saddle` x |centre - level|; 0: none); returns the number of chords whose two rays cross.
int marchRays(const RayField& f, const Vec3& ci, double centre, double level, double len, double step, size_t stride,
              RayScratch& sc, double saddle) {
  const size_t un = sc.dirsIndex.size();
  const bool bright = centre > level;
  auto beyond = [&](double val) { return bright ? val < level : val > level; };
  for (size_t k = 0; k < un; ++k) sc.end[k] = f.rayEnd(ci, sc.dirsIndex[k], len);  // the last point inside
  sc.found.clear();
  sc.radius.assign(un, -1.0);
  for (size_t k = 0; k < un; k += stride) {
    // March out in steps to the first sample beyond the level, halve that step once, and
    // interpolate linearly within the half that holds the crossing. The samples are those of a
    // march with half the step that stops at the same crossing (the same radius), ~half as many.
    const Vec3& d = sc.dirsIndex[k];
    double prev = centre;
    SaddleStop neck(centre, bright, saddle * std::abs(centre - level));
    for (int i = 1;; ++i) {
      double r = i * step;
      if (r > sc.end[k]) break;
      double val = f.sample.at(ci + r * d);
      if (!beyond(val)) {
        prev = val;
        if (!neck.feed(r, val, step)) continue;
        sc.radius[k] = neck.neck();
        sc.found.push_back(sc.radius[k]);
        break;
      }
      // The crossing lies in (r - step, r]: one more sample halves that.
      const double h = 0.5 * step;
      const double mid = f.sample.at(ci + (r - h) * d);
      if (beyond(mid)) {
        r -= h;
        val = mid;
      } else {
        prev = mid;
      }
      const double a = prev - level, b = val - level;
      sc.radius[k] = r - h + h * (a != b ? std::clamp(a / (a - b), 0.0, 1.0) : 0.5);
      sc.found.push_back(sc.radius[k]);
      break;
    }
  }
  int both = 0;
  for (size_t k = 0; k < un / 2; k += stride) both += sc.radius[k] >= 0 && sc.radius[k + un / 2] >= 0;
  return both;
}

// Casts the rays of the plane normal to `t` from `c`; see centreline.h. `surroundings` is the
// median value at the far ends of all rays: measured when NaN (a point's first cast) and kept for
// its later casts, since a point moves by about a voxel while the far ends lie maxRadiusMm away.
// `stride` 2 marches every second ray only (the ray count is then a multiple of 4, so every
// marched ray keeps its opposite).
RayResult castRays(const RayField& f, const Vec3& c, const Vec3& tangent, const CentrelineOptions& o, double step,
                   double& surroundings, double& rayMm, double& radiusBefore, RayScratch& sc, size_t stride,
                   double* farTwice = nullptr, double fromForkMm = 0) {
  RayResult res;
  Vec3 t = tangent.norm() > 0 ? tangent.normalized() : Vec3(0, 0, 1);
  const PlaneBasis basis = planeBasis(t);
  const Vec3 &u = basis.u, &v = basis.v;
  const size_t un = f.cosA.size();
  const int n = static_cast<int>(un);
  sc.dirs.resize(un);
  sc.dirsIndex.resize(un);
  sc.far.resize(un);
  sc.end.resize(un);
  sc.radius.assign(un, -1.0);
  const Vec3 ci = c.cwiseProduct(f.invSpacing);
  const double centre = f.sample.at(ci);
  for (size_t k = 0; k < un; ++k) {
    sc.dirs[k] = f.cosA[k] * u + f.sinA[k] * v;
    sc.dirsIndex[k] = sc.dirs[k].cwiseProduct(f.invSpacing);
  }
  const int marched = n / static_cast<int>(stride);
  auto march = [&](double level, double len) {
    return marchRays(f, ci, centre, level, len, step, stride, sc, o.saddleContrast);
  };
  // The point's radius before its cast grew: the median crossing when at least half the rays
  // crossed, else +infinity (no wall within the first length: a wide lumen).
  auto radiusFound = [&]() {
    if (static_cast<int>(sc.found.size()) * 2 < marched) return std::numeric_limits<double>::infinity();
    const size_t m = sc.found.size() / 2;
    std::nth_element(sc.found.begin(), sc.found.begin() + static_cast<std::ptrdiff_t>(m), sc.found.end());
    return sc.found[m];
  };
  if (std::isnan(surroundings)) {
    // The median value at the rays' far ends (each cut at the volume's edge) for a length R.
    auto farMedian = [&](double R) {
      for (size_t k = 0; k < un; ++k) sc.far[k] = f.sample.at(ci + f.rayEnd(ci, sc.dirsIndex[k], R) * sc.dirsIndex[k]);
      std::nth_element(sc.far.begin(), sc.far.begin() + n / 2, sc.far.end());
      return sc.far[un / 2];
    };
    rayMm = o.maxRadiusMm;
    surroundings = farMedian(rayMm);
    const double first = surroundings;
    if (farTwice) *farTwice = farMedian(std::min(2 * rayMm, f.capMm));
    // Grow the cast while the far ends were still inside a wide lumen: the value at twice the
    // length is much further from the point's value than the one at the current length.
    while (o.growContrast > 0 && rayMm < f.capMm) {
      const double longer = std::min(2 * rayMm, f.capMm);
      const double far2 = farMedian(longer);
      if (std::abs(centre - far2) <= o.growContrast * std::abs(centre - surroundings)) break;
      rayMm = longer, surroundings = far2;
    }
    // ... unless the wall at the grown cast's level lies within the first length in at least half
    // the rays (a narrower lumen whose far ends lay in a darker or brighter material farther out,
    // a bronchus with lung at 15 mm and soft tissue at 30): then the first cast stays.
    if (rayMm > o.maxRadiusMm &&
        static_cast<int>((march(0.5 * (centre + surroundings), o.maxRadiusMm), sc.found.size())) * 2 >= marched)
      rayMm = o.maxRadiusMm, surroundings = first;
    if (rayMm > o.maxRadiusMm && centre != first) {
      march(0.5 * (centre + first), o.maxRadiusMm);
      radiusBefore = radiusFound();
    }
  }
  const double bg = surroundings;
  if (centre == bg) return res;
  const double level = 0.5 * (centre + bg);
  // Near the wall of a wide lumen the rays towards the far wall find no crossing within the
  // length: while fewer than half the chords have both rays crossing, the length is doubled (up to the cap).
  for (;;) {
    const int both = march(level, rayMm);
    if (o.growContrast <= 0 || !o.growOnEscapes || both * 4 >= marched || rayMm >= f.capMm) break;
    if (std::isnan(radiusBefore)) radiusBefore = radiusFound();
    rayMm = std::min(2 * rayMm, f.capMm);
  }
  // A wide lumen under a bias: each ray's wall at its own half-way level (ray_walls.h).
  centreline_detail::localRayWalls(f.sample, ci, sc.dirsIndex, centre, level, step, stride, o.wideRadii * o.maxRadiusMm,
                                   sc.radius, sc.found);
  res.hits = static_cast<int>(sc.found.size());
  res.rays = n / static_cast<int>(stride);
  res.escaped = res.rays - res.hits;
  if (sc.found.empty()) return res;
  const size_t mid = sc.found.size() / 2;
  std::nth_element(sc.found.begin(), sc.found.begin() + static_cast<std::ptrdiff_t>(mid), sc.found.end());
  res.medianRadius = sc.found[mid];
  // Chord k / k + n/2 through c: its midpoint lies at (r_k - r_opp) / 2 along d_k; the centre's
  // offset o satisfies o . d_k = that for every chord (exact for a circle), solved by least squares.
  // A ray more than twice the median long has left the lumen's cross-section (into a branch at a
  // bifurcation, along a neighbouring vessel): its chord would pull the centre there. Far off the
  // axis of a wide lumen, though, the rays towards the far wall are all more than twice the
  // median long; a chord through the point is at most twice as long as the median chord there
  // (for a circle, unless the point lies within 0.13 R of the wall), so where the rule above
  // leaves fewer than half the chords, a chord is kept unless it is more than twice the median chord long.
  const double longRay = 2.0 * res.medianRadius;
  for (size_t k = 0; k < un; k += stride) {
    res.escaped += sc.radius[k] > longRay;
    res.longestRay = std::max(res.longestRay, sc.radius[k]);
  }
  sc.found.clear();
  for (size_t k = 0; k < un / 2; k += stride)
    if (sc.radius[k] >= 0 && sc.radius[k + un / 2] >= 0) sc.found.push_back(sc.radius[k] + sc.radius[k + un / 2]);
  double longChord = 0;
  if (!sc.found.empty()) {
    const size_t cm = sc.found.size() / 2;
    std::nth_element(sc.found.begin(), sc.found.begin() + static_cast<std::ptrdiff_t>(cm), sc.found.end());
    res.medianChord = sc.found[cm];
    longChord = 2.0 * res.medianChord;
  }
  Eigen::Matrix2d A;
  Eigen::Vector2d b;
  // Rule 2: by the wall of a narrow round lumen (11129's root trunk: 3.4 voxels off the axis, radius 3.7) the rays to
  // the far wall are all over twice the median ray: rule 0 kept too few chords, the point stayed. Where the section is
  // closed (every ray crossed, no chord over 1.5x the median), round (chordsAgree) and away from forks (as the own
  // lobe rule: a fused section looks closed too), every chord locates the centre; the point steps, radius as before.
  bool closed = res.hits == res.rays && fromForkMm > o.lobeForkRadii * res.medianRadius;
  for (size_t k = 0; k < un / 2 && closed; k += stride)
    closed = sc.radius[k] + sc.radius[k + un / 2] <= 0.75 * longChord;
  int chords = 0, rule = 0;
  for (; rule < 3 && chords * 2 < res.rays / 2; ++rule) {
    if (rule == 1 && rayMm <= o.maxRadiusMm) continue;  // not in a lumen wider than the first cast
    if (rule == 2 && !closed) break;
    A.setZero(), b.setZero(), chords = 0;
    for (size_t k = 0; k < un / 2; k += stride) {
      const double r1 = sc.radius[k], r2 = sc.radius[k + un / 2];
      if (r1 < 0 || r2 < 0) continue;
      if (rule == 0 ? r1 > longRay || r2 > longRay : r1 + r2 > longChord) continue;
      const Eigen::Vector2d d2(sc.dirs[k].dot(u), sc.dirs[k].dot(v));
      A += d2 * d2.transpose();
      b += d2 * (0.5 * (r1 - r2));
      ++chords;
    }
  }
  if (chords * 2 < res.rays / 2 || std::abs(A.determinant()) < 1e-9) {
    res.hits = 0;  // too few chords to locate the centre: leave the point
    return res;
  }
  const Eigen::Vector2d o2 = A.ldlt().solve(b);
  if (rule == 3 && !centreline_detail::chordsAgree(sc.dirs, sc.radius, u, v, stride, o2, 0.25 * step)) {
    res.hits = 0;  // not one round lumen (a wide trunk's wall cut obliquely): leave the point
    return res;
  }
  res.offset = o2[0] * u + o2[1] * v;
  if (rule == 3) res.hits = 0, res.nearWall = true;
  return res;
}

// Rays of the plane normal to `tangent` at c (mm) that find no crossing of the level half-way
// between the value at c and `surroundings` within discMm: they leave a lumen of that radius
// (into a sibling or the parent where the section is fused).
int discEscapes(const RayField& f, const Vec3& c, const Vec3& tangent, double discMm, double surroundings,
                double step) {
  Vec3 t = tangent.norm() > 0 ? tangent.normalized() : Vec3(0, 0, 1);
  const PlaneBasis basis = planeBasis(t);
  const Vec3 &u = basis.u, &v = basis.v;
  const Vec3 ci = c.cwiseProduct(f.invSpacing);
  const double centre = f.sample.at(ci);
  if (std::isnan(surroundings) || centre == surroundings) return 0;
  const double level = 0.5 * (centre + surroundings);
  const bool bright = centre > surroundings;
  int escaped = 0;
  for (size_t k = 0; k < f.cosA.size(); ++k) {
    const Vec3 d = (f.cosA[k] * u + f.sinA[k] * v).cwiseProduct(f.invSpacing);
    const double end = std::min(discMm, f.rayEnd(ci, d, discMm));
    bool crossed = false;
    for (double r = step; r <= end + 1e-9 && !crossed; r += step) {
      const double val = f.sample.at(ci + r * d);
      crossed = bright ? val < level : val > level;
    }
    escaped += !crossed && end >= discMm - 1e-9;  // a ray cut by the volume's edge is no escape
  }
  return escaped;
}

// The lumen's cross-section at c (mm) in the plane normal to `tangent`: its widest and narrowest chord over `chords`
// directions spread over half a turn, each chord the distance between the crossings of the level half-way between the
// value at c and `surroundings` on both sides (linearly interpolated between samples). False where a ray finds no
// crossing within maxMm (or before the volume's edge). `widestDir`, when given, receives the widest chord's direction
// and its walls' distances from c along it (plus) and against it (minus).
bool sectionWidths(const RayField& f, const Vec3& c, const Vec3& tangent, double surroundings, double maxMm,
                   double step, double& widest, double& narrowest, Vec3* widestDir = nullptr, double* plus = nullptr,
                   double* minus = nullptr) {
  constexpr int chords = 12;
  const Vec3 t = tangent.norm() > 0 ? tangent.normalized() : Vec3(0, 0, 1);
  const PlaneBasis basis = planeBasis(t);
  const Vec3 &u = basis.u, &v = basis.v;
  const Vec3 ci = c.cwiseProduct(f.invSpacing);
  const double centre = f.sample.at(ci);
  if (std::isnan(surroundings) || centre == surroundings) return false;
  const double level = 0.5 * (centre + surroundings);
  const bool bright = centre > surroundings;
  auto wall = [&](const Vec3& dirMm, double& out) {
    const Vec3 d = dirMm.cwiseProduct(f.invSpacing);
    const double end = f.rayEnd(ci, d, maxMm);
    double prev = centre;
    for (double r = step; r <= end + 1e-9; r += step) {
      const double val = f.sample.at(ci + r * d);
      if (bright ? val < level : val > level) {
        out = r - step * (level - val) / (prev - val);  // the crossing between the last two samples
        return true;
      }
      prev = val;
    }
    return false;
  };
  widest = 0, narrowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < chords; ++k) {
    const double a = M_PI * k / chords;
    const Vec3 d = std::cos(a) * u + std::sin(a) * v;
    double r1 = 0, r2 = 0;
    if (!wall(d, r1) || !wall(-d, r2)) return false;
    if (widestDir && r1 + r2 > widest) *widestDir = d, *plus = r1, *minus = r2;
    widest = std::max(widest, r1 + r2), narrowest = std::min(narrowest, r1 + r2);
  }
  return true;
}

// A point's last cast: where, the step it gave and its median ray length. A point whose last
// step and whose drift since (smoothing included) are both under settleMm has settled: cast
// again, its rays would give the same step to within that, so it is not (most points settle
// after two rounds; the ones near ends and branches keep moving and keep being cast).
struct LastCast {
  Vec3 at{0, 0, 0};
  double stepMm = std::numeric_limits<double>::infinity();
  double radiusMm = 0;
};

// The rays' field of `vol`: `rays` (even, at least 4) directions per normal plane.
RayField makeRayField(const VolumeF32& vol, int rays) {
  const Geometry& g = vol.geometry();
  const Vec3 sp = g.spacing;
  RayField field{
      TrilinearSampler(vol),
      sp,
      sp.cwiseInverse(),
      Vec3(static_cast<double>(g.dims[0] - 1), static_cast<double>(g.dims[1] - 1), static_cast<double>(g.dims[2] - 1)),
      0,
      {},
      {}};
  field.capMm = Vec3(static_cast<double>(g.dims[0]), static_cast<double>(g.dims[1]), static_cast<double>(g.dims[2]))
                    .cwiseProduct(sp)
                    .norm();
  rays = std::max(4, rays - rays % 2);
  for (int k = 0; k < rays; ++k) {
    field.cosA.push_back(std::cos(2 * M_PI * k / rays));
    field.sinA.push_back(std::sin(2 * M_PI * k / rays));
  }
  return field;
}

// A point whose rays do not resolve its lumen (wide: the median at twice the first length is much further from the
// point's value than the one at the first length, or fewer than half its chords find both walls) is centred and
// measured in its cross-section instead (cross_section.h): it moves to the centre of the largest circle inscribed in
// its lobe of the section. False where that does not apply or finds nothing (the rays' result stands). Trees narrow
// away from the root: a section wider than the root's lumen (`rootRadiusMm`, the largest radius within 2 first ray
// lengths of the root, + a voxel; < 0: the point lies within that reach) is not this path's lumen (a faint bronchus in
// the lung, whose value hardly differs from the lung's: the section is the lung's; the README chest CTA airway tree got
// radii of 11-13 mm in its right lung with the largest radius of the points before a point instead). And a lumen whose
// inscribed radius is under wideRadii x the first ray length is one the rays resolve from any point inside it (its far
// wall lies within 2 radii): their escapes there come from a junction or an end, which the rays' rules handle (thin
// trees as before). `polarity`: the root's lumen against its background (+1 bright, -1 dark, 0 unknown): a point darker
// than its background in a bright tree (or brighter in a dark one) lies outside the lumen, and its section would be the
// background's (the carotid MRA: 3 points pulled out of the vessel). `stays`: the point is not moved (a placed point in
// the last cast, which measures it): a section whose circle does not hold the point's own lumen (sectionHoldsPoint: a
// daughter's first points just beyond a wide trunk's wall, the plane cutting into the trunk through the ostium) does
// not measure it; its rays do (the median of those that crossed: the daughter's wall; session 18).
bool sectionOf(const RayField& field, const CentrelineOptions& o, const Vec3& q, const Vec3& tangent,
               double surroundings, double farTwice, const RayResult& r, double rootRadiusMm, int polarity, bool stays,
               SectionScratch& section, SectionResult& s) {
  if (o.sectionContrast <= 0) return false;
  const double value = field.sample.at(q.cwiseProduct(field.invSpacing));
  const bool wider = std::abs(value - surroundings) * o.sectionContrast < std::abs(value - farTwice) &&
                     std::abs(value - surroundings) < std::abs(surroundings - farTwice);
  if (!wider && r.hits * 2 >= r.rays) return false;
  if (polarity * (value - (wider ? farTwice : surroundings)) < 0) return false;
  s = sectionCentre(field.sample, field.spacing, q, tangent, value, wider ? farTwice : surroundings, 2 * o.maxRadiusMm,
                    section);
  return s.ok && s.inscribedMm > o.wideRadii * o.maxRadiusMm &&
         (rootRadiusMm < 0 || s.radiusMm <= rootRadiusMm + field.spacing.minCoeff()) &&
         (!stays || sectionHoldsPoint(s));
}

// The root's lumen against its background (+1 bright, -1 dark, 0 equal): its value against the median
// at the first ray length, or at twice that where it is further (a root in a lumen wider than the rays).
// Casts the root once (its surroundings, as its first cast in the rounds would).
int rootPolarity(const RayField& field, const CentrelineOptions& o, const Vec3& q0, const Vec3& t0, double step,
                 double& surroundings, double& rayMm, double& radiusBefore, double& farTwice) {
  RayScratch rs;
  castRays(field, q0, t0, o, step, surroundings, rayMm, radiusBefore, rs, 1, &farTwice);
  const double v0 = field.sample.at(q0.cwiseProduct(field.invSpacing));
  const double bg0 = std::abs(v0 - farTwice) > std::abs(v0 - surroundings) ? farTwice : surroundings;
  return v0 > bg0 ? 1 : v0 < bg0 ? -1 : 0;
}

// A wide section between two narrow tree neighbours is not a wide lumen (a faint bronchus whose
// section is the lung around it: the README chest CTA airway tree had one point of 10.3 mm between
// two of 1.4 mm): it keeps its rays' radius.
void isolatedSectionsKeepRays(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                              const std::vector<uint8_t>& sectioned, const std::vector<double>& rayRadius,
                              std::vector<double>& radii) {
  for (size_t k = 1; k < radii.size(); ++k) {
    if (!sectioned[k]) continue;
    bool wideNeighbour = radii[static_cast<size_t>(parent[k])] >= 0.5 * radii[k];
    for (int32_t c : children[k]) wideNeighbour = wideNeighbour || radii[static_cast<size_t>(c)] >= 0.5 * radii[k];
    if (!wideNeighbour) radii[k] = rayRadius[k];
  }
}

// Tangent at point i from two tree steps on either side (one where the tree branches or ends).
Vec3 treeTangent(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                 const std::vector<Vec3>& q, size_t i) {
  size_t up = i, down = i;
  for (int k = 0; k < 2 && parent[up] >= 0; ++k) up = static_cast<size_t>(parent[up]);
  for (int k = 0; k < 2 && children[down].size() == 1; ++k) down = static_cast<size_t>(children[down][0]);
  if (up == down) return Vec3(0, 0, 1);
  return Vec3(q[down] - q[up]);
}

// One smoothing step: every inner point (not an end, not frozen) moves `weight` of the way to the
// mean of itself and its tree neighbours; `next` is scratch.
void smoothTree(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                const std::vector<uint8_t>& frozen, double weight, std::vector<Vec3>& q, std::vector<Vec3>& next) {
  next = q;
  for (size_t i = 1; i < q.size(); ++i) {
    if (children[i].empty() || frozen[i]) continue;  // ends stay where the centring put them
    Vec3 m = q[static_cast<size_t>(parent[i])];
    for (int32_t c : children[i]) m += q[static_cast<size_t>(c)];
    m /= static_cast<double>(children[i].size() + 1);
    next[i] = (1 - weight) * q[i] + weight * m;
  }
  std::swap(q, next);
}

// The rounds' state placeWideTrunk reads (centreline.h: wideTrunk).
struct WideState {
  const std::vector<LastCast>& last;
  const std::vector<uint8_t>&sectioned, &nearRoot;
  const std::vector<double>&sectionLevel, &surroundings;
  double rootRadiusMm;
  int polarity;
};

// Wide points (centred by their section, or rays as long as a section's inscribed radius must be,
// with the sections' guards: no wider than the root's lumen + a voxel beyond its reach, the root's
// polarity: a faint bronchus's rays reach the lung), their level (the section's, else the rays')
// and radius, then placeWideTrunk (wide_trunk.h); `copyPoint(k)` appends a copy of point k to the
// rounds' state.
void placeWide(const RayField& field, const CentrelineOptions& o, const WideState& st, std::vector<int32_t>& parent,
               std::vector<std::vector<int32_t>>& children, std::vector<Vec3>& q, std::vector<uint8_t>& frozen,
               std::vector<uint8_t>& placed, centreline_detail::KeptWide& kept,
               const std::function<size_t(size_t)>& copyPoint) {
  const size_t n = q.size();
  const Vec3& sp = field.spacing;
  std::vector<double> radius(n), level(n);
  std::vector<uint8_t> wide(n);
  // The root's trunk is wide from wideTrunkVoxels on however fine the spacing: its daughters run a
  // trunk radius inside its lumen, where their rays centre them on its axis, so a path ran up the axis
  // a radius past its junction and cut back (10706: radius 8.2 voxels = 5.8 mm under wideRadii x
  // maxRadiusMm = 7.5 mm; 86.5 % within a voxel, 5 points on a neighbour). Only a lumen of at least
  // trunkShare of the root's: every point over 7 voxels wide put 503's and 542's daughters through
  // placeWideTrunk (96.8 -> 81.8 %, 100 -> 95.1 %).
  constexpr double wideTrunkVoxels = 7, trunkShare = 0.6;
  const double wideMm = o.wideRadii * o.maxRadiusMm, trunkWideMm = std::min(wideMm, wideTrunkVoxels * sp.minCoeff());
  for (size_t k = 0; k < n; ++k) {
    radius[k] = st.last[k].radiusMm;
    const double value = field.sample.at(q[k].cwiseQuotient(sp));
    level[k] = st.sectioned[k] ? st.sectionLevel[k] : 0.5 * (value + st.surroundings[k]);
    const bool trunk = st.rootRadiusMm > 0 && radius[k] >= trunkShare * st.rootRadiusMm;
    const bool rays = radius[k] > (trunk ? trunkWideMm : wideMm) &&
                      (st.nearRoot[k] || radius[k] <= st.rootRadiusMm + sp.minCoeff()) &&
                      st.polarity * (value - st.surroundings[k]) >= 0 && std::isfinite(level[k]);
    wide[k] = st.sectioned[k] ? 1 : rays ? 2 : 0;
  }
  centreline_detail::keepWideRuns(parent, children, wide);
  placed.assign(n, 0);
  auto copy = [&](size_t k) {
    radius.push_back(radius[k]);
    level.push_back(level[k]);
    wide.push_back(wide[k]);
    placed.push_back(0);
    return copyPoint(k);
  };
  centreline_detail::placeWideTrunk({field.sample, sp, wide, radius, level, st.polarity}, parent, children, q, frozen,
                                    placed, copy, kept.radiusMm, &kept.junctions, &kept.ostia);
  kept.level = std::move(level);
}

// After the final centring: the wide trunk's junctions placed again from their daughters' centred points
// (wide_trunk.h: replaceJunctions), then which placed points confineToLumen leaves (unkeepShallow). The fused
// section's rays measure the blob, not the child's lumen: the points placed in their own lobe take the child's radius.
void afterFinalCentring(const RayField& field, const centreline_detail::KeptWide& kept, int polarity,
                        const std::vector<double>& ownLobeRadius, std::vector<Vec3>& q, RefinedCentreline& out) {
  centreline_detail::replaceJunctions(field.sample, field.spacing, kept.junctions, q);
  centreline_detail::unkeepShallow(field.sample, field.spacing, q, kept.radiusMm, kept.level, out.radiiMm, polarity,
                                   out.wideTrunk);
  centreline_detail::ostiumRadii(q, kept.ostia, field.spacing.minCoeff(), out.radiiMm);
  for (size_t k = 0; k < ownLobeRadius.size() && k < q.size(); ++k)
    if (!std::isnan(ownLobeRadius[k])) out.radiiMm[k] = ownLobeRadius[k];
}

// Touching lumens (centreline.h: lobeValley): a point some of whose rays escaped (through a contact into a touching
// tube, or at a fork), or whose longest ray is lobeLongRay x the median long away from forks (`fromForkMm` along the
// tree: a contact too thin for the escape rule), or, away from forks alike, whose lumen another traced path's touches
// with that path's voxel in the other lobe (`touching`, touchingPaths: a neck stopping every ray short of the wall;
// session 37, 524), and whose section holds two lobes (a pair of touching tubes; more lobes are not that: a junction of
// several, or a wide lumen with structure, where the README chest CTA airway's junction point moved to 0.73 mm of the
// wall) moves to the centre of its own lobe (own_lobe.h: the lobe of its path voxel `anchor`) instead of its chords'
// centre, where that lobe is no nearer a touching path's voxel than the anchor (lobeNearerTouching) and one the rays
// resolve (its radius at most wideRadii x the first ray length; wider lumens are the sections' and the wide trunk's).
// The step's cap is the rays'. Positions in mm; returns the lobes found (0: none).
int ownLobeOffset(const RayField& field, const CentrelineOptions& o, const Vec3& q, const Vec3& tangent,
                  const Vec3& anchor, const Vec3* ends, double surroundings, double fromForkMm, const Vec3* touching,
                  const RayResult& r, LobeScratch& lobe, Vec3& off) {
  const double value = field.sample.at(q.cwiseProduct(field.invSpacing));
  const bool awayFromForks = fromForkMm > o.lobeForkRadii * r.medianRadius;
  const bool longRay = o.lobeLongRay > 0 && r.longestRay > o.lobeLongRay * r.medianRadius && awayFromForks;
  const bool rays = r.escaped > 0 || longRay;  // else a touching path's voxel (touchingPaths) in the other lobe
  if (!(o.lobeValley > 0) || (!rays && !(touching && o.lobeTouching && awayFromForks)) || std::isnan(surroundings) ||
      value == surroundings)
    return 0;
  const double halfMm = std::min(o.maxRadiusMm, 2.5 * r.medianRadius + 2 * field.spacing.minCoeff());
  const double level = 0.5 * (value + surroundings);
  const LobeResult l =
      ownLobe(field.sample, field.spacing, q, tangent, anchor, level, value > surroundings, halfMm, o.lobeValley, lobe);
  const auto inOther = [&](const Vec3* at, size_t count) {
    return neighboursInOtherLobe(field.sample, field.spacing, q, tangent, at, level, value > surroundings, halfMm,
                                 o.lobeValley, l.centre, lobe, count);
  };
  if (l.lobes == 2 && l.radiusMm <= o.wideRadii * o.maxRadiusMm && !(ends && inOther(ends, 2)) &&
      (rays || inOther(touching, 1)) && !lobeNearerTouching(l.centre, anchor, touching, 0.5 * field.spacing.norm()))
    off = l.centre - q;
  return l.lobes;
}

// A centring step clamped: larger steps only where the cast grew (a lumen wider than the first cast; in the chest
// CTA's trachea, 18 mm across, they moved a point near the carina to within 0.75 mm of the wall), and a grown cast
// moves the point at most by its radius from before the growth (a thin lumen's point whose rays grew into a wider
// lumen beside it). stepBound is that bound. The final centring takes no section move beyond it: a section carrying
// a rested point further was read across a wider lumen beside its own (5605's daughter point: 10 mm into the trunk).
double stepBound(const CentrelineOptions& o, double rayMm, double radiusBefore, double medianChord) {
  double maxStep = rayMm > o.maxRadiusMm ? std::max(o.maxStepMm, o.maxStepRadii * 0.5 * medianChord) : o.maxStepMm;
  return radiusBefore < maxStep ? std::max(o.maxStepMm, radiusBefore) : maxStep;
}
Vec3 clampedStep(const CentrelineOptions& o, double rayMm, double radiusBefore, double medianChord, Vec3 off) {
  const double maxStep = stepBound(o, rayMm, radiusBefore, medianChord);
  if (off.norm() > maxStep) off *= maxStep / off.norm();
  return off;
}

// Forks re-branched (o.splitForks) and their junction zones placed (centreline_junctions.h) on the
// centred points; copyPoint(k) appends a copy of point k to every per-point array (q, surroundings and
// last included) and returns its index. Returns per point the child's own radius where the point went
// to its own lobe of a fused section (NaN elsewhere).
template <class CopyPoint>
std::vector<double> placeForks(const RayField& field, const CentrelineOptions& o, double step,
                               const std::vector<double>& surroundings, const std::vector<LastCast>& last,
                               std::vector<int32_t>& parent, std::vector<std::vector<int32_t>>& children,
                               std::vector<Vec3>& q, std::vector<uint8_t>& frozen, CopyPoint&& copyPoint,
                               const std::function<Vec3(size_t)>& raw) {
  const double minSpacing = field.spacing.minCoeff();
  std::vector<double> radius(q.size());
  for (size_t k = 0; k < q.size(); ++k) radius[k] = last[k].radiusMm;
  auto tangent = [&](size_t k) { return treeTangent(parent, children, q, k); };
  auto fused = [&](size_t k, double discMm) {
    return discEscapes(field, q[k], tangent(k), discMm, surroundings[k], step) >= 2;
  };
  auto widths = [&](size_t k, double maxMm, double& widest, double& narrowest) {
    return sectionWidths(field, q[k], tangent(k), surroundings[k], maxMm, 0.5 * step, widest, narrowest);
  };
  auto lobes = [&](size_t k, double maxMm, Vec3& dir, double& plus, double& minus, double& narrowest) {
    double widest = 0;
    return sectionWidths(field, q[k], tangent(k), surroundings[k], maxMm, 0.5 * step, widest, narrowest, &dir, &plus,
                         &minus);
  };
  if (o.splitForks) {
    auto copy = [&](size_t k) {
      radius.push_back(radius[k]);
      return copyPoint(k);
    };
    centreline_detail::splitForks(parent, children, q, frozen, radius, minSpacing, fused, copy, widths, raw, lobes,
                                  field.spacing);
  }
  std::vector<double> ownLobeRadius(q.size(), std::numeric_limits<double>::quiet_NaN());
  const double wideMm = o.wideTrunk && o.sectionContrast > 0 ? o.wideRadii * o.maxRadiusMm : HUGE_VAL;  // placeWide's
  auto lobeCentre = [&](size_t k, const Vec3& d, double outerMm, double innerMm, double maxMm, Vec3& centre) {
    return centreline_detail::lobeCentreFromWalls(field.sample, field.spacing, q[k], tangent(k), surroundings[k],
                                                  0.5 * step, d, outerMm, innerMm, maxMm, centre);
  };
  centreline_detail::placeJunctions({parent, children, radius, raw, field.spacing.maxCoeff(), lobeCentre}, q, frozen,
                                    minSpacing, fused, widths, lobes, &ownLobeRadius, wideMm);
  centreline_detail::placeFusedLobes({parent, children, radius, raw},
                                     {field.sample, field.spacing, o, surroundings, tangent}, q, frozen, ownLobeRadius);
  centreline_detail::balanceFreeForks(parent, children, frozen, q);  // the forks these left free
  return ownLobeRadius;
}

}  // namespace

RefinedCentreline centreline_detail::refineTree(const VolumeF32& vol, const CentrelineTree& tree,
                                                const CentrelineOptions& o, Progress& progress) {
  centreline_detail::validateRefineInput(vol, tree, o);
  size_t n = tree.points.size();  // grows where forks are re-branched (splitForks)
  const Vec3 sp = vol.geometry().spacing;
  const RayField field = makeRayField(vol, o.rays);
  RefinedCentreline out;
  // Ray step: the smallest spacing, halved once around the crossing (the crossing is located as
  // with a step of half a spacing, which gave the same phantom accuracy as a quarter).
  const double step = sp.minCoeff();
  std::vector<int32_t> parent = tree.parent, source(n);
  std::vector<std::vector<int32_t>> children(n);
  for (size_t i = 0; i < n; ++i) source[i] = static_cast<int32_t>(i);
  for (size_t i = 1; i < n; ++i) children[static_cast<size_t>(parent[i])].push_back(static_cast<int32_t>(i));
  std::vector<Vec3> q(n), next(n);
  for (size_t i = 0; i < n; ++i) q[i] = tree.points[i].cwiseProduct(sp);
  std::vector<double> surroundings(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> rayMm(n, o.maxRadiusMm);  // per point, set with its surroundings
  // Per point its radius before its cast first grew (NaN: it has not grown; +inf: no wall found).
  std::vector<double> radiusBefore(n, std::numeric_limits<double>::quiet_NaN());
  // Per point the median value at twice the first ray length (NaN until its first cast).
  std::vector<double> farTwice(n, std::numeric_limits<double>::quiet_NaN());
  auto tangent = [&](size_t i) { return treeTangent(parent, children, q, i); };
  std::vector<LastCast> last(n);
  std::vector<uint8_t> frozen(n, 0);   // junction zones placed by placeJunctions
  std::vector<uint8_t> cast(n, 0);     // per point: 1 cast, never centred by it; 2 centred by a cast
  std::vector<uint8_t> oneLobe(n, 0);  // per point: its last own-lobe look found one lobe (fitTwoTubes' touched points)
  const double settleMm = o.settleVoxels * sp.minCoeff();
  // The root's lumen: the points within 2 first ray lengths of the root along the tree (their
  // sections are taken as they are) and the largest radius among them, set before each round.
  std::vector<uint8_t> nearRoot = centreline_detail::nearRootPoints(tree, q, 2 * o.maxRadiusMm);
  // Per input point its distance along the input tree to the nearest branch point (ownLobeOffset).
  const std::vector<double> fromFork = alongTreeFromForks(tree.parent, q);
  double rootRadiusMm = 0;
  std::vector<uint8_t> sectioned(n, 0);      // per point: its last radius came from its section
  std::vector<double> rayRadius(n, 0.0);     // ... and its rays' radius then
  std::vector<double> sectionLevel(n, 0.0);  // ... and its section's half-way level
  const int polarity = out.polarity =
      rootPolarity(field, o, q[0], tangent(0), step, surroundings[0], rayMm[0], radiusBefore[0], farTwice[0]);
  bool measuring = false;  // the last cast, which only measures the placed (frozen) points
  auto centreSection = [&](size_t k, const RayResult& r, SectionScratch& section) {
    SectionResult s;
    if (!sectionOf(field, o, q[k], tangent(k), surroundings[k], farTwice[k], r, nearRoot[k] ? -1 : rootRadiusMm,
                   polarity, measuring && frozen[k], section, s))
      return false;
    LastCast& lc = last[k];
    rayRadius[k] = lc.radiusMm;
    sectioned[k] = 1, sectionLevel[k] = s.level;
    lc.radiusMm = s.radiusMm;
    if (k == 0 || frozen[k] || o.iterations == 0 || !field.inside(s.centre) ||
        (measuring && (s.centre - q[k]).norm() > stepBound(o, rayMm[k], radiusBefore[k], r.medianChord)))
      return true;
    next[k] = s.centre;
    lc.stepMm = (s.centre - q[k]).norm();
    return true;
  };
  const auto raw = [&](size_t k) { return tree.points[static_cast<size_t>(source[k])].cwiseProduct(sp); };
  // One centring step of every point but the root, marching every `stride`-th ray; `radii`, when given, also receives
  // every point's median ray length (the root's included) at its position before the step.
  auto centre = [&](size_t stride, std::vector<double>* radii) {
    std::vector<double> radius(n);  // the last casts' (0: none yet)
    for (size_t k = 0; k < n; ++k) radius[k] = last[k].radiusMm;
    const std::vector<int64_t> touching = centreline_detail::touchingPaths({parent, children, radius, raw}, o, q);
    rootRadiusMm = 0;
    for (size_t k = 0; k < n; ++k)
      if (nearRoot[k]) rootRadiusMm = std::max(rootRadiusMm, last[k].radiusMm);
    parallelFor(
        0, static_cast<int64_t>(n),
        [&](int64_t b, int64_t e) {
          RayScratch scratch;
          SectionScratch section;
          LobeScratch lobe;
          for (int64_t i = b; i < e; ++i) {
            const size_t k = static_cast<size_t>(i);
            next[k] = q[k];
            if ((k == 0 || frozen[k]) && !radii) continue;
            LastCast& lc = last[k];
            if (lc.stepMm < settleMm && (q[k] - lc.at).norm() < settleMm) {
              if (radii) (*radii)[k] = lc.radiusMm;
              continue;
            }
            const RayResult r = castRays(field, q[k], tangent(k), o, step, surroundings[k], rayMm[k], radiusBefore[k],
                                         scratch, stride, &farTwice[k], fromFork[static_cast<size_t>(source[k])]);
            // Too few chords (r.hits 0): radius 0 in the rounds, the last cast's by the rays that crossed.
            lc = {q[k], std::numeric_limits<double>::infinity(), r.hits > 0 || measuring ? r.medianRadius : 0.0};
            sectioned[k] = 0;
            const bool bySection = centreSection(k, r, section);
            cast[k] = std::max<uint8_t>(cast[k], bySection || r.hits * 2 >= r.rays || r.nearWall ? 2 : 1);
            if (radii) (*radii)[k] = lc.radiusMm;
            if (bySection) continue;
            if (k == 0 || frozen[k] || o.iterations == 0 || (r.hits * 2 < r.rays && !r.nearWall)) continue;
            Vec3 off = r.offset;
            const size_t child = plainChainChild(parent, children, k);  // 0: none
            const Vec3 ends[2] = {q[static_cast<size_t>(parent[k])], q[child]};
            const Vec3 touchVoxel = touching[k] >= 0 ? raw(static_cast<size_t>(touching[k])) : Vec3(Vec3::Zero());
            oneLobe[k] = 1 == ownLobeOffset(field, o, q[k], tangent(k), raw(k), child ? ends : nullptr, surroundings[k],
                                            fromFork[static_cast<size_t>(source[k])],
                                            touching[k] >= 0 ? &touchVoxel : nullptr, r, lobe, off);
            off = clampedStep(o, rayMm[k], radiusBefore[k], r.medianChord, off);
            if (field.inside(q[k] + off)) {
              next[k] = q[k] + off;
              lc.stepMm = off.norm();
            }
          }
        },
        o.pointsPerThread);
    std::swap(q, next);
  };
  centreline_detail::RoundSteps rounds;  // per point: whether its last two rounds stepped against each other
  for (int it = 0; it < o.iterations; ++it) {
    progress.report(static_cast<double>(it) / (o.iterations + 1), "centreline");
    rounds.begin(q);
    centre(it < o.coarseRounds && field.cosA.size() % 4 == 0 ? 2 : 1, nullptr);
    smoothTree(parent, children, frozen, o.smoothWeight, q, next);
    rounds.end(q);
  }
  // A copy keeps its source's state (position, surroundings, last cast); the caller links it.
  auto copyPoint = [&](size_t k) {
    auto dup = [k](auto& v) { v.push_back(v[k]); };
    q.push_back(q[k]), next.push_back(q[k]), parent.push_back(-1), children.emplace_back();
    dup(surroundings), dup(rayMm), dup(radiusBefore), dup(farTwice), dup(nearRoot), dup(sectioned), dup(rayRadius);
    dup(sectionLevel), dup(last), dup(frozen), dup(source), dup(cast), dup(oneLobe), rounds.copy(k);
    return n++;
  };
  std::vector<double> ownLobeRadius;  // per point placed in its own lobe of a fused section: the child's (NaN: none)
  if (o.junctions && o.iterations > 0)
    ownLobeRadius = placeForks(field, o, step, surroundings, last, parent, children, q, frozen, copyPoint, raw);
  centreline_detail::KeptWide kept;
  if (o.wideTrunk && o.sectionContrast > 0 && o.iterations > 0)
    placeWide(field, o, {last, sectioned, nearRoot, sectionLevel, surroundings, rootRadiusMm, polarity}, parent,
              children, q, frozen, out.wideTrunk, kept, copyPoint);
  // The final centring also gives the radii (the rays of a step that is, by now, small), so the
  // points are not cast a sixth time; with no iterations it only measures them. Its step smoothed, then kiss25's fit.
  out.radiiMm.resize(n);
  measuring = true;
  const std::vector<Vec3> rested = q;  // the rounds' positions
  centre(1, &out.radiiMm);
  const auto stepped = centreline_detail::smoothFinalStep(parent, children, frozen, o.smoothWeight, rested, q);
  centreline_detail::lineUncentred({parent, children, out.radiiMm, raw}, frozen, cast, o, sp, q, out.radiiMm);
  centreline_detail::fitTwoTubes({parent, children, out.radiiMm, raw}, frozen, o, field.sample, sp, q, &out.radiiMm,
                                 &oneLobe);
  centreline_detail::centreForkTrunks({parent, children, out.radiiMm, raw}, frozen, o, sp.minCoeff(), q, out.radiiMm);
  isolatedSectionsKeepRays(parent, children, sectioned, rayRadius, out.radiiMm);
  afterFinalCentring(field, kept, polarity, ownLobeRadius, q, out);
  centreline_detail::holdReversedSteps({parent, children, out.radiiMm, raw}, o, rounds, rested, stepped, q);
  centreline_detail::finishRefined(q, sp, parent, source, out);
  progress.report(1.0, "centreline");
  return out;
}

}  // namespace vs
