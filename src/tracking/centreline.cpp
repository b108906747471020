#include "tracking/centreline.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "features/features3d.h"
#include "features/vesselness.h"
#include "util/parallel.h"

namespace vs {

namespace {

// Points live in "physical index" space q = index * spacing (mm, axis-aligned): distances are mm.
struct Sampler {
  const VolumeF32& vol;
  Vec3 spacing;
  Vec3 hiMm;  // largest q inside the volume
  double at(const Vec3& q) const { return sampleTrilinear(vol, q.cwiseQuotient(spacing)); }
  bool inside(const Vec3& q) const {
    for (int a = 0; a < 3; ++a)
      if (q[a] < 0 || q[a] > hiMm[a]) return false;
    return true;
  }
};

struct RayResult {
  int hits = 0;
  Vec3 offset{0, 0, 0};  // least-squares centre offset from the chord midpoints
  double medianRadius = 0;
};

// Casts the rays of the plane normal to `t` from `c`; see centreline.h.
RayResult castRays(const Sampler& s, const Vec3& c, const Vec3& tangent, const CentrelineOptions& o, double step) {
  RayResult res;
  Vec3 t = tangent.norm() > 0 ? tangent.normalized() : Vec3(0, 0, 1);
  Vec3 u = std::abs(t[0]) < 0.9 ? t.cross(Vec3(1, 0, 0)) : t.cross(Vec3(0, 1, 0));
  u.normalize();
  const Vec3 v = t.cross(u);
  const int n = std::max(4, o.rays - o.rays % 2);
  std::vector<Vec3> dirs(static_cast<size_t>(n));
  std::vector<double> far(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    dirs[static_cast<size_t>(k)] = std::cos(a) * u + std::sin(a) * v;
  }
  const double centre = s.at(c);
  for (int k = 0; k < n; ++k) {
    // The surroundings: the last sample of the ray inside the volume.
    double r = o.maxRadiusMm;
    while (r > step && !s.inside(c + r * dirs[static_cast<size_t>(k)])) r -= step;
    far[static_cast<size_t>(k)] = s.at(c + r * dirs[static_cast<size_t>(k)]);
  }
  std::vector<double> sorted = far;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double bg = sorted[static_cast<size_t>(n / 2)];
  if (centre == bg) return res;
  const double level = 0.5 * (centre + bg);
  const bool bright = centre > bg;
  std::vector<double> radius(static_cast<size_t>(n), -1.0);
  for (int k = 0; k < n; ++k) {
    const Vec3& d = dirs[static_cast<size_t>(k)];
    double prev = centre;
    for (double r = step; r <= o.maxRadiusMm; r += step) {
      const Vec3 q = c + r * d;
      if (!s.inside(q)) break;
      const double val = s.at(q);
      if (bright ? val < level : val > level) {
        const double a = prev - level, b = val - level;
        radius[static_cast<size_t>(k)] = r - step + step * (a != b ? std::clamp(a / (a - b), 0.0, 1.0) : 0.5);
        break;
      }
      prev = val;
    }
  }
  std::vector<double> found;
  for (double r : radius)
    if (r >= 0) found.push_back(r);
  res.hits = static_cast<int>(found.size());
  if (found.empty()) return res;
  std::nth_element(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(found.size() / 2), found.end());
  res.medianRadius = found[found.size() / 2];
  // Chord k / k + n/2 through c: its midpoint lies at (r_k - r_opp) / 2 along d_k; the centre's
  // offset o satisfies o . d_k = that for every chord (exact for a circle), solved by least squares.
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  int chords = 0;
  for (int k = 0; k < n / 2; ++k) {
    const double r1 = radius[static_cast<size_t>(k)], r2 = radius[static_cast<size_t>(k + n / 2)];
    if (r1 < 0 || r2 < 0) continue;
    const Eigen::Vector2d d2(dirs[static_cast<size_t>(k)].dot(u), dirs[static_cast<size_t>(k)].dot(v));
    A += d2 * d2.transpose();
    b += d2 * (0.5 * (r1 - r2));
    ++chords;
  }
  if (chords * 2 < n / 2 || std::abs(A.determinant()) < 1e-9) {
    res.hits = 0;  // too few chords to locate the centre: leave the point
    return res;
  }
  const Eigen::Vector2d o2 = A.ldlt().solve(b);
  res.offset = o2[0] * u + o2[1] * v;
  return res;
}

}  // namespace

RefinedCentreline refineCentreline(const VolumeF32& vol, const CentrelineTree& tree, const CentrelineOptions& o,
                                   Progress& progress) {
  const size_t n = tree.points.size();
  VS_REQUIRE(tree.parent.size() == n, "refineCentreline: points and parents differ in size");
  VS_REQUIRE(o.iterations >= 0 && o.rays >= 4 && o.maxRadiusMm > 0 && o.smoothWeight >= 0 && o.smoothWeight < 1 &&
                 o.maxStepMm > 0,
             "refineCentreline: iterations >= 0, rays >= 4, max radius > 0, smooth weight in [0,1), max step > 0");
  const Geometry& g = vol.geometry();
  for (size_t i = 0; i < n; ++i) {
    VS_REQUIRE(g.containsContinuous(tree.points[i]), "refineCentreline: point outside the volume");
    VS_REQUIRE(tree.parent[i] < static_cast<int32_t>(i) && (i == 0) == (tree.parent[i] < 0),
               "refineCentreline: parents must precede their children and only point 0 is the root");
  }
  const Vec3 sp = g.spacing;
  const Sampler s{vol, sp,
                  Vec3(static_cast<double>(g.dims[0] - 1) * sp[0], static_cast<double>(g.dims[1] - 1) * sp[1],
                       static_cast<double>(g.dims[2] - 1) * sp[2])};
  // Ray step: half the smallest spacing (crossings are interpolated within a step; a quarter
  // gave the same phantom accuracy at twice the samples).
  const double step = 0.5 * sp.minCoeff();
  std::vector<std::vector<int32_t>> children(n);
  for (size_t i = 1; i < n; ++i) children[static_cast<size_t>(tree.parent[i])].push_back(static_cast<int32_t>(i));
  std::vector<Vec3> q(n), next(n);
  for (size_t i = 0; i < n; ++i) q[i] = tree.points[i].cwiseProduct(sp);

  // Tangent from two tree steps on either side (one where the tree branches or ends).
  auto tangent = [&](size_t i) {
    size_t up = i, down = i;
    for (int k = 0; k < 2 && tree.parent[up] >= 0; ++k) up = static_cast<size_t>(tree.parent[up]);
    for (int k = 0; k < 2 && children[down].size() == 1; ++k) down = static_cast<size_t>(children[down][0]);
    if (up == down) return Vec3(0, 0, 1);
    return Vec3(q[down] - q[up]);
  };
  auto centre = [&]() {
    parallelFor(
        1, static_cast<int64_t>(n),
        [&](int64_t b, int64_t e) {
          for (int64_t i = b; i < e; ++i) {
            const size_t k = static_cast<size_t>(i);
            const RayResult r = castRays(s, q[k], tangent(k), o, step);
            next[k] = q[k];
            if (r.hits * 2 < o.rays) continue;
            Vec3 off = r.offset;
            if (off.norm() > o.maxStepMm) off *= o.maxStepMm / off.norm();
            if (s.inside(q[k] + off)) next[k] = q[k] + off;
          }
        },
        64);
    next[0] = q[0];
    std::swap(q, next);
  };
  auto smooth = [&]() {
    next = q;
    for (size_t i = 1; i < n; ++i) {
      if (children[i].empty()) continue;  // ends stay where the centring put them
      Vec3 m = q[static_cast<size_t>(tree.parent[i])];
      for (int32_t c : children[i]) m += q[static_cast<size_t>(c)];
      m /= static_cast<double>(children[i].size() + 1);
      next[i] = (1 - o.smoothWeight) * q[i] + o.smoothWeight * m;
    }
    std::swap(q, next);
  };
  for (int it = 0; it < o.iterations; ++it) {
    progress.report(static_cast<double>(it) / (o.iterations + 1), "centreline");
    centre();
    smooth();
  }
  if (o.iterations > 0) centre();
  RefinedCentreline out;
  out.points.resize(n);
  out.radiiMm.resize(n);
  const double minR = 0.5 * sp.minCoeff();
  parallelFor(
      0, static_cast<int64_t>(n),
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          const size_t k = static_cast<size_t>(i);
          const RayResult r = castRays(s, q[k], tangent(k), o, step);
          out.radiiMm[k] = std::max(minR, r.hits > 0 ? r.medianRadius : minR);
          out.points[k] = q[k].cwiseQuotient(sp);
        }
      },
      64);
  progress.report(1.0, "centreline");
  return out;
}

VolumeF32 refinementIntensity(const VolumeF32& volume, double smoothMm, bool costsGiven, Progress& progress) {
  if (!costsGiven) return smoothMm > 0 ? gaussianSmooth3D(volume, smoothMm, progress) : volume;
  VolumeF32 lumen = volume;
  const float hi = percentileOf(lumen.voxels(), 99.9);
  for (float& v : lumen.voxels())
    if (!std::isfinite(v)) v = hi;
  return smoothMm > 0 ? gaussianSmooth3D(lumen, smoothMm, progress) : lumen;
}

}  // namespace vs
