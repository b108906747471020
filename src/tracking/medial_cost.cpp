#include "tracking/medial_cost.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "util/error.h"
#include "util/parallel.h"

namespace vs {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// One line of squared distances f (kInf: no outside voxel seen yet) at spacing h, replaced by
// min_j (x_i - x_j)^2 + f_j over the line and two outside points just beyond its ends (index -1
// and n: outside the volume). Lower envelope of the parabolas, Felzenszwalb-Huttenlocher.
struct Envelope {
  std::vector<double> pos, val, from;  // the envelope's parabolas: apex, value, left boundary
  void run(std::vector<double>& f, double h) {
    const size_t n = f.size();
    pos.resize(n + 2), val.resize(n + 2), from.resize(n + 2);
    int64_t k = -1;
    auto add = [&](double p, double fp) {
      double s = -kInf;
      while (k >= 0) {
        const size_t kk = static_cast<size_t>(k);
        s = ((fp + p * p) - (val[kk] + pos[kk] * pos[kk])) / (2 * (p - pos[kk]));
        if (s > from[kk]) break;
        --k;
      }
      if (k < 0) s = -kInf;
      ++k;
      pos[static_cast<size_t>(k)] = p, val[static_cast<size_t>(k)] = fp, from[static_cast<size_t>(k)] = s;
    };
    add(-h, 0);
    for (size_t i = 0; i < n; ++i)
      if (f[i] < kInf) add(static_cast<double>(i) * h, f[i]);
    add(static_cast<double>(n) * h, 0);
    size_t j = 0;
    for (size_t i = 0; i < n; ++i) {
      const double x = static_cast<double>(i) * h;
      while (j + 1 <= static_cast<size_t>(k) && from[j + 1] < x) ++j;
      f[i] = (x - pos[j]) * (x - pos[j]) + val[j];
    }
  }
};

// The squared-distance pass along `axis` over every line of the volume.
void envelopePass(const Geometry& g, std::vector<float>& sq, int axis) {
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;  // the other two axes (a2 outermost)
  const int64_t n = g.dims[axis];
  const int64_t stride = axis == 0 ? 1 : axis == 1 ? g.dims[0] : g.dims[0] * g.dims[1];
  const double h = g.spacing[axis];
  parallelFor(
      0, g.dims[a2],
      [&](int64_t c0, int64_t c1) {
        Envelope env;
        std::vector<double> line(static_cast<size_t>(n));
        for (int64_t c = c0; c < c1; ++c)
          for (int64_t b = 0; b < g.dims[a1]; ++b) {
            Index3 p{0, 0, 0};
            p[a1] = b, p[a2] = c;
            const int64_t base = g.linear(p[0], p[1], p[2]);
            bool any = false;
            for (int64_t i = 0; i < n; ++i) {
              const float v = sq[static_cast<size_t>(base + i * stride)];
              line[static_cast<size_t>(i)] = v;
              any = any || v > 0;
            }
            if (!any) continue;  // all outside: stays 0
            env.run(line, h);
            for (int64_t i = 0; i < n; ++i)
              sq[static_cast<size_t>(base + i * stride)] = static_cast<float>(line[static_cast<size_t>(i)]);
          }
      },
      1);
}

// The 26 neighbour offsets and their lengths (mm).
struct Neighbours {
  Index3 d[26];
  double len[26];
  explicit Neighbours(const Geometry& g) {
    int k = 0;
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          d[k] = {dx, dy, dz};
          len[k] = std::sqrt(std::pow(static_cast<double>(dx) * g.spacing[0], 2) +
                             std::pow(static_cast<double>(dy) * g.spacing[1], 2) +
                             std::pow(static_cast<double>(dz) * g.spacing[2], 2));
          ++k;
        }
  }
};
}  // namespace

std::vector<float> distanceToOutside(const Geometry& g, const std::vector<uint8_t>& inside) {
  VS_REQUIRE(static_cast<int64_t>(inside.size()) == g.voxelCount(),
             "distance transform: mask and volume differ in size");
  std::vector<float> sq(inside.size());
  for (size_t i = 0; i < sq.size(); ++i) sq[i] = inside[i] ? std::numeric_limits<float>::infinity() : 0.0f;
  for (int axis = 0; axis < 3; ++axis) envelopePass(g, sq, axis);
  for (float& v : sq) v = std::sqrt(v);
  return sq;
}

