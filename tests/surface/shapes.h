// Analytic test shapes for the surface tests: star-shaped objects around a centre, as a blurred
// step (air 0 -> object 1000, edge width w mm) so the iso-value 500 is exactly the surface, and a
// fine parametric mesh of the same surface as the reference.
#pragma once

#include <cmath>
#include <functional>
#include <random>

#include "mesh/tri_mesh.h"
#include "volume/volume.h"

namespace vs::test {

// Radius (mm) of the surface along a unit direction (world).
using RadialFunction = std::function<double(const Vec3&)>;

inline VolumeF32 makeStarVolume(const Geometry& g, const Vec3& centerWorld, const RadialFunction& radius,
                                double edgeMm = 1.0, double noiseSigma = 0, uint32_t seed = 1) {
  VolumeF32 v(g);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 d = g.indexToWorld(Vec3(double(x), double(y), double(z))) - centerWorld;
        const double r = d.norm();
        const double R = r > 1e-9 ? radius(d / r) : radius(Vec3::UnitX());
        double val = 1000.0 * 0.5 * (1.0 + std::erf((R - r) / edgeMm));
        if (noiseSigma > 0) val += noiseSigma * noise(rng);
        v(x, y, z) = static_cast<float>(val);
      }
  return v;
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
