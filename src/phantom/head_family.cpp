// The randomised head family (issue 26): see head_family.h.
#include "phantom/head_family.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "phantom/phantom_internal.h"
#include "util/error.h"

namespace vs {

using namespace phantom_detail;

namespace {

// Signed distance (mm, < 0 inside) and outward normal of a tilted ellipsoid: (q - 1) / |grad q|
// with q its level, exact on the surface to first order.
double sdAndNormal(const TiltedEllipsoid& e, const Vec3& p, Vec3& normal) {
  const Vec3 local = e.rotation.transpose() * (p - e.centerMm);
  const Vec3 u = local.cwiseQuotient(e.semiAxesMm);
  const double q = u.norm();
  if (q < 1e-9) {
    normal = e.rotation.col(0);
    return -e.semiAxesMm.minCoeff();
  }
  const Vec3 g = u.cwiseQuotient(e.semiAxesMm) / q;
  const double gn = g.norm();
  normal = e.rotation * (g / gn);
  return (q - 1.0) / gn;
}

TiltedEllipsoid shrunk(const TiltedEllipsoid& e, double mm) {
  TiltedEllipsoid s = e;
  s.semiAxesMm -= Vec3::Constant(mm);
  return s;
}

double cover(const TiltedEllipsoid& e, const Vec3& p, const Vec3& spacing) {
  Vec3 n;
  const double sd = sdAndNormal(e, p, n);
  return coverage(sd, voxelExtentAlong(n, spacing));
}

Eigen::Matrix3d rotationXYZ(double ax, double ay, double az) {
  return (Eigen::AngleAxisd(az, Vec3::UnitZ()) * Eigen::AngleAxisd(ay, Vec3::UnitY()) *
          Eigen::AngleAxisd(ax, Vec3::UnitX()))
      .toRotationMatrix();
}

// The point where the line q + t d (t from -reach to +reach) leaves the region sd < 0 last (the
// outermost crossing), by sampling and bisection; false when it never crosses.
template <class SD>
bool outermostCrossing(const SD& sd, const Vec3& q, const Vec3& d, double reach, Vec3& out) {
  const double step = 0.5;
  for (double t = reach; t > -reach; t -= step) {
    double a = t - step, b = t;  // sd(a) < 0 <= sd(b) is a crossing
    if (!(sd(q + a * d) < 0 && sd(q + b * d) >= 0)) continue;
    for (int i = 0; i < 40; ++i) {
      const double m = 0.5 * (a + b);
      (sd(q + m * d) < 0 ? a : b) = m;
    }
    out = q + 0.5 * (a + b) * d;
    return true;
  }
  return false;
}

}  // namespace

double TiltedEllipsoid::level(const Vec3& p) const {
  return (rotation.transpose() * (p - centerMm)).cwiseQuotient(semiAxesMm).norm();
}

double TiltedEllipsoid::signedDistance(const Vec3& p) const {
  Vec3 n;
  return sdAndNormal(*this, p, n);
}

double HeadFamilyTruth::boneOuterSignedDistance(const Vec3& p) const {
  return shrunk(head, skinMm + fatMm + muscleMm).signedDistance(p);
}

double HeadFamilyTruth::faceSignedDistance(const Vec3& p) const {
  return std::min(head.signedDistance(p), chin.signedDistance(p));
}

std::vector<Vec3> HeadFamilyTruth::noseLoopMm(int count) const {
  std::vector<Vec3> loop;
  const Vec3 lateral = nose.rotation.col(0), vertical = nose.rotation.col(2);
  auto face = [&](const Vec3& p) { return faceSignedDistance(p); };
  for (int i = 0; i < count; ++i) {
    const double th = 2 * M_PI * i / count;
    const Vec3 dir = std::cos(th) * nose.semiAxesMm.x() * lateral + std::sin(th) * nose.semiAxesMm.z() * vertical;
    for (double f = 0.8; f < 3; f += 0.02) {
      Vec3 q;
      if (!outermostCrossing(face, nose.centerMm + f * dir, faceDirection, 40, q)) continue;
      if (nose.level(q) >= 1.12) {
        loop.push_back(q);
        break;
      }
    }
  }
  return loop;
}

std::vector<Vec3> HeadFamilyTruth::earLoopMm(int count) const {
  std::vector<Vec3> loop;
  const Vec3 out = (ear.centerMm - head.centerMm).normalized();
  const Vec3 a = out.unitOrthogonal(), b = out.cross(a);
  auto body = [&](const Vec3& p) { return head.signedDistance(p); };
  const double r = ear.semiAxesMm.maxCoeff();
  for (int i = 0; i < count; ++i) {
    const double th = 2 * M_PI * i / count;
    for (double f = 0.3; f < 3; f += 0.02) {
      Vec3 q;
      if (!outermostCrossing(body, ear.centerMm + f * r * (std::cos(th) * a + std::sin(th) * b), out, 60, q)) continue;
      if (ear.level(q) >= 1.12) {
        loop.push_back(q);
        break;
      }
    }
  }
  return loop;
}

std::vector<Vec3> HeadFamilyTruth::faceLoopMm(double upDeg, double sideDeg, double radiusMm, int count) const {
  const Vec3 up = head.rotation.col(2), side = head.rotation.col(0);
  const Vec3 level = (std::cos(sideDeg * M_PI / 180) * faceDirection + std::sin(sideDeg * M_PI / 180) * side);
  const Vec3 dir = (std::cos(upDeg * M_PI / 180) * level + std::sin(upDeg * M_PI / 180) * up).normalized();
  auto face = [&](const Vec3& p) { return faceSignedDistance(p); };
  Vec3 p0;
  if (!outermostCrossing(face, head.centerMm, dir, 300, p0)) return {};
  Vec3 n0;
  sdAndNormal(head, p0, n0);
  const Vec3 u = n0.cross(up).normalized(), v = n0.cross(u);
  std::vector<Vec3> loop;
  for (int i = 0; i < count; ++i) {
    const double th = 2 * M_PI * i / count;
    Vec3 q;
    if (outermostCrossing(face, p0 + radiusMm * (std::cos(th) * u + std::sin(th) * v), n0, 30, q)) loop.push_back(q);
  }
  return loop;
}

std::vector<Vec3> HeadFamilyTruth::foreheadLoopMm(double radiusMm, int count) const {
  return faceLoopMm(35, 0, radiusMm, count);  // 35 degrees above the face direction
}

std::vector<Vec3> HeadFamilyTruth::cheekLoopMm(double radiusMm, int count) const {
  // Beside the nose, towards the ear's side, level with the nose: plain face (no nose, no chin).
  return faceLoopMm(-8, 45, radiusMm, count);
}

HeadFamilyPhantom makeHeadFamilyPhantom(const HeadFamilyOptions& o, Progress& progress) {
  requireFiniteIn(o.sizeScale, 0.3, 1.5, "head family: size scale");
  PhantomRng rng(PhantomRng::derive(o.seed, 26));
  const double k = o.sizeScale;
  HeadFamilyTruth T;
  T.seed = o.seed;
  T.sizeScale = o.sizeScale;
  const double sxy = rng.uniform(0.8, 1.1);
  T.spacing = Vec3(sxy, sxy, sxy * rng.uniform(1.0, 2.0));
  T.skin = rng.uniform(30, 60);
  T.fat = rng.uniform(-130, -70);
  T.muscle = rng.uniform(35, 60);
  T.bone = rng.uniform(500, 1500);
  T.brain = rng.uniform(20, 40);
  T.noiseSigma = rng.uniform(5, 20);
  T.biasSlope = rng.uniform(-0.1, 0.1);
  T.biasDirection = Vec3(rng.normal(), rng.normal(), rng.normal()).normalized();
  T.skinMm = rng.uniform(1.5, 2.5);
  T.fatMm = rng.uniform(1.0, 5.0);
  T.muscleMm = rng.uniform(0.5, 3.0);
  T.boneMm = rng.uniform(3.0, 9.0);
  T.iso = 0.5 * (T.air + std::min({T.skin, T.fat, T.muscle}));
  const double deg = M_PI / 180;

  T.head.semiAxesMm =
      k * Vec3(70 * rng.uniform(0.92, 1.08), 90 * rng.uniform(0.92, 1.08), 95 * rng.uniform(0.92, 1.08));
  T.head.rotation = rotationXYZ(rng.uniform(-6, 6) * deg, rng.uniform(-4, 4) * deg, rng.uniform(-6, 6) * deg);
  T.faceDirection = T.head.rotation * Vec3(0, -1, 0);
  const Vec3 up = T.head.rotation.col(2), side = T.head.rotation.col(0);
  auto headSurface = [&](const Vec3& dir) {
    Vec3 p;
    outermostCrossing([&](const Vec3& x) { return T.head.signedDistance(x); }, Vec3::Zero(), dir.normalized(),
                      200 * k + 50, p);
    Vec3 n;
    sdAndNormal(T.head, p, n);
    return std::make_pair(p, n);
  };
  // Parts are placed relative to a head centred at 0, then everything is shifted into the volume.
  {  // nose: lateral x, outwards -y, vertical z in its own frame before the tilts
    const auto [p, n] = headSurface(T.faceDirection - rng.uniform(0.12, 0.22) * up);
    T.nose.semiAxesMm = k * Vec3(rng.uniform(7, 11), rng.uniform(9, 14), rng.uniform(14, 22));
    T.nose.rotation =
        T.head.rotation * rotationXYZ(rng.uniform(-15, 15) * deg, rng.uniform(-8, 8) * deg, rng.uniform(-10, 10) * deg);
    T.nose.centerMm = p - rng.uniform(0.25, 0.45) * T.nose.semiAxesMm.y() * n;
  }
  {  // chin: a soft bump on the lower face
    const auto [p, n] = headSurface(T.faceDirection - rng.uniform(0.9, 1.2) * up);
    T.chin.semiAxesMm = k * Vec3(rng.uniform(18, 26), rng.uniform(10, 14), rng.uniform(12, 18));
    T.chin.rotation = T.head.rotation * rotationXYZ(rng.uniform(-20, 20) * deg, 0, rng.uniform(-8, 8) * deg);
    T.chin.centerMm = p - rng.uniform(0.5, 0.8) * T.chin.semiAxesMm.y() * n;
  }
  {  // ear: a flap on the +x side standing away from the head by a random angle
    const auto [p, n] = headSurface(side + rng.uniform(-0.15, 0.05) * up + rng.uniform(0.0, 0.2) * T.faceDirection);
    T.ear.semiAxesMm = k * Vec3(rng.uniform(3, 5), rng.uniform(9, 13), rng.uniform(14, 20));
    const double away = rng.uniform(25, 55) * deg;  // the flap's angle to the head's side
    // Local x (thickness) starts along the head's normal; the flap's width axis (local y) points
    // backwards, tilted out of the head's side by `away`.
    const Vec3 back = -T.faceDirection;
    const Vec3 widthAxis = (std::cos(away) * (back - back.dot(n) * n).normalized() + std::sin(away) * n).normalized();
    const Vec3 heightAxis = n.cross(widthAxis).normalized();
    Eigen::Matrix3d R;
    R.col(0) = widthAxis.cross(heightAxis).normalized();
    R.col(1) = widthAxis;
    R.col(2) = heightAxis;
    T.ear.rotation = R * rotationXYZ(0, rng.uniform(-10, 10) * deg, 0);
    T.ear.centerMm = p + 0.7 * T.ear.semiAxesMm.y() * widthAxis;
  }

  // The volume: the head with 10 mm around it.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const TiltedEllipsoid* e : {&T.head, &T.nose, &T.chin, &T.ear}) {
    const double r = e->semiAxesMm.maxCoeff();
    lo = lo.cwiseMin(e->centerMm - Vec3::Constant(r)), hi = hi.cwiseMax(e->centerMm + Vec3::Constant(r));
  }
  lo -= Vec3::Constant(10), hi += Vec3::Constant(10);
  Geometry geom;
  for (int i = 0; i < 3; ++i) geom.dims[size_t(i)] = int64_t(std::ceil((hi[i] - lo[i]) / T.spacing[i])) + 1;
  geom.spacing = T.spacing;
  for (TiltedEllipsoid* e : {&T.head, &T.nose, &T.chin, &T.ear}) e->centerMm -= lo;
  checkAllocation(geom.dims, sizeof(int16_t) + 1, "head family phantom");

