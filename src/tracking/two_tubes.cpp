// A lumen model per tube where two kissing tubes are fused into one blob (session 29 kiss25): the blob's
// cross-sections fitted as one blurred disc and as two. See centreline_junctions.h.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

namespace {

using Vec2 = Eigen::Vector2d;
using VecX = Eigen::VectorXd;

// From point k along its plain chain (up: towards the root; down: its one child), the first point whose radius is at
// most `limit` within `reachMm` along the input points (`along`: the distance walked); -1 where a branch point, a
// placed (frozen) point, an end or the reach comes first.
int64_t narrowerAlong(const JunctionInput& in, const std::vector<uint8_t>& frozen, size_t k, bool up, double limit,
                      double reachMm, double& along) {
  along = 0;
  for (size_t at = k;;) {
    const int64_t next = up ? in.parent[at] : in.children[at].size() == 1 ? in.children[at][0] : -1;
    if (next < 0) return -1;
    const size_t j = static_cast<size_t>(next);
    along += (in.raw(j) - in.raw(at)).norm();
    if (along > reachMm || frozen[j]) return -1;
    if (in.radius[j] <= limit) return next;
    if (in.children[j].size() != 1) return -1;  // a branch point or an end before a narrower point
    at = j;
  }
}

// A cross-section's samples (plane coordinates, mm) and values; nEff: the independent samples it holds (its area
// over the voxel's extent along both plane axes: trilinear samples across a thick slice are not independent).
struct Samples {
  std::vector<Vec2> p;
  VecX v;
  double nEff = 0;
};

// A partial-volume-blurred disc: the share of lumen at p of a disc (centre c, radius r) blurred by a Gaussian (s).
double disc(const Vec2& p, const Vec2& c, double r, double s) {
  return 0.5 * std::erfc(((p - c).norm() - r) / (std::sqrt(2.0) * s));
}

using Shape = std::function<double(const VecX&, const Vec2&)>;

// The residuals of the values against background + contrast x shape(theta) (both levels by least squares).
double residuals(const Samples& s, const Shape& f, const VecX& th, VecX& res, double& contrast) {
  const Eigen::Index n = s.v.size();
  VecX shape(n);
  for (Eigen::Index i = 0; i < n; ++i) shape[i] = f(th, s.p[static_cast<size_t>(i)]);
  const double ms = shape.mean(), mv = s.v.mean();
  const double sxx = (shape.array() - ms).square().sum();
  contrast = sxx > 1e-12 ? ((shape.array() - ms) * (s.v.array() - mv)).sum() / sxx : 0.0;
  res = s.v - (VecX::Constant(n, mv - contrast * ms) + contrast * shape);
  return res.squaredNorm();
}

// Levenberg-Marquardt (forward-difference Jacobian) from th; returns the residual sum of squares.
double fitShape(const Samples& s, const Shape& f, VecX& th, double& contrast) {
  VecX r, r2;
  double cost = residuals(s, f, th, r, contrast), lambda = 1e-3, c2 = 0;
  for (int it = 0; it < 60; ++it) {
    Eigen::MatrixXd J(r.size(), th.size());
    for (Eigen::Index j = 0; j < th.size(); ++j) {
      VecX t = th;
      const double h = 1e-5 * std::max(1.0, std::abs(th[j]));
      t[j] += h;
      residuals(s, f, t, r2, c2);
      J.col(j) = (r2 - r) / h;
    }
    const Eigen::MatrixXd A = J.transpose() * J;
    const VecX g = J.transpose() * r;
    bool better = false;
    for (int tries = 0; tries < 12 && !better; ++tries, lambda *= 10) {
      Eigen::MatrixXd Ad = A;
      Ad.diagonal() += lambda * A.diagonal() + VecX::Constant(th.size(), 1e-12);
      const VecX t = th - Ad.ldlt().solve(g);
      const double c = residuals(s, f, t, r2, c2);
      if (c < cost) {
        better = cost - c > 1e-9 * cost;
        th = t, r = r2, cost = c, contrast = c2, lambda *= 0.03;
        if (!better) return cost;
      }
    }
    if (!better) break;
  }
  return cost;
}

// Point k's fit: whether two discs explain its section decisively better, and the own disc's centre (mm).
struct TubeFit {
  bool decisive = false, shape = false;            // shape: decisive before the corroboration
  Vec3 own = Vec3::Zero(), other3 = Vec3::Zero();  // the own and the other disc's centres (mm)
  double dBic = 0, sep = 0, other = 0, blur = 0, contrast = 0;
};

TubeFit fitSection(const Vec3& o, const Vec3& t, const Vec3& ownGuess, double ownR, double blobR, const Vec3& spacing,
                   const std::function<double(const Vec3&)>& value, double bicMin) {
  TubeFit out;
  Vec3 u = t.unitOrthogonal(), w = t.cross(u);
  const Vec3 toOwn = ownGuess - o - t * t.dot(ownGuess - o);
  if (toOwn.norm() > 1e-6) u = toOwn.normalized(), w = t.cross(u);
  // The window holds the blob (half-extent up to about 1.6 of its median ray) and a voxel of background round it.
  const double h = 0.5 * spacing.minCoeff(), reach = 1.6 * blobR + spacing.maxCoeff();
  Samples s;
  std::vector<double> v;
  for (double x = -reach; x <= reach; x += h)
    for (double y = -reach; y <= reach; y += h) {
      if (x * x + y * y > reach * reach) continue;
      const double val = value(o + x * u + y * w);
      if (std::isnan(val)) return out;
      s.p.emplace_back(x, y), v.push_back(val);
    }
  s.v = Eigen::Map<VecX>(v.data(), static_cast<Eigen::Index>(v.size()));
  auto extent = [&](const Vec3& d) { return 1 / d.cwiseQuotient(spacing).norm(); };
  s.nEff = M_PI * reach * reach / (extent(u) * extent(w));
  const double blur0 = std::log(0.5 * spacing.minCoeff()), tn = toOwn.norm();
  VecX one(4);
  one << 0, 0, std::log(blobR), blur0;
  double c1 = 0, c2 = 0;
  const double rss1 = fitShape(
      s, [](const VecX& th, const Vec2& p) { return disc(p, th.head<2>(), std::exp(th[2]), std::exp(th[3])); }, one,
      c1);
  // Two discs: the own at the chain's radius from the chain's line, the other beyond the blob's centre from it.
  VecX two(6);
  two << tn, 0, -std::max(tn, 0.5 * blobR), 0, std::log(blobR), blur0;
  const double rss2 = fitShape(
      s,
      [ownR](const VecX& th, const Vec2& p) {
        const double blur = std::exp(th[5]);
        return 1 - (1 - disc(p, th.head<2>(), ownR, blur)) * (1 - disc(p, th.segment<2>(2), std::exp(th[4]), blur));
      },
      two, c2);
  if (!(rss1 > 0) || !(rss2 > 0)) return out;
  // The information criterion's gain of two discs over one (Gaussian residuals, two parameters more).
  out.dBic = s.nEff * std::log(rss1 / rss2) - 2 * std::log(s.nEff), out.contrast = c2;
  out.sep = (two.head<2>() - two.segment<2>(2)).norm(), out.other = std::exp(two[4]), out.blur = std::exp(two[5]);
  out.own = o + two[0] * u + two[1] * w, out.other3 = o + two[2] * u + two[3] * w;
  // Two tubes, not one with a bulge: neither centre inside the other disc, the discs touching (within a voxel), the
  // same contrast as the one disc's.
  out.decisive = out.dBic > bicMin && out.sep >= std::max(ownR, out.other) &&
                 out.sep <= ownR + out.other + spacing.maxCoeff() && c1 * c2 > 0;
  return out;
}

// Per point its distance from the root along the input points and its count of ancestors.
void treeMeasures(const JunctionInput& in, size_t n, std::vector<double>& arc, std::vector<int>& depth) {
  arc.assign(n, -1), depth.assign(n, -1);
  std::vector<size_t> up;
  for (size_t k = 0; k < n; ++k) {
    size_t at = k;
    for (; depth[at] < 0 && in.parent[at] >= 0; at = static_cast<size_t>(in.parent[at])) up.push_back(at);
    if (depth[at] < 0) arc[at] = 0, depth[at] = 0;
    for (; !up.empty(); up.pop_back()) {
      const size_t c = up.back(), p = static_cast<size_t>(in.parent[c]);
      arc[c] = arc[p] + (in.raw(c) - in.raw(p)).norm(), depth[c] = depth[p] + 1;
    }
  }
}

// Whether the other route (j's, from their last common point `fork` on) and point k's lie apart on both sides of the
// contact: walking k's route up (to the fork) and down (its plain chain), a point farther than apartMm from every
// point of the other route comes before one nearer than togetherMm. Two routes through one lumen that part at a
// branch (the same vessel followed twice, then a fork) are together on one side; two kissing tubes are apart on
// both (session 30 kiss28).
// gap(a, b): whether the intensities between two lumen points dip towards the background (two lumens, not one).
using Gap = std::function<bool(const Vec3&, const Vec3&)>;

bool partedBothSides(const JunctionInput& in, const std::vector<Vec3>& q, size_t upFrom, size_t downFrom, size_t j,
                     size_t fork, double apartMm, double togetherMm, const Gap& gap) {
  std::vector<size_t> other{j};  // j, its descendants, then its ancestors below the fork
  for (size_t i = 0; i < other.size(); ++i)
    for (const int32_t c : in.children[other[i]]) other.push_back(static_cast<size_t>(c));
  for (int64_t at = in.parent[j]; at >= 0 && static_cast<size_t>(at) != fork; at = in.parent[static_cast<size_t>(at)])
    other.push_back(static_cast<size_t>(at));
  const auto side = [&](int64_t at, bool up) {
    for (;;) {
      if (at < 0 || static_cast<size_t>(at) == fork) return false;
      const size_t i = static_cast<size_t>(at);
      double nearest = std::numeric_limits<double>::infinity();
      size_t near = i;
      for (const size_t x : other)
        if ((q[x] - q[i]).norm() < nearest) nearest = (q[x] - q[i]).norm(), near = x;
      if (std::getenv("VS_KISS28_DEBUG"))
        std::fprintf(stderr, "[kiss28] j %zu up %d at %zu nearest %.2f apart %.2f together %.2f\n", j, int(up), i,
                     nearest, apartMm, togetherMm);
      if (nearest < togetherMm) return false;
      if (nearest > apartMm && gap(q[i], q[near])) return true;
      at = up ? in.parent[i] : in.children[i].size() == 1 ? in.children[i][0] : -1;
    }
  };
  return side(static_cast<int64_t>(upFrom), true) && side(static_cast<int64_t>(downFrom), false);
}

// Whether another traced route runs through the other disc alongside: a step of it (refined or input points), not on
// point k's route (neither its ancestor nor its descendant) and parted from it by more than forkMm along both from
// their last common point, crosses the section's plane (through o, normal t) within the other disc (centre, radius)
// at under 30 degrees from the normal - a second tube the trace itself followed beside this one. A bulge, a
// branch's ostium or a tangle's blob that two discs explain better than one has no such route through it (session
// 30 kiss28).
bool corroborated(const JunctionInput& in, const std::vector<Vec3>& q, const std::vector<double>& arc,
                  const std::vector<int>& depth, size_t k, const Vec3& o, const Vec3& t, const Vec3& centre,
                  double radius, double ownR, size_t upFrom, size_t downFrom, double forkMm, const Gap& gap) {
  const auto crosses = [&](const Vec3& a, const Vec3& b) {
    const double da = t.dot(a - o), db = t.dot(b - o);
    if (da * db > 0 || da == db || std::abs(db - da) < 0.87 * (b - a).norm()) return false;
    return (a + (b - a) * (da / (da - db)) - centre).norm() <= radius;
  };
  for (size_t j = 0; j < q.size(); ++j) {
    if (in.parent[j] < 0) continue;
    const size_t p = static_cast<size_t>(in.parent[j]);
    if (!crosses(q[p], q[j]) && !crosses(in.raw(p), in.raw(j))) continue;
    size_t a = k, b = j;
    while (depth[a] > depth[b]) a = static_cast<size_t>(in.parent[a]);
    while (depth[b] > depth[a]) b = static_cast<size_t>(in.parent[b]);
    while (a != b) a = static_cast<size_t>(in.parent[a]), b = static_cast<size_t>(in.parent[b]);
    if (a == k || a == j || a == p) continue;  // the same route
    if (arc[k] - arc[a] > forkMm && arc[p] - arc[a] > forkMm &&
        partedBothSides(in, q, upFrom, downFrom, j, a, std::max(ownR, radius), 0.5 * ownR, gap))
      return true;
  }
  return false;
}

}  // namespace