std::vector<float> localLumenRadius(const Geometry& g, const std::vector<float>& dist, double ridgeSlope) {
  VS_REQUIRE(static_cast<int64_t>(dist.size()) == g.voxelCount(), "local radius: distances and volume differ in size");
  const Neighbours nb(g);
  constexpr uint8_t kNone = 255;
  // Per voxel the neighbour of steepest ascent of D when it rises by at least ridgeSlope per mm.
  std::vector<uint8_t> up(dist.size(), kNone);
  parallelFor(
      0, g.dims[2],
      [&](int64_t z0, int64_t z1) {
        for (int64_t z = z0; z < z1; ++z)
          for (int64_t y = 0; y < g.dims[1]; ++y)
            for (int64_t x = 0; x < g.dims[0]; ++x) {
              const size_t i = static_cast<size_t>(g.linear(x, y, z));
              if (dist[i] <= 0) continue;
              double best = ridgeSlope;
              for (int k = 0; k < 26; ++k) {
                const Index3 q{x + nb.d[k][0], y + nb.d[k][1], z + nb.d[k][2]};
                if (!g.contains(q)) continue;
                const double slope =
                    (static_cast<double>(dist[static_cast<size_t>(g.linear(q[0], q[1], q[2]))]) - dist[i]) / nb.len[k];
                if (slope >= best) best = slope, up[i] = static_cast<uint8_t>(k);
              }
            }
      },
      4);
  // Follow each chain to its ridge voxel (D strictly rises along it, so it ends) and give the
  // chain that voxel's D.
  std::vector<float> radius(dist.size(), -1.0f);
  std::vector<size_t> chain;
  for (size_t i = 0; i < dist.size(); ++i) {
    if (dist[i] <= 0) {
      radius[i] = 0;
      continue;
    }
    size_t j = i;
    chain.clear();
    while (radius[j] < 0 && up[j] != kNone) {
      chain.push_back(j);
      const Index3 p = g.unlinear(static_cast<int64_t>(j));
      const Index3& d = nb.d[up[j]];
      j = static_cast<size_t>(g.linear(p[0] + d[0], p[1] + d[1], p[2] + d[2]));
    }
    if (radius[j] < 0) radius[j] = dist[j];
    for (size_t c : chain) radius[c] = radius[j];
  }
  return radius;
}

std::string addMedialTerm(NodeCost3D& cost, double lumenCost, const MedialOptions& options) {
  VS_REQUIRE(options.weight >= 0 && std::isfinite(options.weight) && options.ridgeSlope > 0 && options.lumenLevel > 0 &&
                 options.lumenLevel <= 1,
             "medial term: weight >= 0, ridge slope > 0, lumen level in (0, 1]");
  const MedialOptions& o = options;
  if (o.weight == 0) return "";
  const Geometry& g = cost.geometry;
  std::vector<uint8_t> lumen(cost.node.size());
  for (size_t i = 0; i < lumen.size(); ++i) lumen[i] = cost.node[i] <= lumenCost ? 1 : 0;
  const std::vector<float> dist = distanceToOutside(g, lumen);
  lumen = {};
  const std::vector<float> radius = localLumenRadius(g, dist, o.ridgeSlope);
  parallelFor(
      0, static_cast<int64_t>(cost.node.size()),
      [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
          const size_t k = static_cast<size_t>(i);
          const double rel = dist[k] > 0 ? std::min(1.0, static_cast<double>(dist[k]) / radius[k]) : 0.0;
          cost.node[k] += static_cast<float>(o.weight * (1 - rel));
        }
      },
      1 << 16);
  char buf[200];
  std::snprintf(buf, sizeof buf,
                " + medial term %.3g (1 - D/R_loc), D: distance to the wall of s >= %.3g, R_loc: D at its ridge "
                "(ascent >= %.3g/mm)",
                o.weight, o.lumenLevel, o.ridgeSlope);
  return buf;
}

}  // namespace vs