  const TiltedEllipsoid fatOuter = shrunk(T.head, T.skinMm), muscleOuter = shrunk(T.head, T.skinMm + T.fatMm),
                        boneOuter = shrunk(T.head, T.skinMm + T.fatMm + T.muscleMm),
                        brainOuter = shrunk(T.head, T.skinMm + T.fatMm + T.muscleMm + T.boneMm);
  HeadFamilyPhantom out;
  out.volume = VolumeI16(geom, 0);
  out.labels = VolumeU8(geom, 0);
  PhantomRng noise(PhantomRng::derive(o.seed, 27));
  const Vec3& s = T.spacing;
  for (int64_t z = 0; z < geom.dims[2]; ++z) {
    if ((z & 7) == 0) progress.report(double(z) / double(geom.dims[2]), "phantom head family");
    for (int64_t y = 0; y < geom.dims[1]; ++y)
      for (int64_t x = 0; x < geom.dims[0]; ++x) {
        const Vec3 p(double(x) * s[0], double(y) * s[1], double(z) * s[2]);
        const double body =
            std::max({cover(T.head, p, s), cover(T.chin, p, s), cover(T.nose, p, s), cover(T.ear, p, s)});
        double v = T.air + (T.skin - T.air) * body;
        uint8_t label = kHeadAir;
        if (body > 0) {
          const double cf = cover(fatOuter, p, s);
          if (cf > 0) {
            v += (T.fat - T.skin) * cf;
            const double cm = cover(muscleOuter, p, s);
            if (cm > 0) {
              v += (T.muscle - T.fat) * cm;
              const double cb = cover(boneOuter, p, s);
              if (cb > 0) {
                v += (T.bone - T.muscle) * cb;
                v += (T.brain - T.bone) * cover(brainOuter, p, s);
              }
            }
          }
          const double bias = 1 + T.biasSlope * (p - T.head.centerMm).dot(T.biasDirection) / 100;
          v = T.air + (v - T.air) * bias;
          if (T.head.signedDistance(p) < 0 || T.chin.signedDistance(p) < 0) {
            label = brainOuter.signedDistance(p) < 0  ? kHeadBrain
                    : boneOuter.signedDistance(p) < 0 ? kHeadBone
                                                      : kHeadSoft;
          } else if (T.nose.signedDistance(p) < 0) {
            label = kHeadNose;
          } else if (T.ear.signedDistance(p) < 0) {
            label = kHeadEar;
          }
        }
        v += T.noiseSigma * noise.normal();
        out.volume(x, y, z) = int16_t(std::lround(std::clamp(v, -32768.0, 32767.0)));
        out.labels(x, y, z) = label;
      }
  }
  progress.report(1.0, "phantom head family");
  out.truth = T;
  return out;
}

