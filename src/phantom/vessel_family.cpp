// The randomised vessel family (phantom.h: makeVesselFamilyCase): a variant drawn from the seed (a
// thin tree as before, a wide lumen with daughters, two kissing or two parallel vessels), drawn radii,
// contrast falloff, spacing and branch angles, then bias, polarity and Rician noise.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "phantom/phantom.h"
#include "phantom/phantom_internal.h"

namespace vs {

using namespace phantom_detail;

std::string vesselFamilyVariantName(VesselFamilyVariant v) {
  switch (v) {
    case VesselFamilyVariant::Thin:
      return "thin";
    case VesselFamilyVariant::WideLumen:
      return "wide";
    case VesselFamilyVariant::Kissing:
      return "kissing";
    case VesselFamilyVariant::Parallel:
      return "parallel";
    case VesselFamilyVariant::Flat:
      return "flat";
  }
  return "thin";
}

std::string VesselFamilyCase::describe() const {
  char buf[260];
  std::snprintf(buf, sizeof buf, "seed %llu: %s, %s, spacing %.2f,%.2f,%.2f, falloff %.2f, bias %.2f, rician %.1f",
                static_cast<unsigned long long>(truth.seed), vesselFamilyVariantName(variant).c_str(),
                dark ? "dark" : "bright", truth.spacing[0], truth.spacing[1], truth.spacing[2], falloff, bias, rician);
  std::string out = buf;
  if (variant == VesselFamilyVariant::WideLumen) {
    std::snprintf(buf, sizeof buf, ", lumen radius %.1f vox", lumenRadiusVoxels);
    out += buf;
  } else if (variant == VesselFamilyVariant::Flat) {
    std::snprintf(buf, sizeof buf, ", flat lumen %.1f x %.1f vox (aspect %.2f, equivalent radius %.1f vox)",
                  2 * lumenRadiusVoxels, 2 * lumenRadiusVoxels / flatAspect, flatAspect,
                  lumenRadiusVoxels / std::sqrt(flatAspect));
    out += buf;
  } else if (variant == VesselFamilyVariant::Kissing || variant == VesselFamilyVariant::Parallel) {
    std::snprintf(buf, sizeof buf, ", gap %.2f vox", gapVoxels);
    out += buf;
  }
  for (size_t k = 0; k < bones.size(); ++k) {
    std::snprintf(buf, sizeof buf, k == 0 ? ", bone %.0f (gap %.1f vox)" : ", %.0f (%.1f)", bones[k].value,
                  bones[k].gapVoxels);
    out += buf;
  }
  return out;
}

namespace {

// A tube of the drawn geometry, world mm; a child's first point is its parent's last.
// r: the truth's radius; a flat tube (semiMinor > 0) is rendered with an elliptic section instead, semi-axes
// semiMajor along `major` (perpendicular to its axis) and semiMinor across, and r is its equivalent radius.
struct Tube {
  int parent = -1;
  int depth = 0;
  std::vector<Vec3> pts;
  std::vector<double> r;
  double semiMajor = 0, semiMinor = 0;
  Vec3 major = Vec3::Zero();
  double reach(size_t k) const { return std::max(r[k], semiMajor); }
  double arc() const {
    double a = 0;
    for (size_t k = 1; k < pts.size(); ++k) a += (pts[k] - pts[k - 1]).norm();
    return a;
  }
};

Vec3 randomPerpendicular(PhantomRng& rng, const Vec3& d) {
  for (;;) {
    Vec3 g(rng.normal(), rng.normal(), rng.normal());
    g -= g.dot(d) * d;
    if (g.norm() > 1e-6) return g.normalized();
  }
}

// The trunk's axis e: x, y or z tilted by up to 15 degrees; u, w complete an orthonormal frame.
void drawFrame(PhantomRng& rng, Vec3& e, Vec3& u, Vec3& w) {
  Vec3 axis = Vec3::Zero();
  axis[static_cast<int>(rng.integer(0, 2))] = 1;
  const double tilt = rng.uniform(0.0, 0.26);
  e = (std::cos(tilt) * axis + std::sin(tilt) * randomPerpendicular(rng, axis)).normalized();
  u = randomPerpendicular(rng, e);
  w = e.cross(u);
}

// Wide lumen: a straight trunk of radius R along e from the origin, split at the daughters' origins. Flat
// (aspect > 1): the trunk's section is an ellipse of semi-axes R (along the angle phi0 about e, drawn at random)
// and R / aspect, and its daughters leave it from the two ends of the wide axis in turn (phi0, phi0 + pi, ...),
// as veins leave a dural sinus's edges; the truth's radius is the section's equivalent radius R / sqrt(aspect).
std::vector<Tube> wideLumen(PhantomRng& rng, double s, double R, double unit, double aspect = 1) {
  const bool flat = aspect > 1;
  Vec3 e, u, w;
  drawFrame(rng, e, u, w);
  const int n = static_cast<int>(rng.integer(2, 4));
  const double Lt = std::max(40 * s, rng.uniform(1.5, 2.5) * R);
  const size_t nn = static_cast<size_t>(n);
  std::vector<double> h(nn), rd(nn), theta(nn), phi(nn), Ld(nn), bend(nn);
  const double phi0 = rng.uniform(0.0, 2 * M_PI);
  for (int k = 0; k < n; ++k) {
    const size_t i = size_t(k);
    h[i] = Lt * (0.2 + 0.6 * (k + 0.5) / n + rng.uniform(-0.05, 0.05));
    rd[i] = std::max(rng.uniform(1.5, 4.0) * s, 0.5 * unit);
    phi[i] = phi0 + (flat ? M_PI * k : 2 * M_PI * k / n) + rng.uniform(-0.3, 0.3);
    if (flat) rd[i] = std::min(rd[i], R / aspect);  // no daughter wider than the flat lumen is deep
    Ld[i] = rng.uniform(12.0, 25.0) * s;
    bend[i] = rng.uniform(-4.0, 4.0) * s;
  }
  // The distance from the trunk's axis to its wall along the unit radial direction v (R when round).
  const Vec3 major = std::cos(phi0) * u + std::sin(phi0) * w, minor = e.cross(major);
  const double Rminor = R / aspect;
  const auto wall = [&](const Vec3& v) {
    if (!flat) return R;
    const double a = v.dot(major) / R, b = v.dot(minor) / Rminor;
    return 1.0 / std::sqrt(a * a + b * b);
  };
  const auto wallAt = [&](const Vec3& p) {  // the wall's distance in the direction of p's radial part
    const Vec3 q = p - p.dot(e) * e;
    return flat ? (q.norm() > 1e-12 ? wall(q.normalized()) : Rminor) : R;
  };
  std::vector<std::vector<Vec3>> dpts(nn);
  // Daughters 50-130 degrees off the axis, re-drawn while two come closer than their radii + 2 voxels
  // outside the trunk (up to 50 draws; the last is kept, so two daughters may rarely come closer).
  for (int attempt = 0; attempt < 50; ++attempt) {
    for (int k = 0; k < n; ++k) {
      const size_t i = size_t(k);
      theta[i] = rng.uniform(50.0, 130.0) * M_PI / 180.0;
      const Vec3 radial = std::cos(phi[i]) * u + std::sin(phi[i]) * w;
      const Vec3 d = std::cos(theta[i]) * e + std::sin(theta[i]) * radial;
      const Vec3 v = d.cross(radial).normalized();  // bends sideways, along the trunk's surface
      const double inner = wall(radial) / std::sin(theta[i]), len = inner + Ld[i];
      const int steps = std::max(2, static_cast<int>(std::ceil(len / (0.5 * s))));
      dpts[i].clear();
      for (int j = 0; j <= steps; ++j) {
        const double t = len * j / steps, out = std::max(0.0, t - inner) / Ld[i];
        dpts[i].push_back(h[i] * e + t * d + bend[i] * out * out * v);
      }
    }
    bool ok = true;
    for (int a = 0; a < n && ok; ++a)
      for (int b = a + 1; b < n && ok; ++b)
        for (const Vec3& p : dpts[size_t(a)]) {
          if ((p - p.dot(e) * e).norm() < wallAt(p) + rd[size_t(a)]) continue;
          for (const Vec3& q : dpts[size_t(b)])
            if ((q - q.dot(e) * e).norm() >= wallAt(q) + rd[size_t(b)] &&
                (p - q).norm() < rd[size_t(a)] + rd[size_t(b)] + 2 * s) {
              ok = false;
              break;
            }
          if (!ok) break;
        }
    if (ok) break;
  }
  std::vector<Tube> tubes;
  Vec3 from = Vec3::Zero();
  int parent = -1;
  for (int k = 0; k <= n; ++k) {
    Tube seg;
    seg.parent = parent;
    seg.depth = k;
    const Vec3 to = k < n ? Vec3(h[size_t(k)] * e) : Vec3(Lt * e);
    seg.pts = {from, to};
    seg.r = {R, R};
    if (flat) {
      const double equivalent = std::sqrt(R * Rminor);  // the section's area as a circle's
      seg.r = {equivalent, equivalent};
      seg.semiMajor = R, seg.semiMinor = Rminor, seg.major = major;
    }
    tubes.push_back(seg);
    const int segId = static_cast<int>(tubes.size()) - 1;
    if (k < n) {
      Tube d;
      d.parent = segId;
      d.depth = k + 1;
      d.pts = dpts[size_t(k)];
      for (size_t j = 0; j < d.pts.size(); ++j)
        d.r.push_back(rd[size_t(k)] * (1.0 - 0.25 * double(j) / double(d.pts.size() - 1)));
      tubes.push_back(d);
    }
    parent = segId;
    from = to;
  }
  return tubes;
}

// Kissing / parallel: trunk -> A (straight on) and B (out, back beside A at surface gap g, away).
std::vector<Tube> sideBySide(PhantomRng& rng, double s, double g, double unit) {
  Vec3 e, u, w;
  drawFrame(rng, e, u, w);
  const double rmin = std::max(1.5 * s, 0.5 * unit);
  const double rA0 = std::max(rmin, rng.uniform(1.5, 3.5) * s), rB0 = std::max(rmin, rng.uniform(1.5, 3.5) * s);
  const double r0 = std::max(rng.uniform(3.0, 4.5) * s, 1.1 * std::max(rA0, rB0));
  const double Lt = rng.uniform(10.0, 18.0) * s;
  const double Lb1 = rng.uniform(8.0, 14.0) * s, Lb2 = rng.uniform(10.0, 16.0) * s, Ls = rng.uniform(25.0, 40.0) * s;
  const double Ld = rng.uniform(12.0, 20.0) * s, D = rng.uniform(8.0, 14.0) * s, M = rng.uniform(5.0, 9.0) * s;
  const double LA = Lb1 + Lb2 + Ls + rng.uniform(10.0, 20.0) * s, LB = Lb1 + Lb2 + Ls + Ld;
  const double bendAmp = rng.uniform(0.0, 6.0) * s, total = Lt + std::max(LA, LB);
  auto spine = [&](double t) { return Vec3(t * e + bendAmp * std::sin(M_PI * t / total) * w); };
  auto rA = [&](double t) { return rA0 * (1.0 - 0.2 * t / LA); };
  auto rB = [&](double t) { return rB0 * (1.0 - 0.2 * t / LB); };
  auto c = [&](double t) { return rA(t) + rB(t) + g; };
  const double peak = c(Lb1) + M;
  auto off = [&](double t) {
    if (t < Lb1) return peak * std::sin(0.5 * M_PI * t / Lb1);
    if (t < Lb1 + Lb2) return c(t) + (peak - c(Lb1)) * 0.5 * (1 + std::cos(M_PI * (t - Lb1) / Lb2));
    if (t < Lb1 + Lb2 + Ls) return c(t);
    return c(t) + D * (1 - std::cos(0.5 * M_PI * (t - Lb1 - Lb2 - Ls) / Ld));
  };
  const double step = 0.5 * s;
  std::vector<Tube> tubes(3);
  const int nt = std::max(2, static_cast<int>(std::ceil(Lt / step)));
  for (int j = 0; j <= nt; ++j) {
    tubes[0].pts.push_back(spine(Lt * j / nt));
    tubes[0].r.push_back(r0);
  }
  const double len[2] = {LA, LB};
  for (int b = 1; b <= 2; ++b) {
    Tube& t = tubes[size_t(b)];
    t.parent = 0;
    t.depth = 1;
    const int nb = static_cast<int>(std::ceil(len[b - 1] / step));
    for (int j = 0; j <= nb; ++j) {
      const double x = len[b - 1] * j / nb;
      t.pts.push_back(spine(Lt + x) + (b == 2 ? off(x) : 0.0) * u);
      t.r.push_back(b == 1 ? rA(x) : rB(x));
    }
  }
  return tubes;
}

// Max partial-volume coverage of the capsule [a, e] (radii ra, rb) over the volume; the contrast of
// the segment that covers a voxel most.
void renderSegment(const Geometry& geom, double unit, const Vec3& a, const Vec3& e, double ra, double rb, double c0,
                   double c1, std::vector<float>& cov, std::vector<float>& contrast) {
  const Vec3& s = geom.spacing;
  const double reach = std::max(ra, rb) + unit;
  int64_t lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::max<int64_t>(0, static_cast<int64_t>(std::floor((std::min(a[i], e[i]) - reach) / s[i])));
    hi[i] = std::min<int64_t>(geom.dims[i] - 1, static_cast<int64_t>(std::ceil((std::max(a[i], e[i]) + reach) / s[i])));
  }
  const Vec3 ab = e - a;
  const double ab2 = std::max(ab.squaredNorm(), 1e-18);
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const Vec3 p(double(x) * s[0], double(y) * s[1], double(z) * s[2]);
        const double t = std::clamp((p - a).dot(ab) / ab2, 0.0, 1.0);
        const Vec3 dv = p - (a + t * ab);
        const double d = dv.norm();
        const double sd = d - (ra + t * (rb - ra));
        if (sd > unit) continue;
        const Vec3 n = d > 1e-12 ? Vec3(dv / d) : Vec3(1, 0, 0);
        const float cv = static_cast<float>(coverage(sd, voxelExtentAlong(n, s)));
        const size_t i = static_cast<size_t>(geom.linear(x, y, z));
        if (cv > cov[i]) {
          cov[i] = cv;
          contrast[i] = static_cast<float>(c0 + t * (c1 - c0));
        }
      }
}

