// Head phantom: skin, skull shell and brain as nested axis-aligned ellipsoids plus a
// nose ellipsoid on the face side (towards y = 0), HU-like int16 values.
#include <algorithm>
#include <cmath>

#include "phantom/phantom.h"
#include "phantom/phantom_internal.h"
#include "util/error.h"

namespace vs {

using namespace phantom_detail;

double Ellipsoid::level(const Vec3& p) const { return (p - centerMm).cwiseQuotient(semiAxesMm).norm(); }

namespace {

// Approximate signed distance (mm, < 0 inside) and outward normal of an ellipsoid:
// (q - 1) / |grad q| with q = |(p - c) / a|, exact on the surface to first order.
double ellipsoidSd(const Ellipsoid& e, const Vec3& p, Vec3& normal) {
  const Vec3 rel = p - e.centerMm;
  const Vec3 u = rel.cwiseQuotient(e.semiAxesMm);
  const double q = u.norm();
  if (q < 1e-9) {
    normal = Vec3(1, 0, 0);
    return -e.semiAxesMm.minCoeff();
  }
  const Vec3 g = u.cwiseQuotient(e.semiAxesMm) / q;
  const double gn = g.norm();
  normal = g / gn;
  return (q - 1.0) / gn;
}

double ellipsoidCoverage(const Ellipsoid& e, const Vec3& p, const Vec3& spacing) {
  Vec3 n;
  const double sd = ellipsoidSd(e, p, n);
  return coverage(sd, voxelExtentAlong(n, spacing));
}

}  // namespace

HeadPhantom makeHeadPhantom(const HeadPhantomOptions& o, Progress& progress) {
  requireDims(o.dims, 16, 16, "head phantom");
  requireSpacing(o.spacing, "head phantom");
  requireFiniteIn(o.noiseSigma, 0, 10000, "head phantom: noise sigma");
  for (double v : {o.air, o.softTissue, o.bone, o.brain})
    requireFiniteIn(v, -32768, 32767, "head phantom: tissue value");
  if (!(o.air < o.softTissue && o.softTissue < o.bone))
    throw InvalidArgument("head phantom: need air < soft tissue < bone");
  Geometry geom;
  geom.dims = o.dims;
  geom.spacing = o.spacing;
  checkAllocation(o.dims, sizeof(int16_t), "head phantom");

  PhantomRng rng(PhantomRng::derive(o.seed, 11));
  Vec3 E;
  for (int i = 0; i < 3; ++i) E[i] = static_cast<double>(o.dims[i] - 1) * o.spacing[i];
  auto jit = [&] { return 1.0 + rng.uniform(-0.04, 0.04); };

  HeadTruth T;
  T.seed = o.seed;
  T.dims = o.dims;
  T.spacing = o.spacing;
  T.noiseSigma = o.noiseSigma;
  T.air = o.air;
  T.softTissue = o.softTissue;
  T.bone = o.bone;
  T.brain = o.brain;
  T.isoSkin = 0.5 * (o.air + o.softTissue);
  T.isoBone = 0.5 * (o.softTissue + o.bone);

  // Skin: slightly posterior of the centre so the nose fits in front.
  T.skin.name = "skin";
  T.skin.value = o.softTissue;
  T.skin.centerMm = Vec3(0.5 * E[0], 0.53 * E[1], 0.5 * E[2]);
  T.skin.semiAxesMm = Vec3(0.36 * E[0] * jit(), 0.37 * E[1] * jit(), 0.40 * E[2] * jit());
  const double aMin = T.skin.semiAxesMm.minCoeff();
  const double soft = std::max(0.09 * aMin * jit(), 1.5 * o.spacing.maxCoeff());
  const double boneT = std::max(0.10 * aMin * jit(), 2.0 * o.spacing.maxCoeff());
  T.skullOuter.name = "skull_outer";
  T.skullOuter.value = o.bone;
  T.skullOuter.centerMm = T.skin.centerMm;
  T.skullOuter.semiAxesMm = T.skin.semiAxesMm - Vec3::Constant(soft);
  T.skullInner.name = "skull_inner";
  T.skullInner.value = o.brain;
  T.skullInner.centerMm = T.skin.centerMm;
  T.skullInner.semiAxesMm = T.skullOuter.semiAxesMm - Vec3::Constant(boneT);
  if (T.skullInner.semiAxesMm.minCoeff() < 2 * o.spacing.maxCoeff())
    throw InvalidArgument("head phantom: volume " + geom.describe() + " is too small for the head layers");

  // Nose: centred just inside the skin on the face side, a little below the middle.
  T.nose.name = "nose";
  T.nose.value = o.softTissue;
  T.nose.semiAxesMm = Vec3(0.06 * E[0] * jit(), 0.09 * E[1] * jit(), 0.11 * E[2] * jit());
  T.nose.centerMm = Vec3(T.skin.centerMm[0], T.skin.centerMm[1] - 0.95 * T.skin.semiAxesMm[1],
                         T.skin.centerMm[2] - 0.12 * T.skin.semiAxesMm[2]);
  for (int i = 0; i < 3; ++i) {
    const double lo = (T.nose.centerMm[i] - T.nose.semiAxesMm[i]) / o.spacing[i];
    const double hi = (T.nose.centerMm[i] + T.nose.semiAxesMm[i]) / o.spacing[i];
    T.noseBoxMin[i] = std::clamp<int64_t>(static_cast<int64_t>(std::floor(lo)), 0, o.dims[i] - 1);
    T.noseBoxMax[i] = std::clamp<int64_t>(static_cast<int64_t>(std::ceil(hi)), 0, o.dims[i] - 1);
  }
  T.faceDirection = Vec3(0, -1, 0);

  HeadPhantom out;
  out.volume = VolumeI16(geom, 0);
  out.truth = T;
  PhantomRng noise(PhantomRng::derive(o.seed, 12));
  const Vec3& s = o.spacing;
  for (int64_t z = 0; z < o.dims[2]; ++z) {
    if ((z & 7) == 0) progress.report(static_cast<double>(z) / static_cast<double>(o.dims[2]), "phantom head");
    for (int64_t y = 0; y < o.dims[1]; ++y)
      for (int64_t x = 0; x < o.dims[0]; ++x) {
        const Vec3 p(static_cast<double>(x) * s[0], static_cast<double>(y) * s[1], static_cast<double>(z) * s[2]);
        const double cSkin = std::max(ellipsoidCoverage(T.skin, p, s), ellipsoidCoverage(T.nose, p, s));
        double v = o.air + (o.softTissue - o.air) * cSkin;
        if (cSkin > 0) {
          const double cOuter = ellipsoidCoverage(T.skullOuter, p, s);
          v += (o.bone - o.softTissue) * cOuter;
          if (cOuter > 0) v += (o.brain - o.bone) * ellipsoidCoverage(T.skullInner, p, s);
        }
        if (o.noiseSigma > 0) v += o.noiseSigma * noise.normal();
        out.volume(x, y, z) = static_cast<int16_t>(std::lround(std::clamp(v, -32768.0, 32767.0)));
      }
  }
  progress.report(1.0, "phantom head");
  return out;
}

std::vector<Vec3> noseBaseLoopMm(const HeadTruth& t, int count, double noseLevel) {
  std::vector<Vec3> loop;
  for (int i = 0; i < count; ++i) {
    const double th = 2 * M_PI * i / count;
    const Vec3 dir(t.nose.semiAxesMm.x() * std::cos(th), 0, t.nose.semiAxesMm.z() * std::sin(th));
    for (double f = 1.0; f < 3; f += 0.02) {
      Vec3 q = t.nose.centerMm + f * dir;
      // Onto the skin ellipsoid along -y (the face side).
      const Vec3 rel = (q - t.skin.centerMm).cwiseQuotient(t.skin.semiAxesMm);
      const double yy = 1 - rel.x() * rel.x() - rel.z() * rel.z();
      if (yy <= 0) continue;
      q.y() = t.skin.centerMm.y() - std::sqrt(yy) * t.skin.semiAxesMm.y();
      if (t.nose.level(q) >= noseLevel) {
        loop.push_back(q);
        break;
      }
    }
  }
  return loop;
}

}  // namespace vs
