#include "tracking/lumen_recentre.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <unordered_set>

#include "tracking/box_search.h"
#include "tracking/medial_cost.h"
#include "tracking/section_shape.h"
#include "volume/sample.h"

namespace vs {

namespace {

using retrace::mmOf;

// A route point's section plane (u, w) and each in-plane ray's reach (ray k at angle 2 pi k / rays from u to w).
struct SectionRays {
  Vec3 u{1, 0, 0}, w{0, 1, 0};
  std::vector<double> ray;
  bool clipped = false;  // a ray left the grid: the section is wider than the grid holds
};

// The route point i's reach: its longest ray to the wall in the plane normal to the route there (0 off the lumen).
// With the lumen's depth (distance to its wall, mm; nullptr: none), a ray stops at a neck: where the depth, having
// risen to a peak and fallen from it along the ray, rises again by more than the coarsest spacing (less is the grid's
// digitisation of the wall) - past it lies another lumen (a kissing neighbour across its contact), not the own section,
// whose depth along any ray from a point inside rises at most once and then falls (a convex section).
// With the image (RecentreImage), a ray also stops at the bottom of a dip in the smoothed intensity: where, having
// fallen from its maximum, it rises again by more than the image's floor above the dip's bottom (a dip that deep) or
// above that maximum (a brighter neighbour beyond a shallow dip). Two tubes fused at a contact (no neck in the mask at
// the lumen level) can still show their two centres in the image; a flat lumen's section is one plateau, along which
// the image varies by its noise only.
double sectionReach(const NodeCost3D& cost, double lumenCost, const std::vector<Index3>& route, size_t i, int rays,
                    const std::function<double(const Index3&)>* depth, const RecentreImage& image = {},
                    const TrilinearSampler* sampler = nullptr, SectionRays* section = nullptr,
                    const Vec3* normal = nullptr, const Vec3* origin = nullptr) {
  const Geometry& g = cost.geometry;
  const auto lumen = [&](const Index3& v) {
    return cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= lumenCost;
  };
  const Index3& p = route[i];
  if (section) section->ray.assign(static_cast<size_t>(rays), 0.0);
  if (!lumen(p)) return 0;
  const size_t a = i >= 2 ? i - 2 : 0, b = std::min(route.size() - 1, i + 2);
  Vec3 t = normal ? *normal : mmOf(g, route[b]) - mmOf(g, route[a]);
  if (t.norm() == 0) t = Vec3(0, 0, 1);
  t.normalize();
  Vec3 u = std::abs(t[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  u = (u - u.dot(t) * t).normalized();
  const Vec3 w = t.cross(u);
  if (section) section->u = u, section->w = w;
  const double step = 0.5 * g.spacing.minCoeff(), coarsest = g.spacing.maxCoeff();
  const Vec3 at = origin ? *origin : mmOf(g, p);
  double reach = 0;
  for (int k = 0; k < rays; ++k) {
    const double ang = 2 * M_PI * k / rays;
    const Vec3 d = std::cos(ang) * u + std::sin(ang) * w;
    double peak = 0, lowest = std::numeric_limits<double>::infinity(), lowestAt = 0;
    // The image along the ray: its highest value so far, and the lowest since that one (with where).
    double brightest = -std::numeric_limits<double>::infinity(), dimmest = 0, dimmestAt = 0;
    if (sampler) brightest = dimmest = image.sign * sampler->at(at.cwiseQuotient(g.spacing));
    double length = 0;
    for (double s = step;; s += step) {
      const Vec3 q = at + s * d;
      const Index3 v{std::llround(q[0] / g.spacing[0]), std::llround(q[1] / g.spacing[1]),
                     std::llround(q[2] / g.spacing[2])};
      if (!g.contains(v) || !lumen(v)) {
        length = s;
        if (section && !g.contains(v)) section->clipped = true;
        break;
      }
      if (sampler) {
        const double iv = image.sign * sampler->at(q.cwiseQuotient(g.spacing));
        const bool fell = brightest > dimmest;
        if (iv > brightest && !fell)
          brightest = dimmest = iv, dimmestAt = s;  // still rising: the own section's maximum is ahead
        else if (iv < dimmest)
          dimmest = iv, dimmestAt = s;
        // Past the dip, another maximum (a dip deeper than the floor), or a rise beyond the own maximum by more than
        // the floor after any fall (a brighter neighbour: a thin tube's shallow peak beside a wider tube's plateau).
        const bool twoMaxima = brightest - dimmest > image.dipFloor && iv - dimmest > image.dipFloor;
        const bool brighterBeyond = fell && iv - brightest > image.dipFloor;
        if (twoMaxima || brighterBeyond) {
          length = dimmestAt;
          break;
        }
      }
      if (!depth) continue;
      const double dv = (*depth)(v);
      if (dv >= peak && lowest == std::numeric_limits<double>::infinity())
        peak = dv;  // still rising from the point
      else if (dv < lowest)
        lowest = dv, lowestAt = s;
      if (dv > lowest + coarsest) {
        length = lowestAt;
        break;
      }
    }
    reach = std::max(reach, length);
    if (section) section->ray[static_cast<size_t>(k)] = length;
  }
  return reach;
}

// A route's own lumen: the lumen voxels reached from it, each within the section of the route point it came from
// (from: that point's index, -1 outside; queue: the reached voxels, box-linear), and each point's reach.
struct OwnLumen {
  Geometry box;
  Index3 lo{0, 0, 0};
  std::vector<uint8_t> lumen;
  std::vector<int32_t> from;
  std::vector<int64_t> queue;
  std::vector<double> reach;
  std::vector<SectionRays> sections;
  // Each route point's narrowest section through it (the lumen's own cut, not the route's normal plane): its normal,
  // the centroid of its ray polygon (mm) and its longest ray.
  std::vector<Vec3> lumenNormal, lumenCentre;
  std::vector<double> lumenReach;
  double nearAxis = 0;
  // A voxel (r: its offset from route point o, mm) lies within o's own section where it lies within the reach of o's
  // rays on either side of its direction in o's plane: a ray stopped at a neighbour's contact keeps that neighbour
  // out, where the longest ray alone (another direction's) would take it in. Near o's axis the longest.
  bool withinSection(size_t o, const Vec3& r) const {
    const SectionRays& sr = sections[o];
    const double a = r.dot(sr.u), b = r.dot(sr.w), dist = r.norm();
    if (std::hypot(a, b) <= nearAxis || sr.ray.empty()) return dist <= reach[o];
    const double turns = std::atan2(b, a) / (2 * M_PI), n = static_cast<double>(sr.ray.size());
    const double at = (turns < 0 ? turns + 1 : turns) * n;
    const size_t k = static_cast<size_t>(std::floor(at)) % sr.ray.size(), next = (k + 1) % sr.ray.size();
    return dist <= std::max(sr.ray[k], sr.ray[next]);
  }
  size_t full(int64_t bi, const Geometry& g) const {
    const Index3 b = box.unlinear(bi);
    return static_cast<size_t>(g.linear(b[0] + lo[0], b[1] + lo[1], b[2] + lo[2]));
  }
  int64_t inBox(const Index3& v) const { return box.linear(v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]); }
  bool holds(const Index3& v) const { return box.contains({v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]}); }
};

OwnLumen floodOwnLumen(const NodeCost3D& cost, double lumenCost, const std::vector<Index3>& route,
                       const RecentreOptions& options, const RecentreImage& image) {
  OwnLumen own;
  const Geometry& g = cost.geometry;
  // The box: the route's bounds grown by twice the largest plain reach (no neck read), so the wall the distances
  // read lies inside it.
  double maxReach = 0;
  for (size_t i = 0; i < route.size(); ++i)
    maxReach = std::max(maxReach, sectionReach(cost, lumenCost, route, i, options.rays, nullptr));
  Index3& lo = own.lo;
  lo = route[0];
  Index3 hi = route[0];
  for (const Index3& v : route)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  Geometry& box = own.box;
  box = g;
  for (int k = 0; k < 3; ++k) {
    const int64_t m = static_cast<int64_t>(std::ceil(2 * maxReach / g.spacing[k])) + 2;
    lo[k] = std::max<int64_t>(0, lo[k] - m), hi[k] = std::min<int64_t>(g.dims[k] - 1, hi[k] + m);
    box.dims[k] = hi[k] - lo[k] + 1;
  }
  const auto full = [&](int64_t bi) {
    const Index3 b = box.unlinear(bi);
    return static_cast<size_t>(g.linear(b[0] + lo[0], b[1] + lo[1], b[2] + lo[2]));
  };
  const auto inBox = [&](const Index3& v) { return box.linear(v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]); };
  const size_t n = static_cast<size_t>(box.voxelCount());
  std::vector<uint8_t>& boxLumen = own.lumen;
  boxLumen.assign(n, 0);
  for (size_t i = 0; i < n; ++i) boxLumen[i] = cost.node[full(static_cast<int64_t>(i))] <= lumenCost ? 1 : 0;
  const std::vector<float> dist = distanceToOutside(box, boxLumen);
  const std::function<double(const Index3&)> depth = [&](const Index3& v) {
    const Index3 b{v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]};
    return box.contains(b) ? static_cast<double>(dist[static_cast<size_t>(box.linear(b[0], b[1], b[2]))]) : 0.0;
  };
  std::vector<double>& reach = own.reach;
  reach.assign(route.size(), 0.0);
  std::vector<SectionRays>& sections = own.sections;
  sections.assign(route.size(), {});
  const bool withImage = image.smoothed && image.smoothed->geometry().dims == g.dims;
  std::optional<TrilinearSampler> sampler;
  if (withImage) sampler.emplace(*image.smoothed);
  for (size_t i = 0; i < route.size(); ++i)
    reach[i] = sectionReach(cost, lumenCost, route, i, options.rays, &depth, image, sampler ? &*sampler : nullptr,
                            &sections[i]);
  // The lumen's own section through each route point: of the planes tilted from the route's normal plane by 0, 30,
  // 60 and 90 degrees, the one of least area. A plane cuts a tube's whole section stretched by 1 / cos of its tilt
  // from the tube's axis, so the narrowest is the tube's own section wherever the route runs - a route crossing a flat
  // lumen towards an ostium at its edge has normal planes that cut the lumen along its length, whose centroid is the
  // route itself (session 50 flatlumen2: 604's routes re-centred onto the first route's diagonal).
  own.lumenNormal.assign(route.size(), Vec3::Zero());
  own.lumenCentre.assign(route.size(), Vec3::Zero());
  own.lumenReach.assign(route.size(), 0.0);
  // A section's ray polygon read from `from` (mm) in the plane normal to n: its area and centroid (mm), its longest
  // ray.
  const auto polygon = [&](size_t i, const Vec3& normal, const Vec3& from, Vec3& centroid, double& longest) {
    SectionRays cut;
    longest = sectionReach(cost, lumenCost, route, i, options.rays, &depth, image, sampler ? &*sampler : nullptr, &cut,
                           &normal, &from);
    if (cut.clipped) return 0.0;  // not read: its area is the grid's
    const size_t m = cut.ray.size();
    double area = 0;
    Vec3 sum = Vec3::Zero();
    for (size_t k = 0; k < m; ++k) {
      const double a0 = 2 * M_PI * double(k) / double(m), a1 = 2 * M_PI * double(k + 1) / double(m);
      const Vec3 p0 = cut.ray[k] * (std::cos(a0) * cut.u + std::sin(a0) * cut.w);
      const Vec3 p1 = cut.ray[(k + 1) % m] * (std::cos(a1) * cut.u + std::sin(a1) * cut.w);
      const double tri = 0.5 * p0.cross(p1).norm();
      area += tri, sum += tri * (p0 + p1) / 3;
    }
    centroid = area > 0 ? Vec3(from + sum / area) : from;
    return area;
  };
  for (size_t i = 0; i < route.size(); ++i) {
    const SectionRays& sr = sections[i];
    const Vec3 t = sr.u.cross(sr.w), at = mmOf(g, route[i]);
    double least = std::numeric_limits<double>::infinity();
    for (int tilt = 0; tilt <= 3; ++tilt) {
      const double ta = tilt * M_PI / 6;
      for (int az = 0; az < (tilt == 0 ? 1 : tilt == 3 ? 4 : 8); ++az) {
        const double aa = M_PI * az / 4;  // at 90 degrees az and az + 4 are one plane
        const Vec3 normal =
            (std::cos(ta) * t + std::sin(ta) * (std::cos(aa) * sr.u + std::sin(aa) * sr.w)).normalized();
        Vec3 centroid;
        double longest = 0;
        const double area = polygon(i, normal, at, centroid, longest);
        if (area > 0 && area < least)
          least = area, own.lumenNormal[i] = normal, own.lumenCentre[i] = centroid, own.lumenReach[i] = longest;
      }
    }
    // Rays fanned from a point off the section's centre sample its far side sparsely: read the chosen plane again
    // from the centroid found, twice (the polygon's centroid settles on the section's within a fraction of a voxel).
    for (int again = 0; again < 2 && least < std::numeric_limits<double>::infinity(); ++again) {
      Vec3 centroid;
      double longest = 0;
      const Vec3 from = own.lumenCentre[i];
      const Index3 v{std::llround(from[0] / g.spacing[0]), std::llround(from[1] / g.spacing[1]),
                     std::llround(from[2] / g.spacing[2])};
      if (!g.contains(v) || cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] > lumenCost) break;
      if (polygon(i, own.lumenNormal[i], from, centroid, longest) <= 0) break;
      own.lumenCentre[i] = centroid, own.lumenReach[i] = longest;
    }
  }
  // A voxel lies within the own section of route point o where it lies within the reach of o's rays on either side
  // of its direction in o's plane: a ray stopped at a neighbour's contact keeps that neighbour out, where the longest
  // ray alone (another direction's) would take it in. Near o's axis (the plane's direction undefined) the longest.
  own.nearAxis = 0.5 * g.spacing.minCoeff();
  const auto withinSection = [&](size_t o, const Vec3& r) { return own.withinSection(o, r); };
  // The own lumen: reached from the route through lumen voxels, each within the reach of the route point it came from.
  constexpr int32_t kOut = -1;
  std::vector<int32_t>& from = own.from;
  from.assign(n, kOut);
  std::vector<int64_t>& queue = own.queue;
  for (size_t i = 0; i < route.size(); ++i) {
    const int64_t b = inBox(route[i]);
    if (from[static_cast<size_t>(b)] == kOut)
      from[static_cast<size_t>(b)] = static_cast<int32_t>(i), queue.push_back(b);
  }
  for (size_t head = 0; head < queue.size(); ++head) {
    const Index3 p = box.unlinear(queue[head]);
    const int32_t o = from[static_cast<size_t>(queue[head])];
    const Vec3 om = mmOf(g, route[static_cast<size_t>(o)]);
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const Index3 q{p[0] + dx, p[1] + dy, p[2] + dz};
          if (!box.contains(q)) continue;
          const size_t qi = static_cast<size_t>(box.linear(q[0], q[1], q[2]));
          if (from[qi] != kOut || !boxLumen[qi]) continue;
          const Index3 qf{q[0] + lo[0], q[1] + lo[1], q[2] + lo[2]};
          if (!withinSection(static_cast<size_t>(o), mmOf(g, qf) - om)) continue;
          from[qi] = o;
          queue.push_back(static_cast<int64_t>(qi));
        }
  }
  return own;
}

}  // namespace

