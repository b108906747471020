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

// A region of the octant's box (from the centre to the volume's border): the voxels on one side of
// the iso-value (`object` or background) 6-connected to the seeds within the box.
class BoxRegion {
 public:
  BoxRegion(const VolumeF32& v, double iso, bool brightInside, const Index3& center, const OctantSigns& o, bool object,
            const std::vector<Index3>& seeds)
      : geometry_(v.geometry()) {
    for (int a = 0; a < 3; ++a) {
      lo_[a] = o[a] > 0 ? center[a] : 0;
      dims_[a] = (o[a] > 0 ? geometry_.dims[a] - 1 : center[a]) - lo_[a] + 1;
    }
    mask_.assign(static_cast<size_t>(dims_[0] * dims_[1] * dims_[2]), 0);
    std::vector<int64_t> stack;
    auto visit = [&](int64_t x, int64_t y, int64_t z) {
      const int64_t k = x + dims_[0] * (y + dims_[1] * z);
      if (mask_[static_cast<size_t>(k)]) return;
      const double val = v(lo_[0] + x, lo_[1] + y, lo_[2] + z);
      if ((brightInside ? val >= iso : val < iso) != object) return;
      mask_[static_cast<size_t>(k)] = 1;
      stack.push_back(k);
    };
    for (const Index3& p : seeds)
      if (p[0] >= lo_[0] && p[1] >= lo_[1] && p[2] >= lo_[2] && p[0] < lo_[0] + dims_[0] && p[1] < lo_[1] + dims_[1] &&
          p[2] < lo_[2] + dims_[2])
        visit(p[0] - lo_[0], p[1] - lo_[1], p[2] - lo_[2]);
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
  // The voxel nearest the world point is in the region.
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

// The voxels of the octant box's faces on the volume's border.
std::vector<Index3> farFaces(const Index3& dims, const Index3& center, const OctantSigns& o) {
  Index3 lo{0, 0, 0}, hi{0, 0, 0};
  for (int a = 0; a < 3; ++a) lo[a] = o[a] > 0 ? center[a] : 0, hi[a] = o[a] > 0 ? dims[a] - 1 : center[a];
  std::vector<Index3> out;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int64_t j = lo[c]; j <= hi[c]; ++j)
      for (int64_t i = lo[b]; i <= hi[b]; ++i) {
        Index3 p{0, 0, 0};
        p[a] = o[a] > 0 ? hi[a] : lo[a], p[b] = i, p[c] = j;
        out.push_back(p);
      }
  }
  return out;
}

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
  // Built on the first candidate ray (most octants have none): the outside air, and the object
  // the patch lies on (seeded from the object voxels nearest its vertices).
  std::optional<BoxRegion> outside, patchObject;
  auto buildRegions = [&] {
    outside.emplace(volume, iso, brightInside, center, octant, false, farFaces(g.dims, center, octant));
    std::vector<Index3> seeds;
    for (const Vec3& w : vertices) seeds.push_back(roundIndex(g.worldToIndex(w)));
    patchObject.emplace(volume, iso, brightInside, center, octant, true, seeds);
  };
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
      bool rayFolded = false, meetsOther = false;
      if (walk.startsAbove != brightInside) gapStart = 0;
      const auto& cs = walk.crossings;
      for (size_t c = 0; c < cs.size(); ++c) {
        if (cs[c].rising != brightInside) {  // leaving the object
          gapStart = cs[c].t;
          continue;
        }
        const double back = cs[c].t, objectEnd = c + 1 < cs.size() ? cs[c + 1].t : walk.end;
        if (start + back <= r.reach + voxel || back - *gapStart < voxel || objectEnd - back < voxel) continue;
        if (!outside) buildRegions();
        bool gapOutside = false;
        for (double t = *gapStart + voxel / 4; t < back && !gapOutside; t += voxel / 4)
          gapOutside = outside->at(from + t * r.dir);
        if (!gapOutside) continue;
        // The object met again: part of the patch's object (an ear, an overhang) or another one.
        bool connected = false;
        for (double t = back + voxel / 4; t < objectEnd && !connected; t += voxel / 4)
          connected = patchObject->at(from + t * r.dir);
        if (!connected) {
          meetsOther = true;
          continue;
        }
        rayFolded = true;
        if (!out.firstFold) out.firstFold = g.worldToIndex(from + back * r.dir);
        break;
      }
      out.foldedRays += rayFolded;
      out.otherObjectRays += meetsOther && !rayFolded;
    }
  return out;
}

}  // namespace vs
