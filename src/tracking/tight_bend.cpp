// A point where its own tube bends as tightly as its radius (session 38 apex930). See tight_bend.h.
#include "tracking/tight_bend.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace vs::centreline_detail {

double chainBendRadius(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                       const std::vector<Vec3>& q, size_t k, double arcMm, Vec3& centre) {
  const double inf = std::numeric_limits<double>::infinity();
  if (parent[k] < 0 || children[k].size() != 1) return inf;
  size_t up = k, down = k;
  for (double s = 0; s < arcMm && parent[up] >= 0;) {
    const size_t p = static_cast<size_t>(parent[up]);
    s += (q[p] - q[up]).norm(), up = p;
    if (children[up].size() > 1) break;  // a branch point ends the chain
  }
  for (double s = 0; s < arcMm && children[down].size() == 1;) {
    const size_t c = static_cast<size_t>(children[down][0]);
    s += (q[c] - q[down]).norm(), down = c;
  }
  const Vec3 a = q[up] - q[k], b = q[down] - q[k];
  const Vec3 axb = a.cross(b);
  const double area2 = axb.squaredNorm();
  if (!(area2 > 1e-12)) return inf;
  const Vec3 c = (a.squaredNorm() * b - b.squaredNorm() * a).cross(axb) / (2 * area2);  // circumcentre - q[k]
  centre = q[k] + c;
  return c.norm();
}

bool tightBendStep(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                   const std::vector<Vec3>& q, size_t k, const Vec3& tangent, const std::vector<Vec3>& dirs,
                   const std::vector<double>& radius, size_t stride, double medianRadius, bool awayFromForks, Vec3& off,
                   const BendSection* section) {
  const size_t n = dirs.size();
  if (!awayFromForks || n < 4 || n % 2 != 0 || radius.size() != n || stride == 0 || !(tangent.norm() > 0) ||
      !(medianRadius > 0))
    return false;
  Vec3 centre;
  const double bend = chainBendRadius(parent, children, q, k, medianRadius, centre);
  if (!(bend <= medianRadius)) return false;
  const Vec3 t = tangent.normalized(), inward = centre - q[k];
  Vec3 normal = -(inward - inward.dot(t) * t);  // the bend's outward normal in the section plane
  if (!(normal.norm() > 1e-6)) return false;
  normal.normalize();
  const Vec3 binormal = t.cross(normal);
  size_t across = 0, outward = 0;  // the marched ray nearest the binormal (of the first half) and the outward normal
  for (size_t j = 0; j < n; j += stride) {
    if (j < n / 2 && std::abs(dirs[j].dot(binormal)) > std::abs(dirs[across].dot(binormal))) across = j;
    if (dirs[j].dot(normal) > dirs[outward].dot(normal)) outward = j;
  }
  const double r1 = radius[across], r2 = radius[across + n / 2], rOut = radius[outward];
  const double longRay = 2.0 * medianRadius;  // castRays' own: a longer ray left the lumen's section
  if (r1 < 0 || r2 < 0 || rOut < 0 || r1 > longRay || r2 > longRay || rOut > longRay) return false;
  const double along = rOut * dirs[outward].dot(normal) - 0.5 * (r1 + r2);  // to a half chord in from the outer wall
  if (!(along > off.dot(normal))) return false;                             // it only takes back the open inside's pull
  if (section) {  // not towards a waist: the chord across at the new position no narrower than through q[k]
    const double value = section->sample.at(q[k].cwiseQuotient(section->spacing)), ring = section->surroundings;
    const double atNew = std::isnan(ring) || value == ring
                             ? r1 + r2
                             : chordThrough(*section, q[k] + off + (along - off.dot(normal)) * normal, binormal,
                                            0.5 * (value + ring), value > ring, longRay);
    if (atNew < r1 + r2) {
      if (std::getenv("VS_TIGHT_BEND_DEBUG"))
        std::fprintf(stderr, "tight bend: k %zu q %.2f %.2f %.2f across %.2f at the new position < %.2f\n", k, q[k][0],
                     q[k][1], q[k][2], atNew, r1 + r2);
      return false;
    }
  }
  if (std::getenv("VS_TIGHT_BEND_DEBUG"))
    std::fprintf(
        stderr,
        "tight bend: k %zu q %.2f %.2f %.2f bend %.2f mm, median ray %.2f, half chord %.2f, out %.2f, step %.2f -> "
        "%.2f\n",
        k, q[k][0], q[k][1], q[k][2], bend, medianRadius, 0.5 * (r1 + r2), rOut, off.dot(normal), along);
  off += (along - off.dot(normal)) * normal;
  return true;
}

double chordThrough(const BendSection& section, const Vec3& at, const Vec3& dir, double level, bool bright,
                    double maxMm) {
  const double step = 0.5 * section.spacing.minCoeff();
  double chord = 0;
  for (const double sign : {1.0, -1.0}) {
    double s = 0;
    for (;; s += step) {
      if (s > maxMm) return -1;
      const Vec3 p = (at + sign * s * dir).cwiseQuotient(section.spacing);
      if (!section.sample.inside(p)) return -1;
      const double v = section.sample.at(p);
      if (bright ? v < level : v > level) break;
    }
    chord += s;
  }
  return chord;
}

}  // namespace vs::centreline_detail
