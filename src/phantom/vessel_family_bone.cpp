// Bone beside the family's vessels (phantom.h: makeVesselFamilyBoneCase): boxes far brighter than the lumen,
// touching or a few voxels from a vessel's wall, for the lumen model's upper edge (docs/notes/tracking.md,
// session 15 bone1).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "phantom/phantom.h"
#include "phantom/phantom_internal.h"

namespace vs {

double BoneBlock::signedDistanceMm(const Vec3& p) const {
  double outside = 0, inside = -1e300;
  for (int a = 0; a < 3; ++a) {
    const double q = std::abs((p - centre).dot(axes[static_cast<size_t>(a)])) - halfMm[a];
    outside += q > 0 ? q * q : 0.0;
    inside = std::max(inside, q);
  }
  return outside > 0 ? std::sqrt(outside) : inside;
}

namespace phantom_detail {
namespace {
Vec3 perpendicular(PhantomRng& rng, const Vec3& d) {
  for (;;) {
    Vec3 g(rng.normal(), rng.normal(), rng.normal());
    g -= g.dot(d) * d;
    if (g.norm() > 1e-6) return g.normalized();
  }
}

// The largest-|q| axis of the box at p: the normal of its nearest face (for the partial-volume ramp).
Vec3 faceNormal(const BoneBlock& b, const Vec3& p) {
  int best = 0;
  double bq = -1e300;
  for (int a = 0; a < 3; ++a) {
    const double q = std::abs((p - b.centre).dot(b.axes[static_cast<size_t>(a)])) - b.halfMm[a];
    if (q > bq) bq = q, best = a;
  }
  return b.axes[static_cast<size_t>(best)];
}

// A block beside branch point (b, k), or none (value 0) when it would cover a vessel or the root.
BoneBlock drawBlock(PhantomRng& rng, const VesselTruth& t, double vox, double fg, double bg) {
  const Vec3& sp = t.spacing;
  const VesselBranch& br = t.branches[static_cast<size_t>(rng.integer(0, static_cast<int64_t>(t.branches.size()) - 1))];
  const size_t n = br.points.size(), k = static_cast<size_t>(rng.integer(0, static_cast<int64_t>(n) - 1));
  const Vec3 p = br.points[k].cwiseProduct(sp);
  const Vec3 tan = (br.points[std::min(k + 1, n - 1)] - br.points[k > 0 ? k - 1 : 0]).cwiseProduct(sp).normalized();
  BoneBlock b;
  b.axes[0] = perpendicular(rng, tan);
  b.axes[1] = (tan - tan.dot(b.axes[0]) * b.axes[0]).normalized();
  b.axes[2] = b.axes[0].cross(b.axes[1]);
  b.gapVoxels = rng.uniform(0.0, 3.0);
  b.halfMm = Vec3(rng.uniform(1.5, 4.0), rng.uniform(4.0, 12.0), rng.uniform(3.0, 10.0)) * vox;
  b.centre = p + (br.radiiMm[k] + b.gapVoxels * vox + b.halfMm[0]) * b.axes[0];
  b.value = fg + rng.uniform(1.5, 3.0) * (fg - bg);
  // Not over a vessel (a centreline point inside by more than its radius - half a voxel), nor at the root.
  for (const VesselBranch& o : t.branches)
    for (size_t j = 0; j < o.points.size(); ++j)
      if (b.signedDistanceMm(o.points[j].cwiseProduct(sp)) < o.radiiMm[j] - 0.5 * vox) return BoneBlock{};
  const VesselBranch& root = t.branches.front();
  const Vec3 r(double(t.rootVoxel[0]), double(t.rootVoxel[1]), double(t.rootVoxel[2]));
  if (b.signedDistanceMm(r.cwiseProduct(sp)) < root.radiiMm.front() + 3 * vox) return BoneBlock{};
  return b;
}
}  // namespace

void addBoneBlocks(PhantomRng& rng, VesselFamilyCase& c) {
  const VesselTruth& t = c.truth;
  const Geometry& g = c.volume.geometry();
  const double vox = g.spacing.minCoeff(), fg = t.foreground, bg = t.background;
  const int count = static_cast<int>(rng.integer(2, 4));
  for (int i = 0; i < count; ++i)
    for (int attempt = 0; attempt < 30; ++attempt) {
      const BoneBlock b = drawBlock(rng, t, vox, fg, bg);
      if (b.value > 0) {
        c.bones.push_back(b);
        break;
      }
    }
  // The vessels' share of each voxel from the render (they stay in front of the bone).
  const VolumeF32 vessels = c.volume;
  for (const BoneBlock& b : c.bones) {
    const double reach = b.halfMm.norm() + g.spacing.maxCoeff();
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max<int64_t>(0, static_cast<int64_t>(std::floor((b.centre[a] - reach) / g.spacing[a])));
      hi[a] = std::min<int64_t>(g.dims[a] - 1, static_cast<int64_t>(std::ceil((b.centre[a] + reach) / g.spacing[a])));
    }
    for (int64_t z = lo[2]; z <= hi[2]; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t x = lo[0]; x <= hi[0]; ++x) {
          const Vec3 p = g.spacing.cwiseProduct(Vec3(double(x), double(y), double(z)));
          const double cover = coverage(b.signedDistanceMm(p), voxelExtentAlong(faceNormal(b, p), g.spacing));
          if (cover <= 0) continue;
          const double w = std::clamp((vessels(x, y, z) - bg) / (fg - bg), 0.0, 1.0);
          const double v = c.volume(x, y, z);
          c.volume(x, y, z) = static_cast<float>(v + (b.value - v) * cover * (1.0 - w));
        }
  }
}

}  // namespace phantom_detail
}  // namespace vs