// The same for a straight elliptic cylinder [a, e] (semi-axes A along `major`, B across; ellipsoidal caps of
// semi-axis B along the axis), contrast c0 -> c1: the signed distance to its wall to first order (the level
// k - 1 of k = |section point / semi-axes| over k's gradient), the normal along that gradient.
void renderFlatSegment(const Geometry& geom, double unit, const Vec3& a, const Vec3& e, double A, double B,
                       const Vec3& major, double c0, double c1, std::vector<float>& cov, std::vector<float>& contrast) {
  const Vec3& s = geom.spacing;
  const double reach = A + unit;
  int64_t lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::max<int64_t>(0, static_cast<int64_t>(std::floor((std::min(a[i], e[i]) - reach) / s[i])));
    hi[i] = std::min<int64_t>(geom.dims[i] - 1, static_cast<int64_t>(std::ceil((std::max(a[i], e[i]) + reach) / s[i])));
  }
  const double len = std::max((e - a).norm(), 1e-9);
  const Vec3 axis = (e - a) / len, minor = axis.cross(major);
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const Vec3 p(double(x) * s[0], double(y) * s[1], double(z) * s[2]);
        const double t = (p - a).dot(axis), over = t < 0 ? t : (t > len ? t - len : 0.0);
        const Vec3 dv = p - a - t * axis;
        const double xa = dv.dot(major), xb = dv.dot(minor);
        const double k = std::sqrt((xa / A) * (xa / A) + (xb / B) * (xb / B) + (over / B) * (over / B));
        const Vec3 g = (xa / (A * A)) * major + (xb / (B * B)) * minor + (over / (B * B)) * axis;
        const double gn = g.norm();
        const double sd = k > 1e-12 && gn > 1e-12 ? (k * k - 1) / (2 * gn) : -B;  // (k^2 - 1) / |grad k^2|
        if (sd > unit) continue;
        const Vec3 n = gn > 1e-12 ? Vec3(g / gn) : Vec3(minor);
        const float cv = static_cast<float>(coverage(sd, voxelExtentAlong(n, s)));
        const size_t i = static_cast<size_t>(geom.linear(x, y, z));
        if (cv > cov[i]) {
          cov[i] = cv;
          contrast[i] = static_cast<float>(c0 + std::clamp(t / len, 0.0, 1.0) * (c1 - c0));
        }
      }
}

