// Session 45 speedE: the contact walks' lumen test rounds without the library call (volume/round_half.h), their
// sections take the eight directions' cosines and sines from a table formed once, and the Gaussian smoothing forms a
// row of outputs tap by tap - each must give every value the code before gave, bit for bit (the reference copies
// below are that code as it was).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "features/vesselness.h"
#include "tracking/contact_walk.h"
#include "volume/round_half.h"
#include "volume/volume.h"

namespace vs {
namespace {

TEST(ExactSpeed, RoundHalfAwayIsLlroundEverywhere) {
  std::vector<double> xs = {0.0,
                            -0.0,
                            0.5,
                            -0.5,
                            1.5,
                            -1.5,
                            2.5,
                            -2.5,
                            0.49999999999999994,
                            -0.49999999999999994,
                            std::nextafter(0.5, 1.0),
                            std::nextafter(-0.5, -1.0),
                            4503599627370495.5,
                            -4503599627370495.5,
                            4503599627370496.0,
                            -4503599627370496.0,
                            9007199254740993.0,
                            1e18,
                            -1e18,
                            1e-300,
                            -1e-300,
                            std::numeric_limits<double>::denorm_min()};
  for (double k = -70; k <= 70; k += 1)
    for (double d : {-0.5, 0.5}) {
      xs.push_back(k + d);
      xs.push_back(std::nextafter(k + d, 0.0));
      xs.push_back(std::nextafter(k + d, k + 2 * d));
    }
  std::mt19937_64 rng(4501);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200000; ++i) xs.push_back(u(rng) * std::ldexp(1.0, static_cast<int>(rng() % 60)));
  for (double x : xs) ASSERT_EQ(roundHalfAway(x), std::llround(x)) << x;
  // The library's own answers beyond 2^52 and for the values without a nearest integer.
  for (double x : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN(), 1e300})
    EXPECT_EQ(roundHalfAway(x), std::llround(x)) << x;
}

// walk::Lumen::at and walk::sectionAt as they were before session 45 (std::llround per axis; cos and sin per call).
bool refAt(const walk::Lumen& lu, const Vec3& p) {
  const Geometry& g = lu.cost.geometry;
  Index3 v;
  for (size_t ax = 0; ax < 3; ++ax) v[ax] = static_cast<int64_t>(std::llround(p[ax] / g.spacing[ax]));
  return g.contains(v) && lu.cost.node[static_cast<size_t>(g.linear(v[0], v[1], v[2]))] <= lu.level;
}

walk::Section refSectionAt(const walk::Lumen& lu, const Vec3& p, const Vec3& d, double dt, double cap) {
  walk::Section s;
  s.centre = p;
  if (!refAt(lu, p)) return s;
  s.lumen = true;
  Vec3 u, w;
  walk::normals(d, u, w);
  double run[8];
  Vec3 e[8];
  for (int k = 0; k < 8; ++k) {
    volatile double va = k * M_PI / 4;  // the library's cos and sin, as the code before called them
    const double a = va;
    e[k] = std::cos(a) * u + std::sin(a) * w;
    double t = 0;
    while (t < cap && refAt(lu, p + (t + dt) * e[k])) t += dt;
    run[k] = t;
    s.radius += t / 8;
  }
  Vec3 shift = Vec3::Zero();
  for (int k = 0; k < 4; ++k) shift += 0.25 * (run[k] - run[k + 4]) * e[k];
  s.centre = p + shift;
  return s;
}

bool sameBits(double a, double b) { return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b); }