PartCutScore scorePartCut(const HeadFamilyPhantom& ph, HeadLabel part, const VolumeU8& cut) {
  const VolumeU8& truth = ph.labels;
  VS_REQUIRE(truth.dims() == cut.dims(), "score: the label volumes differ in size");
  VS_REQUIRE(part == kHeadNose || part == kHeadEar, "score: the part must be the nose or the ear");
  const HeadFamilyTruth& t = ph.truth;
  const TiltedEllipsoid& shape = part == kHeadNose ? t.nose : t.ear;
  const TiltedEllipsoid& other = part == kHeadNose ? t.ear : t.nose;
  const Geometry& g = truth.geometry();
  PartCutScore s;
  int64_t removed = 0, taken = 0, byCentre = 0, rim = 0;
  for (int64_t i = 0; i < g.voxelCount(); ++i) {
    const bool inPart = truth.data()[i] == part, isCut = cut.data()[i] == 2;
    s.partVoxels += inPart;
    removed += inPart && isCut;
    if (inPart || !isCut) continue;
    ++byCentre;
    if (truth.data()[i] != kHeadAir) {
      ++taken;
      continue;
    }
    const Index3 v = g.unlinear(i);
    const Vec3 p = g.indexToWorld(Vec3(double(v[0]), double(v[1]), double(v[2])));
    const double rest = std::min(t.faceSignedDistance(p), other.signedDistance(p));
    if (shape.signedDistance(p) < rest)
      ++rim;
    else
      ++taken;
  }
  if (s.partVoxels > 0) {
    const double n = double(s.partVoxels);
    s.removed = double(removed) / n;
    s.takenRest = double(taken) / n;
    s.takenByCentre = double(byCentre) / n;
    s.partRimCut = double(rim) / n;
  }
  return s;
}