// Places the tubes in a volume sized to them (3 voxels of margin on every face, the root and the
// terminals on voxel centres), renders them (fg on bg, contrast falling by `falloff` along the path
// length from the root) and writes the truth.
void placeAndRender(std::vector<Tube> tubes, const Vec3& sp, double falloff, double fg, double bg, uint64_t seed,
                    VolumeF32& volume, VesselTruth& T) {
  const double unit = sp.maxCoeff();
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Tube& t : tubes)
    for (size_t k = 0; k < t.pts.size(); ++k) {
      lo = lo.cwiseMin(t.pts[k] - Vec3::Constant(t.reach(k)));
      hi = hi.cwiseMax(t.pts[k] + Vec3::Constant(t.reach(k)));
    }
  Vec3 shift = 3 * sp - lo;
  const Vec3 root = tubes[0].pts[0] + shift;
  for (int i = 0; i < 3; ++i) shift[i] += std::round(root[i] / sp[i]) * sp[i] - root[i] + sp[i];
  Geometry geom;
  for (int i = 0; i < 3; ++i) geom.dims[i] = static_cast<int64_t>(std::ceil((hi[i] - lo[i] + 7 * sp[i]) / sp[i])) + 1;
  geom.spacing = sp;
  for (Tube& t : tubes)
    for (Vec3& p : t.pts) p += shift;
  std::vector<bool> leaf(tubes.size(), true);
  for (const Tube& t : tubes)
    if (t.parent >= 0) leaf[size_t(t.parent)] = false;
  for (size_t i = 0; i < tubes.size(); ++i)
    if (leaf[i]) {  // the terminal on a voxel centre; the children's first points follow their parent's last
      Vec3& p = tubes[i].pts.back();
      for (int k = 0; k < 3; ++k) p[k] = std::round(p[k] / sp[k]) * sp[k];
    }
  for (Tube& t : tubes)
    if (t.parent >= 0) t.pts.front() = tubes[size_t(t.parent)].pts.back();
  std::vector<double> arcStart(tubes.size(), 0.0);
  double maxArc = 0;
  for (size_t i = 0; i < tubes.size(); ++i) {
    if (tubes[i].parent >= 0) arcStart[i] = arcStart[size_t(tubes[i].parent)] + tubes[size_t(tubes[i].parent)].arc();
    maxArc = std::max(maxArc, arcStart[i] + tubes[i].arc());
  }
  std::vector<float> cov(size_t(geom.voxelCount()), 0.0f), contrast(cov.size(), 1.0f);
  for (size_t i = 0; i < tubes.size(); ++i) {
    const Tube& t = tubes[i];
    double arc = arcStart[i];
    for (size_t k = 0; k + 1 < t.pts.size(); ++k) {
      const double next = arc + (t.pts[k + 1] - t.pts[k]).norm();
      if (t.semiMinor > 0)
        renderFlatSegment(geom, unit, t.pts[k], t.pts[k + 1], t.semiMajor, t.semiMinor, t.major,
                          1.0 - falloff * arc / maxArc, 1.0 - falloff * next / maxArc, cov, contrast);
      else
        renderSegment(geom, unit, t.pts[k], t.pts[k + 1], t.r[k], t.r[k + 1], 1.0 - falloff * arc / maxArc,
                      1.0 - falloff * next / maxArc, cov, contrast);
      arc = next;
    }
  }
  volume = VolumeF32(geom, 0.0f);
  float* v = volume.data();
  for (size_t i = 0; i < cov.size(); ++i) v[i] = static_cast<float>(bg + (fg - bg) * cov[i] * contrast[i]);
  T = VesselTruth();
  T.seed = seed;
  T.dims = geom.dims;
  T.spacing = sp;
  T.background = bg;
  T.foreground = fg;
  T.iso = 0.5 * (bg + fg);
  T.radiusUnitMm = unit;
  T.clearanceMm = 0;  // kissing vessels touch: no guaranteed gap
  for (size_t i = 0; i < tubes.size(); ++i) {
    VesselBranch b;
    b.parent = tubes[i].parent;
    b.depth = tubes[i].depth;
    for (size_t j = 0; j < tubes.size(); ++j)
      if (tubes[j].parent == static_cast<int>(i)) b.children.push_back(static_cast<int>(j));
    for (const Vec3& p : tubes[i].pts) b.points.push_back(p.cwiseQuotient(sp));
    b.radiiMm = tubes[i].r;
    T.branches.push_back(std::move(b));
  }
  phantom_detail::addRootTerminalsAndBranchPoints(T);
}

}  // namespace