TEST(ExactSpeed, SectionsEqualTheCodeBefore) {
  // Two tilted tubes on an anisotropic grid (cost 0.1 inside, 1 outside; lumen level 0.5), the sections cut at
  // points in, near and outside them, in random directions, on spacings and steps that land samples on halves.
  NodeCost3D cost;
  cost.kind = CostKind3D::Given;
  cost.geometry.dims = {40, 36, 30};
  cost.geometry.spacing = Vec3(0.5, 0.5, 1.25);
  const Geometry& g = cost.geometry;
  cost.node.assign(static_cast<size_t>(g.voxelCount()), 1.0f);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 p(0.5 * double(x), 0.5 * double(y), 1.25 * double(z));
        const double r1 = std::hypot(p[0] - 8 - 0.1 * p[2], p[1] - 9),
                     r2 = std::hypot(p[0] - 13, p[1] - 6 - 0.2 * p[2]);
        if (r1 <= 3 || r2 <= 1.75) cost.node[static_cast<size_t>(g.linear(x, y, z))] = 0.1f;
      }
  const walk::Lumen lu{cost, 0.5};
  std::mt19937 rng(4502);
  std::uniform_real_distribution<double> u(0, 1), s(-1, 1);
  int inLumen = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3 p(20 * u(rng), 18 * u(rng), 37 * u(rng));
    const Vec3 d = Vec3(s(rng), s(rng), 1 + s(rng)).normalized();
    const double dt = i % 3 == 0 ? 0.25 : 0.125 * (1 + i % 5), cap = 6;
    const walk::Section a = walk::sectionAt(lu, p, d, dt, cap), b = refSectionAt(lu, p, d, dt, cap);
    ASSERT_EQ(a.lumen, b.lumen) << i;
    ASSERT_TRUE(sameBits(a.radius, b.radius)) << i;
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(sameBits(a.centre[k], b.centre[k])) << i;
    inLumen += a.lumen;
  }
  EXPECT_GT(inLumen, 200);  // sections in the tubes, not only outside them
}

// gaussianSmooth3D as it was before session 45: per output, every tap's index clamped to the volume.
VolumeF32 refSmooth(const VolumeF32& vol, double sigmaMm) {
  const Geometry& g = vol.geometry();
  VolumeF32 a = vol, b(g);
  for (int axis = 0; axis < 3; ++axis) {
    if (g.dims[static_cast<size_t>(axis)] == 1) continue;
    const double sv = sigmaMm / g.spacing[axis];
    if (sv <= 1e-6) continue;
    const int r = std::max(1, static_cast<int>(std::ceil(3.0 * sv)));
    std::vector<float> k(static_cast<size_t>(2 * r + 1));
    double sum = 0;
    for (int i = -r; i <= r; ++i) {
      const double w = std::exp(-0.5 * (i * i) / (sv * sv));
      k[static_cast<size_t>(i + r)] = static_cast<float>(w);
      sum += w;
    }
    for (auto& w : k) w = static_cast<float>(w / sum);
    const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2], n = g.dims[static_cast<size_t>(axis)];
    const int64_t stride = axis == 0 ? 1 : (axis == 1 ? nx : nx * ny);
    const float* src = a.data();
    float* dst = b.data();
    for (int64_t z = 0; z < nz; ++z)
      for (int64_t y = 0; y < ny; ++y)
        for (int64_t x = 0; x < nx; ++x) {
          const int64_t i = x + nx * (y + ny * z), pos = axis == 0 ? x : (axis == 1 ? y : z), base = i - pos * stride;
          float acc = 0;
          for (int64_t t = -r; t <= r; ++t)
            acc += k[static_cast<size_t>(t + r)] * src[base + std::clamp<int64_t>(pos + t, 0, n - 1) * stride];
          dst[i] = acc;
        }
    std::swap(a, b);
  }
  return a;
}

TEST(ExactSpeed, SmoothingEqualsTheCodeBefore) {
  // Noise with signed zeros, on grids thinner and thicker than the kernel, spacings anisotropic.
  std::mt19937 rng(4503);
  std::normal_distribution<float> n01(0, 1);
  const Index3 dims[] = {{23, 17, 9}, {3, 40, 5}, {64, 2, 3}, {1, 30, 30}, {12, 12, 1}};
  const Vec3 spacings[] = {Vec3(0.5, 0.5, 1.5), Vec3(1, 1, 1), Vec3(0.3, 0.9, 2.4)};
  int compared = 0;
  for (const Index3& d : dims)
    for (const Vec3& sp : spacings)
      for (double sigma : {0.4, 1.0, 2.5}) {
        Geometry g;
        g.dims = d, g.spacing = sp;
        VolumeF32 v(g);
        for (int64_t i = 0; i < g.voxelCount(); ++i)
          v.data()[i] = i % 7 == 0 ? -0.0f : (i % 5 == 0 ? 0.0f : 100 * n01(rng));
        const VolumeF32 a = gaussianSmooth3D(v, sigma), b = refSmooth(v, sigma);
        for (int64_t i = 0; i < g.voxelCount(); ++i)
          ASSERT_EQ(std::bit_cast<uint32_t>(a.data()[i]), std::bit_cast<uint32_t>(b.data()[i]))
              << d[0] << "x" << d[1] << "x" << d[2] << " sigma " << sigma << " voxel " << i;
        ++compared;
      }
  EXPECT_EQ(compared, 45);
}

}  // namespace
}  // namespace vs