double meanDistanceToBoneMm(const HeadFamilyTruth& t, const std::vector<Vec3>& points) {
  VS_REQUIRE(!points.empty(), "score: no points");
  double sum = 0;
  for (const Vec3& p : points) sum += std::abs(t.boneOuterSignedDistance(p));
  return sum / double(points.size());
}

nlohmann::json toJson(const HeadFamilyTruth& t, const Geometry& g) {
  using nlohmann::json;
  auto index = [&](const Vec3& mm) {
    const Vec3 i = g.worldToIndex(mm);
    return json::array({i.x(), i.y(), i.z()});
  };
  auto loop = [&](const std::vector<Vec3>& points) {
    json j = json::array();
    std::ostringstream text;
    text.precision(5);
    for (const Vec3& p : points) {
      const Vec3 i = g.worldToIndex(p);
      text << (j.empty() ? "" : ";") << i.x() << "," << i.y() << "," << i.z();
      j.push_back(index(p));
    }
    return json{{"points", j}, {"cut_points", text.str()}};
  };
  const double patch = 20 * t.sizeScale;  // the forehead and cheek loops' radius of bench_cut family
  return json{
      {"kind", "head-family"},
      {"seed", t.seed},
      {"dims", json::array({g.dims[0], g.dims[1], g.dims[2]})},
      {"spacing", json::array({g.spacing.x(), g.spacing.y(), g.spacing.z()})},
      {"voxel_type", "int16"},
      {"iso", t.iso},
      {"values", json{{"air", t.air},
                      {"skin", t.skin},
                      {"fat", t.fat},
                      {"muscle", t.muscle},
                      {"bone", t.bone},
                      {"brain", t.brain}}},
      {"layers_mm", json{{"skin", t.skinMm}, {"fat", t.fatMm}, {"muscle", t.muscleMm}, {"bone", t.boneMm}}},
      {"noise_sigma", t.noiseSigma},
      {"bias", json{{"slope_per_100mm", t.biasSlope},
                    {"direction", json::array({t.biasDirection.x(), t.biasDirection.y(), t.biasDirection.z()})}}},
      {"labels", json{{"0", "air"}, {"1", "soft tissue"}, {"2", "bone"}, {"3", "brain"}, {"4", "nose"}, {"5", "ear"}}},
      {"loops", json{{"nose", loop(t.noseLoopMm(12))},
                     {"ear", loop(t.earLoopMm(12))},
                     {"forehead", loop(t.foreheadLoopMm(patch, 12))},
                     {"cheek", loop(t.cheekLoopMm(patch, 12))}}},
  };
}

}  // namespace vs
