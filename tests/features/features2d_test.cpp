// Tests for features/features2d: analytic inputs with exact answers, failure paths.
#include "features/features2d.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "common/test_images.h"

using namespace vs;

namespace {
VolumeF32 image(int64_t w, int64_t h, double su, double sv, const std::function<float(int64_t, int64_t)>& fn) {
  return test::makeImage(w, h, su, sv, fn);
}
}  // namespace

TEST(Features2D, RampWithAnisotropicSpacingGivesGradientPerMm) {
  // I = 3u + 5v with spacing 0.5 x 2 mm: dI/du = 3 / 0.5 = 6, dI/dv = 5 / 2 = 2.5 per mm.
  const auto vol = image(9, 7, 0.5, 2.0, [](int64_t u, int64_t v) { return static_cast<float>(3 * u + 5 * v); });
  const Features2D f = computeFeatures2D(AnyVolume(vol));
  ASSERT_EQ(f.width, 9);
  ASSERT_EQ(f.height, 7);
  for (int64_t v = 0; v < 7; ++v)
    for (int64_t u = 0; u < 9; ++u) {
      const auto i = static_cast<size_t>(f.index(u, v));
      EXPECT_NEAR(f.gradU[i], 6.0, 1e-5) << u << "," << v;  // one-sided differences at the border too
      EXPECT_NEAR(f.gradV[i], 2.5, 1e-5) << u << "," << v;
      EXPECT_NEAR(f.magnitude[i], std::hypot(6.0, 2.5), 1e-5);
      if (u > 0 && v > 0 && u < 8 && v < 6) {
        EXPECT_NEAR(f.laplacian[i], 0.0, 1e-4);
      }
    }
  EXPECT_NEAR(f.maxMagnitude, std::hypot(6.0, 2.5), 1e-5);
}

TEST(Features2D, QuadraticHasKnownLaplacian) {
  // I = u^2 (spacing 2 mm): d2I/dx2 = 2 / (2 mm)^2 = 0.5 per mm^2 in the interior.
  const auto vol = image(8, 5, 2.0, 1.0, [](int64_t u, int64_t) { return static_cast<float>(u * u); });
  const Features2D f = computeFeatures2D(AnyVolume(vol));
  for (int64_t v = 0; v < 5; ++v)
    for (int64_t u = 1; u < 7; ++u) EXPECT_NEAR(f.laplacian[static_cast<size_t>(f.index(u, v))], 0.5, 1e-5);
}

TEST(Features2D, FlatImageHasNoGradientAndNoZeroCrossing) {
  const auto vol = image(6, 4, 1.0, 1.0, [](int64_t, int64_t) { return 42.0f; });
  const Features2D f = computeFeatures2D(AnyVolume(vol), {.smoothSigmaMm = 1.5});
  EXPECT_EQ(f.maxMagnitude, 0.0f);
  EXPECT_EQ(f.magnitudeQuantile(0.99), 0.0f);
  for (size_t i = 0; i < f.magnitude.size(); ++i) {
    EXPECT_EQ(f.magnitude[i], 0.0f);
    EXPECT_EQ(f.zeroCrossing[i], 0);
    EXPECT_NEAR(f.smoothed[i], 42.0f, 1e-4);  // normalised kernel keeps a constant
  }
}

TEST(Features2D, StepEdgeHasZeroCrossingOnTheEdge) {
  // Vertical step between u = 4 and u = 5: the Laplacian is +/- on either side, zero crossings there only.
  const auto vol = image(10, 6, 1.0, 1.0, [](int64_t u, int64_t) { return u < 5 ? 10.0f : 110.0f; });
  const Features2D f = computeFeatures2D(AnyVolume(vol));
  for (int64_t v = 0; v < 6; ++v)
    for (int64_t u = 0; u < 10; ++u) {
      const bool expected = (u == 4 || u == 5);
      EXPECT_EQ(f.zeroCrossing[static_cast<size_t>(f.index(u, v))] != 0, expected) << u << "," << v;
    }
  EXPECT_NEAR(f.magnitude[static_cast<size_t>(f.index(4, 2))], 50.0, 1e-4);
  EXPECT_NEAR(f.maxMagnitude, 50.0, 1e-4);
}

