// Analytic test shapes for the surface tests: star-shaped objects around a centre, as a blurred
// step (air 0 -> object 1000, edge width w mm) so the iso-value 500 is exactly the surface, and a
// fine parametric mesh of the same surface as the reference.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "mesh/tri_mesh.h"
#include "volume/volume.h"

namespace vs::test {

// An n^3 volume's geometry at the origin, identity direction.
inline Geometry cube(int64_t n, const Vec3& spacing = Vec3(1, 1, 1)) {
  Geometry g;
  g.dims = {n, n, n};
  g.spacing = spacing;
  return g;
}

// Radius (mm) of the surface along a unit direction (world).
using RadialFunction = std::function<double(const Vec3&)>;

// Signed distance (mm) of a world point to a surface, negative inside.
using SignedDistance = std::function<double(const Vec3&)>;

// The object inside `distance`, as the blurred step above (the iso-value 500 is the surface).
inline VolumeF32 makeImplicitVolume(const Geometry& g, const SignedDistance& distance, double edgeMm = 1.0,
                                    double noiseSigma = 0, uint32_t seed = 1) {
  VolumeF32 v(g);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        double val =
            1000.0 * 0.5 * (1.0 + std::erf(-distance(g.indexToWorld(Vec3(double(x), double(y), double(z)))) / edgeMm));
        if (noiseSigma > 0) val += noiseSigma * noise(rng);
        v(x, y, z) = static_cast<float>(val);
      }
  return v;
}

inline VolumeF32 makeStarVolume(const Geometry& g, const Vec3& centerWorld, const RadialFunction& radius,
                                double edgeMm = 1.0, double noiseSigma = 0, uint32_t seed = 1) {
  return makeImplicitVolume(
      g,
      [&](const Vec3& p) {
        const Vec3 d = p - centerWorld;
        const double r = d.norm();
        return r - (r > 1e-9 ? radius(d / r) : radius(Vec3::UnitX()));
      },
      edgeMm, noiseSigma, seed);
}

// Signed distance to the solid cylinder of `radius` around the axis through `base` along unit
// `axis`, from `base` to `length` along it.
inline double cylinderDistance(const Vec3& p, const Vec3& base, const Vec3& axis, double radius, double length) {
  const double h = (p - base).dot(axis), rho = (p - base - h * axis).norm();
  const double dr = rho - radius, dh = std::max(-h, h - length);
  return std::min(std::max(dr, dh), 0.0) + std::hypot(std::max(dr, 0.0), std::max(dh, 0.0));
}

// A ball of `radius` mm around `centerWorld` with a mushroom on it along unit `axis`: a stalk
// (radius / 6 thick, radius / 3 long) carrying a flat cap (radius / 2 wide, radius / 6 thick).
// Rays from the centre that pass beside the stalk under the cap leave the ball, cross air and
// meet the cap: an overhang in the octant of `axis` alone.
inline SignedDistance mushroomBall(const Vec3& centerWorld, double radius, const Vec3& axis) {
  return [=](const Vec3& p) {
    const double ball = (p - centerWorld).norm() - radius;
    const Vec3 stalkBase = centerWorld + (radius - 2) * axis, capBase = centerWorld + (radius * 4 / 3) * axis;
    const double stalk = cylinderDistance(p, stalkBase, axis, radius / 6, radius / 3 + 2.5);
    const double cap = cylinderDistance(p, capBase, axis, radius / 2, radius / 6);
    return std::min({ball, stalk, cap});
  };
}

// The surface as a (2n x n) latitude-longitude mesh (poles capped), world mm.
inline TriMesh makeStarMesh(const Vec3& centerWorld, const RadialFunction& radius, int n = 200) {
  TriMesh m;
  const double pi = std::acos(-1.0);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const double th = pi * i / n, ph = pi * j / n;
      const Vec3 d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      m.positions.push_back(centerWorld + radius(d) * d);
    }
  auto id = [n](int i, int j) { return static_cast<int32_t>(i * 2 * n + (j % (2 * n))); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

}  // namespace vs::test