size_t fitTwoTubes(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                   const TrilinearSampler& sample, const Vec3& spacing, std::vector<Vec3>& q) {
  const auto value = [&](const Vec3& p) {
    const Vec3 i = p.cwiseQuotient(spacing);
    return sample.inside(i) ? double(sample.at(i)) : std::numeric_limits<double>::quiet_NaN();
  };
  if (!(o.fusedBumpRadii > 1) || !(o.fusedBumpReachRadii > 0) || !(o.twoTubeBic > 0) || !in.raw || o.iterations <= 0)
    return 0;
  const size_t n = q.size();
  std::vector<TubeFit> fit(n);
  std::vector<double> ownR(n, 0);
  const bool debug = std::getenv("VS_KISS25_DEBUG") != nullptr;
  std::vector<double> arc;  // per point its distance from the root along the input points
  std::vector<int> depth;   // per point its count of ancestors
  for (size_t k = 1; k < n; ++k) {
    if (frozen[k] || in.children[k].size() != 1 || in.parent[k] < 0) continue;
    const double limit = in.radius[k] / o.fusedBumpRadii, reach = o.fusedBumpReachRadii * in.radius[k];
    double up = 0, down = 0;
    const int64_t a = narrowerAlong(in, frozen, k, true, limit, reach, up);
    const int64_t b = a < 0 ? -1 : narrowerAlong(in, frozen, k, false, limit, reach - up, down);
    if (b < 0) continue;
    const size_t ia = static_cast<size_t>(a), ib = static_cast<size_t>(b);
    const double share = up / (up + down);
    const Vec3 line = q[ia] + (q[ib] - q[ia]) * share;
    ownR[k] = in.radius[ia] + (in.radius[ib] - in.radius[ia]) * share;
    const Vec3 t = (q[ib] - q[ia]).normalized();
    // Two lumens side by side have a darker (for a bright lumen) seam between their axes: the lowest value between
    // the two points below the lower end's by over a quarter of the fitted contrast.
    const Gap gap = [&](const Vec3& e, const Vec3& f) {
      const double sgn = fit[k].contrast > 0 ? 1 : -1, h = 0.5 * spacing.minCoeff();
      const double ends = std::min(sgn * value(e), sgn * value(f));
      const int steps = static_cast<int>(std::ceil((f - e).norm() / h));
      double low = ends;
      for (int i = 1; i < steps; ++i) low = std::min(low, sgn * value(e + (f - e) * (double(i) / steps)));
      return low < ends - 0.25 * std::abs(fit[k].contrast);
    };
    fit[k] = fitSection(q[k], t, line, ownR[k], in.radius[k], spacing, value, o.twoTubeBic);
    // The path voxel lies in the own lumen, so its centre lies within the own radius of it.
    fit[k].decisive = fit[k].decisive && (fit[k].own - in.raw(k)).norm() <= ownR[k];
    fit[k].shape = fit[k].decisive;
    if (fit[k].decisive && o.twoTubeForkRadii > 0 && depth.empty()) treeMeasures(in, n, arc, depth);
    fit[k].decisive = fit[k].decisive && (!(o.twoTubeForkRadii > 0) ||
                                          corroborated(in, q, arc, depth, k, q[k], t, fit[k].other3, fit[k].other,
                                                       ownR[k], ia, ib, o.twoTubeForkRadii * in.radius[k], gap));
  }
  // Runs of decisive sections along the chain whose own centres move smoothly (no farther between neighbours than
  // the points are apart plus half the own radius).
  auto linked = [&](size_t k, int64_t j) {
    if (j < 0 || !fit[k].decisive || !fit[static_cast<size_t>(j)].decisive) return false;
    const size_t i = static_cast<size_t>(j);
    return (fit[k].own - fit[i].own).norm() <= (q[k] - q[i]).norm() + 0.5 * std::min(ownR[k], ownR[i]);
  };
  auto down = [&](size_t k) -> int64_t { return in.children[k].size() == 1 ? in.children[k][0] : -1; };
  std::vector<Vec3> out = q;
  size_t moved = 0;
  for (size_t k = 1; k < n; ++k) {
    if (ownR[k] <= 0) continue;
    int run = fit[k].decisive ? 1 : 0;
    for (size_t at = k; run > 0 && linked(at, in.parent[at]); at = static_cast<size_t>(in.parent[at])) ++run;
    for (size_t at = k; run > 0 && linked(at, down(at)); at = static_cast<size_t>(down(at))) ++run;
    const bool move = run >= o.twoTubeRun;
    if (debug)
      std::fprintf(stderr,
                   "[kiss25] k %zu q %.2f %.2f %.2f own %.2f blob %.2f dBic %.1f sep %.2f other %.2f blur %.2f "
                   "shift %.2f raw %.2f shape %d decisive %d run %d move %d depthOwnBefore %.2f\n",
                   k, q[k][0] / spacing[0], q[k][1] / spacing[1], q[k][2] / spacing[2], ownR[k], in.radius[k],
                   fit[k].dBic, fit[k].sep, fit[k].other, fit[k].blur, (fit[k].own - q[k]).norm(),
                   (fit[k].own - in.raw(k)).norm(), fit[k].shape, fit[k].decisive, run, move,
                   ownR[k] - (fit[k].own - q[k]).norm());
    if (move) out[k] = fit[k].own, ++moved;
  }
  q = std::move(out);
  return moved;
}

}  // namespace vs::centreline_detail