TEST(Features2D, SmoothingSigmaIsInMillimetres) {
  // An impulse blurred with sigma 2 mm on 1 x 2 mm pixels: variance 4 px^2 along u, 1 px^2 along v.
  const auto vol = image(41, 41, 1.0, 2.0, [](int64_t u, int64_t v) { return (u == 20 && v == 20) ? 1000.0f : 0.0f; });
  const Features2D f = computeFeatures2D(AnyVolume(vol), {.smoothSigmaMm = 2.0});
  double sum = 0, mu = 0, mv = 0;
  for (int64_t v = 0; v < 41; ++v)
    for (int64_t u = 0; u < 41; ++u) {
      const double x = f.smoothed[static_cast<size_t>(f.index(u, v))];
      sum += x;
      mu += x * (u - 20) * (u - 20);
      mv += x * (v - 20) * (v - 20);
    }
  EXPECT_NEAR(sum, 1000.0, 1e-2);
  EXPECT_NEAR(mu / sum, 4.0, 0.05);
  EXPECT_NEAR(mv / sum, 1.0, 0.05);
}

TEST(Features2D, SliceOfVolumeUsesSliceSpacing) {
  Geometry g;
  g.dims = {5, 6, 7};
  g.spacing = {0.5, 1.0, 3.0};
  VolumeI16 vol(g);
  for (int64_t z = 0; z < 7; ++z)
    for (int64_t y = 0; y < 6; ++y)
      for (int64_t x = 0; x < 5; ++x) vol(x, y, z) = static_cast<int16_t>(x + 2 * y + 3 * z);
  // Coronal slice y = 2: u = x (0.5 mm), v = z (3 mm): dI/du = 2, dI/dv = 1.
  const Features2D f = computeFeatures2D(sliceView(vol, 1, 2));
  EXPECT_EQ(f.width, 5);
  EXPECT_EQ(f.height, 7);
  EXPECT_DOUBLE_EQ(f.spacingV, 3.0);
  EXPECT_NEAR(f.gradU[static_cast<size_t>(f.index(2, 3))], 2.0, 1e-5);
  EXPECT_NEAR(f.gradV[static_cast<size_t>(f.index(2, 3))], 1.0, 1e-5);
}

