// Tube phantoms for quantification (see tube_phantom.h).
#include "phantom/tube_phantom.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "phantom/phantom_internal.h"
#include "util/error.h"
#include "util/parallel.h"
#include "volume/plane_basis.h"

namespace vs {

namespace {
constexpr double kPi = std::numbers::pi;

Vec3 randomUnit(PhantomRng& rng) {
  while (true) {
    const Vec3 v(rng.normal(), rng.normal(), rng.normal());
    if (v.norm() > 1e-6) return v.normalized();
  }
}

Vec3 perpendicular(const Vec3& t, PhantomRng& rng) {
  while (true) {
    const Vec3 r = randomUnit(rng);
    const Vec3 p = r - r.dot(t) * t;
    if (p.norm() > 0.1) return p.normalized();
  }
}

// Lower bound of the signed distance (mm, < 0 inside) of x to a branch (capped tube).
double branchDistance(const TubeBranch& b, const Vec3& x) {
  double s, da, db;
  if (!b.arc) {
    const Vec3 w = x - b.p0;
    s = w.dot(b.dir);
    const Vec3 d = w - s * b.dir;
    const Vec3 eb = b.dir.cross(b.aAxis);
    da = d.dot(b.aAxis), db = d.dot(eb);
  } else {
    const Vec3 w = x - b.centre;
    const Vec3 n = b.aAxis;
    const double px = w.dot(b.e1), py = w.dot(b.e2);
    const double span = b.lengthMm / b.curvatureRadiusMm;
    double phi = std::atan2(py, px);
    if (phi < 0.5 * span - kPi) phi += 2 * kPi;
    s = b.curvatureRadiusMm * phi;
    const Vec3 er = std::cos(phi) * b.e1 + std::sin(phi) * b.e2;
    const Vec3 d = w - b.curvatureRadiusMm * er;
    da = d.dot(n), db = d.dot(er);
  }
  const double sc = std::clamp(s, 0.0, b.lengthMm);
  const double a = b.semiA(sc), bb = b.semiB(sc);
  const double rho = std::sqrt((da / a) * (da / a) + (db / bb) * (db / bb));
  const double radial = (rho - 1) * std::min(a, bb);
  return std::max({radial, -s, s - b.lengthMm});
}

void gaussianBlur(VolumeF32& v, double sigmaMm) {
  if (sigmaMm <= 0) return;
  const Index3 d = v.dims();
  const Vec3 sp = v.geometry().spacing;
  for (int axis = 0; axis < 3; ++axis) {
    const double sigma = sigmaMm / sp[axis];
    const int rad = static_cast<int>(std::ceil(3 * sigma));
    if (rad < 1 || d[static_cast<size_t>(axis)] < 2) continue;
    std::vector<double> k(static_cast<size_t>(2 * rad + 1));
    double sum = 0;
    for (int i = -rad; i <= rad; ++i) sum += k[static_cast<size_t>(i + rad)] = std::exp(-0.5 * i * i / (sigma * sigma));
    for (auto& x : k) x /= sum;
    const int64_t n = d[static_cast<size_t>(axis)];
    const int64_t stride = axis == 0 ? 1 : axis == 1 ? d[0] : d[0] * d[1];
    const int64_t lines = v.size() / n;
    float* data = v.data();
    parallelFor(0, lines, [&](int64_t b, int64_t e) {
      std::vector<double> line(static_cast<size_t>(n));
      for (int64_t l = b; l < e; ++l) {
        int64_t base;
        if (axis == 0)
          base = l * n;
        else if (axis == 1)
          base = (l / d[0]) * d[0] * d[1] + l % d[0];
        else
          base = l;
        for (int64_t i = 0; i < n; ++i) line[static_cast<size_t>(i)] = data[base + i * stride];
        for (int64_t i = 0; i < n; ++i) {
          double acc = 0;
          for (int q = -rad; q <= rad; ++q) {
            const int64_t j = std::clamp<int64_t>(i + q, 0, n - 1);
            acc += k[static_cast<size_t>(q + rad)] * line[static_cast<size_t>(j)];
          }
          data[base + i * stride] = static_cast<float>(acc);
        }
      }
    });
  }
}
}  // namespace

std::string tubeKindName(TubeKind k) {
  switch (k) {
    case TubeKind::Straight:
      return "straight";
    case TubeKind::Curved:
      return "curved";
    case TubeKind::Taper:
      return "taper";
    case TubeKind::Elliptic:
      return "elliptic";
    case TubeKind::Stenosis:
      return "stenosis";
    case TubeKind::Bifurcation:
      return "bifurcation";
  }
  return "straight";
}

TubeKind tubeKindFromName(const std::string& n) {
  for (TubeKind k : {TubeKind::Straight, TubeKind::Curved, TubeKind::Taper, TubeKind::Elliptic, TubeKind::Stenosis,
                     TubeKind::Bifurcation})
    if (tubeKindName(k) == n) return k;
  throw InvalidArgument("tube phantom kind must be straight, curved, taper, elliptic, stenosis or bifurcation, got '" +
                        n + "'");
}

Vec3 TubeBranch::at(double s) const {
  if (!arc) return p0 + s * dir;
  const double phi = s / curvatureRadiusMm;
  return centre + curvatureRadiusMm * (std::cos(phi) * e1 + std::sin(phi) * e2);
}

Vec3 TubeBranch::tangent(double s) const {
  if (!arc) return dir;
  const double phi = s / curvatureRadiusMm;
  return -std::sin(phi) * e1 + std::cos(phi) * e2;
}

double TubeBranch::profile(double s) const {
  double p = 1 + (taperEnd - 1) * std::clamp(s / std::max(lengthMm, 1e-9), 0.0, 1.0);
  // The lesion: a plateau of (1 - degree) over the middle half of its length, cosine shoulders
  // over a quarter on each side.
  const double x = std::abs(s - stenosisCentreMm) / stenosisLengthMm;  // 0 .. 0.5 inside the lesion
  if (stenosisDegree > 0 && x < 0.5) {
    const double depth = x <= 0.25 ? 1.0 : 0.5 * (1 + std::cos(kPi * (x - 0.25) / 0.25));
    p *= 1 - stenosisDegree * depth;
  }
  return p;
}

double TubeBranch::semiA(double s) const { return radiusMm * profile(s) * std::sqrt(aspect); }
double TubeBranch::semiB(double s) const { return radiusMm * profile(s) / std::sqrt(aspect); }
double TubeBranch::equivalentRadiusMm(double s) const { return radiusMm * profile(s); }

TubePhantom makeTubePhantom(const TubePhantomOptions& o, Progress& progress) {
  using phantom_detail::requireFiniteIn;
  requireFiniteIn(o.radiusVoxels, 0.5, 20, "tube phantom: radius (voxels)");
  requireFiniteIn(o.noiseSigma, 0, 1e4, "tube phantom: noise sigma");
  requireFiniteIn(o.background, -1e4, 1e4, "tube phantom: background");
  requireFiniteIn(o.foreground, -1e4, 1e4, "tube phantom: foreground");
  if (o.background == o.foreground) throw InvalidArgument("tube phantom: foreground equals background");
  PhantomRng rng(PhantomRng::derive(o.seed, 0x7b5e));
  Vec3 sp = o.spacing;
  if (!(sp.minCoeff() > 0)) {
    const double s0 = rng.uniform(0.4, 0.8), k = rng.uniform(1.0, 2.0);
    sp = Vec3(s0, s0, s0);
    sp[rng.integer(0, 2)] *= k;
  } else {
    phantom_detail::requireSpacing(sp, "tube phantom");
  }
  TubeTruth T;
  T.seed = o.seed;
  T.kind = o.kind;
  T.spacing = sp;
  T.radiusUnitMm = sp.maxCoeff();
  T.background = o.background;
  T.foreground = o.foreground;
  T.noiseSigma = o.noiseSigma;
  T.blurMm = o.blurMm < 0 ? 0.5 * sp.minCoeff() : o.blurMm;
  const double r = o.radiusVoxels * T.radiusUnitMm;
  auto pick = [&](double given, double lo, double hi, const char* what) {
    if (std::isnan(given)) return rng.uniform(lo, hi);
    requireFiniteIn(given, lo, hi, std::string("tube phantom: ") + what);
    return given;
  };
  const double stenosis = pick(o.stenosisDegree, 0.2, 0.8, "stenosis degree");
  const double stenosisLen = pick(o.stenosisLengthMm, 3, 15, "stenosis length (mm)");
  const double angle = pick(o.bifurcationDeg, 30, 120, "bifurcation angle (degrees)");
  const double aspect = pick(o.aspect, 1.3, 2.0, "aspect");
  const double taper = pick(o.taperRatio, 0.4, 0.7, "taper ratio");
  double side = std::max(24.0, 7 * r + 12 * T.radiusUnitMm);
  if (o.kind == TubeKind::Stenosis) side = std::max(side, 2 * stenosisLen + 8 * r);
  if (o.kind == TubeKind::Bifurcation) side = std::max(side, 16 * r);
  for (int a = 0; a < 3; ++a) T.dims[static_cast<size_t>(a)] = static_cast<int64_t>(std::ceil(side / sp[a])) + 1;
  if (static_cast<double>(T.dims[0]) * static_cast<double>(T.dims[1]) * static_cast<double>(T.dims[2]) > 4e7)
    throw InvalidArgument("tube phantom: " + std::to_string(T.dims[0]) + "x" + std::to_string(T.dims[1]) + "x" +
                          std::to_string(T.dims[2]) + " voxels is too large: use a smaller radius or coarser spacing");
  const Vec3 extent((T.dims[0] - 1) * sp[0], (T.dims[1] - 1) * sp[1], (T.dims[2] - 1) * sp[2]);
  const Vec3 C = 0.5 * extent + Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 0.05 * side;
  const double half = 0.5 * extent.norm() + 2 * r;
  const Vec3 dir = randomUnit(rng);

  TubeBranch main;
  main.radiusMm = r;
  main.dir = dir;
  main.aAxis = perpendicular(dir, rng);
  switch (o.kind) {
    case TubeKind::Curved: {
      main.arc = true;
      main.curvatureRadiusMm = rng.uniform(std::max(4 * r, 0.35 * side), 0.9 * side);
      const Vec3 n = perpendicular(dir, rng).cross(dir).normalized();  // arc normal
      const Vec3 out = n.cross(dir).normalized();                      // from the arc's centre to C
      main.centre = C - main.curvatureRadiusMm * out;
      const double span = std::min(1.6 * kPi, 2 * half / main.curvatureRadiusMm);
      // Start at angle 0: e1 rotated back by span/2 from `out`.
      main.e1 = std::cos(-0.5 * span) * out + std::sin(-0.5 * span) * dir;
      main.e2 = main.e1.cross(n).normalized();  // at angle span/2 the arc passes through C
      main.aAxis = n;
      main.lengthMm = span * main.curvatureRadiusMm;
      break;
    }
    default:
      main.p0 = C - half * dir;
      main.lengthMm = (o.kind == TubeKind::Bifurcation ? 1 : 2) * half;
      break;
  }
  if (o.kind == TubeKind::Taper) main.taperEnd = taper;
  if (o.kind == TubeKind::Elliptic) main.aspect = aspect;
  if (o.kind == TubeKind::Stenosis) {
    main.stenosisDegree = stenosis;
    main.stenosisLengthMm = stenosisLen;
    main.stenosisCentreMm = half + rng.uniform(-0.1, 0.1) * side;
  }
  T.branches.push_back(main);
  if (o.kind == TubeKind::Bifurcation) {
    T.bifurcationDeg = angle;
    T.junctionMm = C;
    const Vec3 q = perpendicular(dir, rng);
    const double h = 0.5 * angle * kPi / 180;
    for (double sgn : {1.0, -1.0}) {
      TubeBranch c;
      c.parent = 0;
      c.radiusMm = 0.8 * r;
      c.dir = (std::cos(h) * dir + sgn * std::sin(h) * q).normalized();
      c.aAxis = perpendicular(c.dir, rng);
      c.p0 = C;
      c.lengthMm = half;
      T.branches.push_back(c);
    }
  }

  // Render: partial volume by 4x4x4 sub-samples near the surface.
  Geometry g;
  g.dims = T.dims;
  g.spacing = sp;
  VolumeF32 vol(g, static_cast<float>(o.background));
  const double h = 0.5 * sp.norm() * 1.05;
  const bool junction = o.kind == TubeKind::Bifurcation;
  auto sdf = [&](const Vec3& x) {
    double best = 1e300;
    for (const auto& b : T.branches) best = std::min(best, branchDistance(b, x));
    if (junction) best = std::min(best, (x - T.junctionMm).norm() - r);
    return best;
  };
  const double contrast = o.foreground - o.background;
  parallelFor(0, T.dims[2], [&](int64_t z0, int64_t z1) {
    for (int64_t z = z0; z < z1; ++z)
      for (int64_t y = 0; y < T.dims[1]; ++y)
        for (int64_t x = 0; x < T.dims[0]; ++x) {
          const Vec3 p(x * sp[0], y * sp[1], z * sp[2]);
          const double d = sdf(p);
          double frac;
          if (d > h) {
            continue;
          } else if (d < -h) {
            frac = 1;
          } else {
            int in = 0;
            for (int k = 0; k < 64; ++k) {
              const Vec3 off((k % 4 + 0.5) / 4 - 0.5, ((k / 4) % 4 + 0.5) / 4 - 0.5, (k / 16 + 0.5) / 4 - 0.5);
              in += sdf(p + off.cwiseProduct(sp)) <= 0;
            }
            frac = in / 64.0;
          }
          vol(x, y, z) = static_cast<float>(o.background + contrast * frac);
        }
  });
  progress.report(0.5, "tube phantom");
  progress.check();
  gaussianBlur(vol, T.blurMm);
  if (o.noiseSigma > 0) {
    PhantomRng nrng(PhantomRng::derive(o.seed, 0x91c3));
    for (auto& v : vol.voxels()) {
      const double a = v + o.noiseSigma * nrng.normal(), b = o.noiseSigma * nrng.normal();
      v = static_cast<float>(std::sqrt(a * a + b * b));
    }
  }
  progress.report(1.0, "tube phantom");
  return {std::move(vol), std::move(T)};
}

std::vector<double> tubeArcsInside(const TubeTruth& t, int branch, double marginMm, double stepMm) {
  VS_REQUIRE(branch >= 0 && branch < static_cast<int>(t.branches.size()), "tubeArcsInside: bad branch");
  VS_REQUIRE(stepMm > 0, "tubeArcsInside: step must be > 0");
  const TubeBranch& b = t.branches[static_cast<size_t>(branch)];
  const Vec3 hi((t.dims[0] - 1) * t.spacing[0], (t.dims[1] - 1) * t.spacing[1], (t.dims[2] - 1) * t.spacing[2]);
  std::vector<double> out;
  for (double s = 0; s <= b.lengthMm; s += stepMm) {
    const Vec3 p = b.at(s);
    if ((p.array() >= marginMm).all() && (p.array() <= hi.array() - marginMm).all()) out.push_back(s);
  }
  return out;
}

Tree tubeTruthTree(const TubeTruth& t, double jitterMm, double hintFactor, double stepMm) {
  Tree tree;
  auto add = [&](const TubeBranch& b, double s, int32_t parent) {
    const Vec3 tan = b.tangent(s);
    const PlaneBasis basis = unitPlaneBasis(tan);
    const Vec3 &u = basis.u, &v = basis.v;
    const Vec3 off = jitterMm * (std::sin(s / 4.0 + 0.3) * u + std::cos(s / 6.0 + 1.1) * v);
    tree.points.push_back(b.at(s) + off);
    tree.parent.push_back(parent);
    tree.radii.push_back(hintFactor * b.equivalentRadiusMm(s));
    tree.types.push_back(3);
    return static_cast<int32_t>(tree.points.size() - 1);
  };
  const double margin = 0.5 * t.spacing.maxCoeff();
  std::vector<double> s0 = tubeArcsInside(t, 0, margin, stepMm);
  if (t.kind == TubeKind::Bifurcation) s0.push_back(t.branches[0].lengthMm);
  int32_t prev = -1;
  for (double s : s0) prev = add(t.branches[0], s, prev);
  const int32_t junction = prev;
  for (size_t b = 1; b < t.branches.size(); ++b) {
    int32_t p = junction;
    for (double s : tubeArcsInside(t, static_cast<int>(b), margin, stepMm))
      if (s > 0) p = add(t.branches[b], s, p);
  }
  return tree;
}

TubeNearest nearestTubeCentre(const TubeTruth& t, const Vec3& p) {
  TubeNearest best;
  for (size_t b = 0; b < t.branches.size(); ++b) {
    const TubeBranch& br = t.branches[b];
    double bs = 0, bd = 1e300;
    for (double s = 0; s <= br.lengthMm; s += 0.25) {
      const double d = (br.at(s) - p).norm();
      if (d < bd) bd = d, bs = s;
    }
    for (double s = std::max(0.0, bs - 0.25); s <= std::min(br.lengthMm, bs + 0.25); s += 0.005) {
      const double d = (br.at(s) - p).norm();
      if (d < bd) bd = d, bs = s;
    }
    if (bd < best.distanceMm) best = {static_cast<int>(b), bs, bd};
  }
  return best;
}

TubeDiameterErrors tubeDiameterErrors(const TubeTruth& t, const std::vector<Vec3>& centres,
                                      const std::vector<double>& diameters) {
  VS_REQUIRE(centres.size() == diameters.size(), "tubeDiameterErrors: one diameter per centre");
  TubeDiameterErrors st;
  for (size_t i = 0; i < centres.size(); ++i) {
    const TubeNearest n = nearestTubeCentre(t, centres[i]);
    const double truth = 2 * t.branches[static_cast<size_t>(n.branch)].equivalentRadiusMm(n.s);
    const double e = diameters[i] - truth;
    st.meanAbsVoxels += std::abs(e) / t.radiusUnitMm;
    st.meanVoxels += e / t.radiusUnitMm;
    st.meanAbsRelative += std::abs(e) / truth;
    ++st.count;
  }
  if (st.count > 0) {
    st.meanAbsVoxels /= st.count;
    st.meanVoxels /= st.count;
    st.meanAbsRelative /= st.count;
  }
  return st;
}

}  // namespace vs
