#include "surface/fold_check.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "util/error.h"
#include "volume/ray_crossings.h"

namespace vs {

namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Ray parameter (mm) where the ray origin + t * dir meets triangle abc, or kNoHit
// (Moller-Trumbore; edges count as inside, so a ray through a shared edge is not lost).
double rayTriangle(const Vec3& origin, const Vec3& dir, const Vec3& a, const Vec3& b, const Vec3& c) {
  constexpr double eps = 1e-9;
  const Vec3 e1 = b - a, e2 = c - a, p = dir.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-12) return kNoHit;
  const Vec3 s = origin - a, q = s.cross(e1);
  const double u = s.dot(p) / det, v = dir.dot(q) / det;
  if (u < -eps || v < -eps || u + v > 1 + eps) return kNoHit;
  const double t = e2.dot(q) / det;
  return t > 0 ? t : kNoHit;
}

// Background voxels of the octant's box connected (6-neighbours) to the box's faces on the
// volume's border: the outside, as seen from within the octant.
class Outside {
 public:
  Outside(const VolumeF32& v, double iso, bool brightInside, const Index3& center, const OctantSigns& o)
      : geometry_(v.geometry()) {
    const Index3& d = geometry_.dims;
    for (int a = 0; a < 3; ++a) {
      lo_[a] = o[a] > 0 ? center[a] : 0;
      dims_[a] = (o[a] > 0 ? d[a] - 1 : center[a]) - lo_[a] + 1;
    }
    mask_.assign(static_cast<size_t>(dims_[0] * dims_[1] * dims_[2]), 0);
    auto background = [&](int64_t x, int64_t y, int64_t z) {
      const double val = v(lo_[0] + x, lo_[1] + y, lo_[2] + z);
      return brightInside ? val < iso : val >= iso;
    };
    std::vector<int64_t> stack;
    auto visit = [&](int64_t x, int64_t y, int64_t z) {
      const int64_t k = x + dims_[0] * (y + dims_[1] * z);
      if (mask_[static_cast<size_t>(k)] || !background(x, y, z)) return;
      mask_[static_cast<size_t>(k)] = 1;
      stack.push_back(k);
    };
    // Seeds: the far face of each axis (the volume's border on the octant's side).
    for (int a = 0; a < 3; ++a) {
      const int64_t face = o[a] > 0 ? dims_[a] - 1 : 0;
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int64_t j = 0; j < dims_[c]; ++j)
        for (int64_t i = 0; i < dims_[b]; ++i) {
          Index3 p{0, 0, 0};
          p[a] = face, p[b] = i, p[c] = j;
          visit(p[0], p[1], p[2]);
        }
    }
    while (!stack.empty()) {
      const int64_t k = stack.back();
      stack.pop_back();
      const int64_t x = k % dims_[0], y = (k / dims_[0]) % dims_[1], z = k / (dims_[0] * dims_[1]);
      if (x > 0) visit(x - 1, y, z);
      if (x + 1 < dims_[0]) visit(x + 1, y, z);
      if (y > 0) visit(x, y - 1, z);
      if (y + 1 < dims_[1]) visit(x, y + 1, z);
      if (z > 0) visit(x, y, z - 1);
      if (z + 1 < dims_[2]) visit(x, y, z + 1);
    }
  }
  // The voxel nearest the world point is outside.
  bool at(const Vec3& world) const {
    const Index3 p = roundIndex(geometry_.worldToIndex(world));
    Index3 q{0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      q[a] = p[a] - lo_[a];
      if (q[a] < 0 || q[a] >= dims_[a]) return false;
    }
    return mask_[static_cast<size_t>(q[0] + dims_[0] * (q[1] + dims_[1] * q[2]))] != 0;
  }

 private:
  const Geometry& geometry_;
  Index3 lo_{0, 0, 0}, dims_{0, 0, 0};
  std::vector<uint8_t> mask_;
};

}  // namespace