VesselFamilyVariant vesselFamilyVariantOf(uint64_t seed) {
  // Its own stream: the thin tree's draws are those from before the variants existed.
  PhantomRng variantRng(PhantomRng::derive(seed, 0x7a71));
  return static_cast<VesselFamilyVariant>(variantRng.integer(0, 3));
}

VesselFamilyCase makeVesselFamilyCase(uint64_t seed, const Index3& dims) {
  return makeVesselFamilyCase(seed, vesselFamilyVariantOf(seed), dims);
}

VesselFamilyCase makeVesselFamilyCase(uint64_t seed, VesselFamilyVariant variant, const Index3& dims) {
  return makeVesselFamilyCase(seed, variant, dims, false);
}

VesselFamilyCase makeVesselFamilyBoneCase(uint64_t seed, const Index3& dims) {
  return makeVesselFamilyCase(seed, vesselFamilyVariantOf(seed), dims, true);
}

// bone: the case bright with bone blocks (their own stream: every other draw as without).
VesselFamilyCase phantom_detail::makeVesselFamilyCase(uint64_t seed, VesselFamilyVariant variant, const Index3& dims,
                                                      bool bone) {
  PhantomRng rng(PhantomRng::derive(seed, 0xfa11));
  VesselFamilyCase out;
  out.variant = variant;
  const double s = rng.uniform(0.6, 1.0);
  out.anisotropy = rng.uniform(1.0, 3.0);
  out.falloff = rng.uniform(0.3, 0.6);
  out.bias = rng.uniform(0.0, 0.4);
  out.rician = rng.uniform(5.0, 15.0);
  out.dark = rng.uniform() < 0.5;
  VesselPhantomOptions o;
  o.seed = seed;
  o.dims = dims;
  o.spacing = Vec3(s, s, s * out.anisotropy);
  o.noiseSigma = 0;
  if (variant == VesselFamilyVariant::Thin) {
    // Radii in the generator's unit (the largest spacing): 4 -> 0.8 voxels of the smallest spacing.
    o.minRadius = std::max(0.5, 0.8 / out.anisotropy);
    o.rootRadius = std::max(o.minRadius, 4.0 / out.anisotropy);
    o.minTerminals = 4;
    o.maxTerminals = 8;
    o.contrastFalloff = out.falloff;
    o.branchAngleMinDeg = 10;
    o.branchAngleMaxDeg = 60;
    const VesselPhantom ph = makeVesselPhantom(o);
    out.truth = ph.truth;
    out.volume = toFloat(AnyVolume(ph.volume));
  } else {
    PhantomRng geo(PhantomRng::derive(seed, 0x9e0));
    const double unit = o.spacing.maxCoeff();
    std::vector<Tube> tubes;
    if (variant == VesselFamilyVariant::WideLumen) {
      out.lumenRadiusVoxels = geo.uniform(8.0, 25.0);
      tubes = wideLumen(geo, s, out.lumenRadiusVoxels * s, unit);
    } else if (variant == VesselFamilyVariant::Flat) {  // its own stream: never drawn by a seed
      PhantomRng flat(PhantomRng::derive(seed, 0xf1a7));
      out.lumenRadiusVoxels = flat.uniform(5.0, 25.0);
      out.flatAspect = flat.uniform(2.0, 3.0);
      tubes = wideLumen(flat, s, out.lumenRadiusVoxels * s, unit, out.flatAspect);
    } else {
      out.gapVoxels = variant == VesselFamilyVariant::Kissing ? geo.uniform(0.0, 1.0) : geo.uniform(2.0, 4.0);
      tubes = sideBySide(geo, s, out.gapVoxels * s, unit);
    }
    placeAndRender(std::move(tubes), o.spacing, out.falloff, o.foreground, o.background, seed, out.volume, out.truth);
  }
  if (bone) {
    out.dark = false;  // bone is brighter than a contrast lumen
    PhantomRng boneRng(PhantomRng::derive(seed, 0xb0e5));
    addBoneBlocks(boneRng, out);
  }
  // Bias: 1 + bias * f, f in [-1/2, 1/2], a smooth wave along a random direction.
  Vec3 dir(rng.normal(), rng.normal(), rng.normal());
  dir.normalize();
  const double phase = rng.uniform(0.0, 2 * M_PI);
  const Geometry& g = out.volume.geometry();
  const Index3 vd = g.dims;
  const double extent = (g.spacing.cwiseProduct(Vec3(double(vd[0]), double(vd[1]), double(vd[2])))).norm();
  PhantomRng noise(PhantomRng::derive(seed, 0x51c3));
  const double fg = o.foreground, bg = o.background;
  for (int64_t z = 0; z < vd[2]; ++z)
    for (int64_t y = 0; y < vd[1]; ++y)
      for (int64_t x = 0; x < vd[0]; ++x) {
        const Vec3 p = g.spacing.cwiseProduct(Vec3(double(x), double(y), double(z)));
        const double f = 0.5 * std::sin(phase + 2 * M_PI * p.dot(dir) / extent);
        double v = out.volume(x, y, z);
        if (out.dark) v = fg + bg - v;
        v *= 1.0 + out.bias * f;
        const double a = v + noise.normal(0, out.rician), b = noise.normal(0, out.rician);
        out.volume(x, y, z) = static_cast<float>(std::sqrt(a * a + b * b));
      }
  return out;
}

}  // namespace vs