TEST(Features2D, NonFinitePixelIsDataErrorNamingTheSlice) {
  Geometry g;
  g.dims = {4, 4, 6};
  VolumeF32 vol(g, 1.0f);
  vol(2, 1, 3) = std::numeric_limits<float>::quiet_NaN();
  try {
    computeFeatures2D(sliceView(vol, 2, 3));
    FAIL() << "expected DataError";
  } catch (const DataError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("slice z=3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("u=2, v=1"), std::string::npos) << msg;
  }
  EXPECT_NO_THROW(computeFeatures2D(sliceView(vol, 2, 2)));  // other slices are fine
  vol(0, 0, 2) = std::numeric_limits<float>::infinity();
  EXPECT_THROW(computeFeatures2D(sliceView(vol, 2, 2)), DataError);
}

TEST(Features2D, RejectsBadInput) {
  Geometry g;
  g.dims = {4, 4, 2};
  VolumeF32 vol(g);
  EXPECT_THROW(computeFeatures2D(AnyVolume(vol)), InvalidArgument);  // not 2D
  EXPECT_THROW(computeFeatures2D(sliceView(vol, 2, 0), {.smoothSigmaMm = -1.0}), InvalidArgument);
  EXPECT_THROW(computeFeatures2D(SliceView<float>{}), InvalidArgument);
}

// The row-parallel, vectorised implementation against the per-pixel definitions in double
// (central differences / spacing, one-sided at the border, 3-point Laplacian with replicated
// border, Gaussian blur with replicated border, the pair rule for zero crossings), on random
// images whose widths exercise the vector loops' tails and the 1- and 2-pixel special cases.
TEST(Features2D, MatchesPerPixelDefinitionsOnRandomImages) {
  struct Case {
    int64_t w, h;
    double su, sv, sigma;
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> val(-50, 50);
  for (const Case& c : {Case{13, 9, 1, 1, 0}, Case{17, 6, 0.5, 1.5, 0}, Case{11, 10, 0.7, 0.7, 1.0},
                        Case{1, 5, 1, 1, 0}, Case{7, 1, 1, 1, 0}, Case{2, 2, 1, 1, 0}, Case{33, 4, 1.3, 0.6, 0.8}}) {
    std::vector<float> img(static_cast<size_t>(c.w * c.h));
    for (auto& x : img) x = val(rng);
    for (int64_t i = 0; i < std::min<int64_t>(3, c.w); ++i) img[static_cast<size_t>(i)] = 7.0f;  // a flat patch
    const auto vol =
        image(c.w, c.h, c.su, c.sv, [&](int64_t u, int64_t v) { return img[static_cast<size_t>(u + c.w * v)]; });
    const Features2D f = computeFeatures2D(AnyVolume(vol), {.smoothSigmaMm = c.sigma});
    auto at = [&](const std::vector<double>& a, int64_t u, int64_t v) {
      return a[static_cast<size_t>(std::clamp<int64_t>(u, 0, c.w - 1) + c.w * std::clamp<int64_t>(v, 0, c.h - 1))];
    };
    // Reference blur (u then v), replicated border.
    std::vector<double> I(img.begin(), img.end());
    for (int axis = 0; axis < 2 && c.sigma > 0; ++axis) {
      const double s = c.sigma / (axis == 0 ? c.su : c.sv);
      const int r = static_cast<int>(std::ceil(3 * s));
      std::vector<double> k;
      double sum = 0;
      for (int i = -r; i <= r; ++i) sum += k.emplace_back(std::exp(-0.5 * i * i / (s * s)));
      std::vector<double> out(I.size());
      for (int64_t v = 0; v < c.h; ++v)
        for (int64_t u = 0; u < c.w; ++u) {
          double acc = 0;
          for (int i = -r; i <= r; ++i)
            acc += k[static_cast<size_t>(i + r)] / sum * (axis == 0 ? at(I, u + i, v) : at(I, u, v + i));
          out[static_cast<size_t>(u + c.w * v)] = acc;
        }
      I = out;
    }
    float gmax = 0;
    for (int64_t v = 0; v < c.h; ++v)
      for (int64_t u = 0; u < c.w; ++u) {
        const auto i = static_cast<size_t>(u + c.w * v);
        const double tol = 1e-4 * (1 + std::fabs(I[i]));
        EXPECT_NEAR(f.smoothed[i], I[i], tol);
        const int64_t um = std::max<int64_t>(u - 1, 0), up = std::min(u + 1, c.w - 1);
        const int64_t vm = std::max<int64_t>(v - 1, 0), vp = std::min(v + 1, c.h - 1);
        const double gu = up > um ? (at(I, up, v) - at(I, um, v)) / ((up - um) * c.su) : 0;
        const double gv = vp > vm ? (at(I, u, vp) - at(I, u, vm)) / ((vp - vm) * c.sv) : 0;
        const double lap = (at(I, u - 1, v) - 2 * I[i] + at(I, u + 1, v)) / (c.su * c.su) +
                           (at(I, u, v - 1) - 2 * I[i] + at(I, u, v + 1)) / (c.sv * c.sv);
        EXPECT_NEAR(f.gradU[i], gu, 1e-3 * (1 + std::fabs(gu))) << c.w << "x" << c.h << " " << u << "," << v;
        EXPECT_NEAR(f.gradV[i], gv, 1e-3 * (1 + std::fabs(gv)));
        EXPECT_NEAR(f.magnitude[i], std::hypot(gu, gv), 1e-3 * (1 + std::hypot(gu, gv)));
        EXPECT_NEAR(f.laplacian[i], lap, 1e-3 * (1 + std::fabs(lap)));
        gmax = std::max(gmax, f.magnitude[i]);
        // Zero crossings by the pair rule on the returned Laplacian: exact.
        const float a = f.laplacian[i];
        bool zc = false, pos = false, neg = false;
        for (const auto& [du, dv] : std::array<std::pair<int, int>, 4>{{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}}) {
          if (!f.contains(u + du, v + dv)) continue;
          const float b = f.laplacian[static_cast<size_t>(f.index(u + du, v + dv))];
          zc |= ((a > 0 && b < 0) || (a < 0 && b > 0)) && std::fabs(a) <= std::fabs(b);
          pos |= b > 0;
          neg |= b < 0;
        }
        zc |= a == 0 && pos && neg;
        EXPECT_EQ(f.zeroCrossing[i] != 0, zc) << c.w << "x" << c.h << " " << u << "," << v;
      }
    EXPECT_EQ(f.maxMagnitude, gmax);
  }
}