std::vector<Index3> recentreInOwnLumen(const NodeCost3D& cost, double lumenCost, const std::vector<Index3>& route,
                                       const std::function<bool(int64_t)>* taken, const RecentreOptions& options,
                                       const RecentreImage& image) {
  if (route.size() < 3 || options.weight <= 0) return route;
  const Geometry& g = cost.geometry;
  const OwnLumen own = floodOwnLumen(cost, lumenCost, route, options, image);
  const Geometry& box = own.box;
  const Index3& lo = own.lo;
  const std::vector<int32_t>& from = own.from;
  const std::vector<int64_t>& queue = own.queue;
  const size_t n = static_cast<size_t>(box.voxelCount());
  const auto full = [&](int64_t bi) { return own.full(bi, g); };
  const auto inBox = [&](const Index3& v) { return own.inBox(v); };
  // The term: each own-lumen voxel's distance to the centroid of its route point's narrowest section (floodOwnLumen),
  // read in that section's plane, relative to the section's reach - 0 on the lumen's centre line, the weight at its
  // farthest wall. The distance to the wall (medial_cost.h's D / R_loc) is no centre on the grid: a flat section
  // digitised holds a band of equal D as wide as the section less its depth, and the term is 0 over the whole band.
  std::vector<int32_t> slot(n, -1);
  for (size_t k = 0; k < queue.size(); ++k) slot[static_cast<size_t>(queue[k])] = static_cast<int32_t>(k);
  std::vector<float> node(queue.size());
  for (size_t k = 0; k < queue.size(); ++k) {
    const size_t o = static_cast<size_t>(from[static_cast<size_t>(queue[k])]);
    const Index3 v = box.unlinear(queue[k]);
    // The offset from the lumen's own section's centre, read in that section's plane.
    const Vec3 r = mmOf(g, {v[0] + lo[0], v[1] + lo[1], v[2] + lo[2]}) - own.lumenCentre[o];
    const double off = (r - r.dot(own.lumenNormal[o]) * own.lumenNormal[o]).norm();
    const double rel = own.lumenReach[o] > 0 && !(taken && (*taken)(static_cast<int64_t>(full(queue[k]))))
                           ? std::min(1.0, off / own.lumenReach[o])
                           : 0.0;
    node[k] = static_cast<float>(cost.node[full(queue[k])] + options.weight * rel);
  }
  // Dijkstra from the root to the target over the own lumen, 26-connected.
  const int32_t src = slot[static_cast<size_t>(inBox(route.front()))],
                dst = slot[static_cast<size_t>(inBox(route.back()))];
  std::vector<double> best(queue.size(), std::numeric_limits<double>::infinity());
  std::vector<int32_t> pred(queue.size(), -1);
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> pq;
  best[static_cast<size_t>(src)] = 0;
  pq.push({0, src});
  while (!pq.empty()) {
    const auto [d, u] = pq.top();
    pq.pop();
    if (d > best[static_cast<size_t>(u)]) continue;
    if (u == dst) break;
    const Index3 p = box.unlinear(queue[static_cast<size_t>(u)]);
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          if (!dx && !dy && !dz) continue;
          const Index3 q{p[0] + dx, p[1] + dy, p[2] + dz};
          if (!box.contains(q)) continue;
          const int32_t v = slot[static_cast<size_t>(box.linear(q[0], q[1], q[2]))];
          if (v < 0) continue;
          const double len = std::sqrt(std::pow(static_cast<double>(dx) * g.spacing[0], 2) +
                                       std::pow(static_cast<double>(dy) * g.spacing[1], 2) +
                                       std::pow(static_cast<double>(dz) * g.spacing[2], 2));
          const double c = d + len * cost.nodeWeight * 0.5 *
                                   (static_cast<double>(node[static_cast<size_t>(u)]) + node[static_cast<size_t>(v)]);
          if (c < best[static_cast<size_t>(v)])
            best[static_cast<size_t>(v)] = c, pred[static_cast<size_t>(v)] = u, pq.push({c, v});
        }
  }
  if (!std::isfinite(best[static_cast<size_t>(dst)])) return route;
  std::vector<Index3> out;
  for (int32_t v = dst; v >= 0; v = pred[static_cast<size_t>(v)]) {
    const Index3 b = box.unlinear(queue[static_cast<size_t>(v)]);
    out.push_back({b[0] + lo[0], b[1] + lo[1], b[2] + lo[2]});
  }
  std::reverse(out.begin(), out.end());
  return out;
}

}  // namespace vs