FoldCheck checkFold(const VolumeF32& volume, double iso, bool brightInside, const Index3& center,
                    const OctantSigns& octant, const std::vector<Vec3>& vertices,
                    const std::vector<std::array<int32_t, 3>>& triangles, int rayGrid) {
  VS_REQUIRE(rayGrid >= 3, "fold check: the ray grid needs at least 3 rays per side");
  const Geometry& g = volume.geometry();
  const int n = rayGrid;
  const Vec3 o = Vec3(double(center[0]), double(center[1]), double(center[2]));
  const Vec3 origin = g.indexToWorld(o);
  const double voxel = g.spacing.minCoeff();

  // Ray (i, j), k = n - i - j: index-space direction (sx i, sy j, sz k); `reach` is how far the
  // patch's surface extends along it (the farthest vertex of the first triangle it meets).
  struct Ray {
    Vec3 dir;
    double hit = kNoHit, reach = 0;
  };
  std::vector<Ray> rays(static_cast<size_t>((n + 1) * (n + 1)));
  auto rayAt = [&](int i, int j) -> Ray& { return rays[static_cast<size_t>(i * (n + 1) + j)]; };
  for (int i = 1; i < n; ++i)
    for (int j = 1; i + j < n; ++j) {
      const Vec3 e(octant[0] * i, octant[1] * j, octant[2] * (n - i - j));
      rayAt(i, j).dir = (g.indexToWorld(o + e / double(n)) - origin).normalized();
    }

  // Each triangle is met only by the rays inside its central projection onto the plane
  // i + j + k = n (index space, octant signs folded in).
  for (const auto& tri : triangles) {
    std::array<Vec3, 3> w;
    double iMin = n, iMax = 0, jMin = n, jMax = 0;
    bool inFront = true;
    for (int c = 0; c < 3; ++c) {
      w[c] = vertices[static_cast<size_t>(tri[c])];
      const Vec3 rel = g.worldToIndex(w[c]) - o;
      const Vec3 q(octant[0] * rel[0], octant[1] * rel[1], octant[2] * rel[2]);
      const double sum = q.sum();
      if (sum <= 1e-9) {
        inFront = false;
        break;
      }
      iMin = std::min(iMin, n * q[0] / sum), iMax = std::max(iMax, n * q[0] / sum);
      jMin = std::min(jMin, n * q[1] / sum), jMax = std::max(jMax, n * q[1] / sum);
    }
    if (!inFront) continue;
    double reach = 0;
    for (const Vec3& p : w) reach = std::max(reach, (p - origin).norm());
    for (int i = std::max(1, int(std::floor(iMin))); i <= std::min(n - 2, int(std::ceil(iMax))); ++i)
      for (int j = std::max(1, int(std::floor(jMin))); j <= std::min(n - 1 - i, int(std::ceil(jMax))); ++j) {
        Ray& r = rayAt(i, j);
        const double t = rayTriangle(origin, r.dir, w[0], w[1], w[2]);
        if (t < r.hit) r.hit = t, r.reach = std::max(t, reach);
      }
  }

  FoldCheck out;
  std::optional<Outside> outside;  // built on the first candidate: most octants never need it
  const Vec3 extent = g.spacing.cwiseProduct(Vec3(double(g.dims[0]), double(g.dims[1]), double(g.dims[2])));
  for (int i = 1; i < n; ++i)
    for (int j = 1; i + j < n; ++j) {
      const Ray& r = rayAt(i, j);
      if (r.hit == kNoHit) continue;
      ++out.rays;
      // The walk starts a voxel before the patch: only a gap that reaches beyond it matters.
      const double start = std::max(0.0, r.hit - voxel);
      const Vec3 from = origin + start * r.dir;
      const RayIsoCrossings walk = rayIsoCrossings(volume, iso, from, r.dir, voxel / 4, extent.norm());
      std::optional<double> gapStart;  // where the ray last left the object
      if (walk.startsAbove != brightInside) gapStart = 0;
      const auto& cs = walk.crossings;
      for (size_t c = 0; c < cs.size(); ++c) {
        if (cs[c].rising != brightInside) {  // leaving the object
          gapStart = cs[c].t;
          continue;
        }
        const double back = cs[c].t, objectEnd = c + 1 < cs.size() ? cs[c + 1].t : walk.end;
        if (start + back <= r.reach + voxel || back - *gapStart < voxel || objectEnd - back < voxel) continue;
        if (!outside) outside.emplace(volume, iso, brightInside, center, octant);
        bool gapOutside = false;
        for (double t = *gapStart + voxel / 4; t < back && !gapOutside; t += voxel / 4)
          gapOutside = outside->at(from + t * r.dir);
        if (!gapOutside) continue;
        ++out.foldedRays;
        if (!out.firstFold) out.firstFold = g.worldToIndex(from + back * r.dir);
        break;
      }
    }
  return out;
}

}  // namespace vs