namespace vs {

bool sectionsReadFlat(const Geometry& g, const std::vector<Index3>& route, size_t from, size_t to, double halfMm,
                      const RecentreImage& image) {
  if (!image.smoothed || std::isnan(image.surround) || to <= from || route.size() < 3) return false;
  const TrilinearSampler sample(*image.smoothed);
  SectionScratch sc;
  // Up to nine sections spread over the stretch; the tangent over two steps either side (a 26-connected chain's
  // single step turns by 45 degrees).
  const size_t count = std::min<size_t>(9, to - from), last = route.size() - 1;
  int flat = 0;
  for (size_t q = 0; q < count; ++q) {
    const size_t k = from + (to - from) * (2 * q + 1) / (2 * count);
    const Vec3 a = mmOf(g, route[k >= 2 ? k - 2 : 0]), b = mmOf(g, route[std::min(last, k + 2)]);
    const Vec3 c = mmOf(g, route[k]);
    const Vec3 ci = c.cwiseQuotient(g.spacing);
    if (!sample.inside(ci)) continue;
    // The lumen's own section through the point: of the planes tilted from the route's normal plane by 0, 30, 60 and
    // 90 degrees, the one of least extent (length x width; clipped: wider than the grid). A route heading for an
    // ostium at a flat lumen's edge cuts the lumen along its length, and that cut reads no flat section (session 50
    // flatlumen2: the routes the gate missed, whose uncentred lines the centred routes then rode).
    const Vec3 t = (b - a).norm() > 0 ? Vec3((b - a).normalized()) : Vec3(0, 0, 1);
    Vec3 u = std::abs(t[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    u = (u - u.dot(t) * t).normalized();
    const Vec3 w = t.cross(u);
    SectionShape s;
    double least = std::numeric_limits<double>::infinity();
    for (int tilt = 0; tilt <= 3; ++tilt) {
      const double ta = tilt * M_PI / 6;
      for (int az = 0; az < (tilt == 0 ? 1 : tilt == 3 ? 4 : 8); ++az) {
        const double aa = M_PI * az / 4;  // at 90 degrees az and az + 4 are one plane
        const Vec3 n = std::cos(ta) * t + std::sin(ta) * (std::cos(aa) * u + std::sin(aa) * w);
        const SectionShape cut = sectionShape(sample, g.spacing, c, n, sample.at(ci), image.surround, halfMm, sc);
        if (!cut.ok || cut.clipped) continue;
        const double extent = cut.lengthMm * cut.widthMm;
        if (extent < least) least = extent, s = cut;
      }
    }
    // Elongated: a round lumen reads 1 / cos of the tangent's error, 1.5 only 48 degrees off. No waist: a notch of a
    // fifth of the narrower lobe is more than one grid step's edge noise on a lumen five steps across. A plateau: a
    // blurred ridge (two thin tubes fused) holds sqrt(ln(4/3) / ln 2) = 0.645 of its half-way area beyond 3/4 of its
    // peak, a lumen several blur widths deep more. Clipped (wider than the grid): not read.
    if (s.ok && !s.clipped && s.aspect >= 1.5 && s.waist >= 0.8 && s.massWaist >= 0.8 && s.plateau >= 0.645) ++flat;
  }
  return 2 * flat > static_cast<int>(count);
}

bool routeStartReadsFlat(const Geometry& g, const std::vector<Index3>& route, double rootRadiusMm,
                         const RecentreImage& image) {
  if (!(rootRadiusMm > 0) || route.size() < 3) return false;
  size_t upTo = 1;
  while (upTo < route.size() && (mmOf(g, route[upTo]) - mmOf(g, route[0])).norm() <= 2 * rootRadiusMm) ++upTo;
  return sectionsReadFlat(g, route, 0, std::max<size_t>(upTo, 3), 4 * rootRadiusMm + 2 * g.spacing.maxCoeff(), image);
}

}  // namespace vs
