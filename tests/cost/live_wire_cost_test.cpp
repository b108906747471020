// Tests for cost/live_wire_cost: exact values on analytic images, ranges, failure paths.
#include "cost/live_wire_cost.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "common/test_images.h"

using namespace vs;

namespace {
Features2D featuresOf(int64_t w, int64_t h, double su, double sv, const std::function<float(int64_t, int64_t)>& fn,
                      double sigma = 0) {
  return computeFeatures2D(AnyVolume(test::makeImage(w, h, su, sv, fn)), {.smoothSigmaMm = sigma});
}
const std::vector<std::array<int, 2>> kSteps8 = {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};
}  // namespace

TEST(LiveWireCost, FlatImageGivesUniformCostPerMm) {
  const Features2D f = featuresOf(7, 5, 0.5, 2.0, [](int64_t, int64_t) { return 7.0f; });
  const auto c = liveWireEdgeCosts(f, {}, kSteps8);
  // fZ = 1, fG = 1, fD = 2/(3 pi) * (pi/2 + pi/2) = 2/3 (no gradient direction).
  const double perMm = 0.43 + 0.43 + 0.14 * 2.0 / 3.0;
  for (int64_t v = 1; v < 4; ++v)
    for (int64_t u = 1; u < 6; ++u)
      for (size_t k = 0; k < 8; ++k) {
        const double len = std::hypot(kSteps8[k][0] * 0.5, kSteps8[k][1] * 2.0);
        EXPECT_NEAR(c[static_cast<size_t>(f.index(u, v)) * 8 + k], perMm * len, 1e-5);
      }
  LiveWireCostOptions go;
  go.kind = LiveWireCostKind::Gradient;
  const auto cg = liveWireEdgeCosts(f, go, kSteps8);
  EXPECT_NEAR(cg[static_cast<size_t>(f.index(3, 2)) * 8 + 4], 255.0 * 0.5, 1e-4);  // +u step of 0.5 mm
  EXPECT_NEAR(cg[static_cast<size_t>(f.index(3, 2)) * 8 + 7], 255.0 * std::hypot(0.5, 2.0), 1e-3);
}

TEST(LiveWireCost, EdgesLeavingTheImageAreImpassable) {
  const Features2D f = featuresOf(4, 3, 1, 1, [](int64_t u, int64_t v) { return static_cast<float>(u * v); });
  const auto c = liveWireEdgeCosts(f, {}, kSteps8);
  EXPECT_TRUE(std::isinf(c[static_cast<size_t>(f.index(0, 0)) * 8 + 0]));
  EXPECT_TRUE(std::isinf(c[static_cast<size_t>(f.index(3, 1)) * 8 + 4]));
  EXPECT_TRUE(std::isfinite(c[static_cast<size_t>(f.index(3, 1)) * 8 + 3]));
}

TEST(LiveWireCost, AlongAStraightEdgeOnlyTheZeroCrossingAndGradientTermsVanish) {
  // Vertical step edge: moving along the edge (v direction) on the zero-crossing column with
  // maximal gradient costs 0 (fZ = 0, fG = 0, fD = 0); crossing it costs more.
  const Features2D f = featuresOf(10, 8, 1, 1, [](int64_t u, int64_t) { return u < 5 ? 0.0f : 100.0f; });
  const double along = liveWireEdgeCost(f, {}, 4, 3, 4, 4);
  EXPECT_NEAR(along, 0.0, 1e-6);
  const double across = liveWireEdgeCost(f, {}, 4, 3, 3, 3);
  EXPECT_GT(across, 0.4);
  // gradient direction term: the edge runs perpendicular to the gradient, so moving across the
  // edge (along the gradient) on the edge pixels gives fD = 2/(3 pi) * (pi/2 + pi/2) = 2/3.
  LiveWireCostOptions onlyD;
  onlyD.weightZ = onlyD.weightG = 0;
  onlyD.weightD = 1;
  EXPECT_NEAR(liveWireEdgeCost(f, onlyD, 4, 3, 5, 3), 2.0 / 3.0, 1e-6);
  EXPECT_NEAR(liveWireEdgeCost(f, onlyD, 4, 3, 4, 2), 0.0, 1e-6);
}

TEST(LiveWireCost, GradientDirectionTermIsNormalisedToAtMostOne) {
  // D(p) and D(q) opposite and the step at 45 degrees: acos terms pi/4 + 3pi/4 ... up to 3pi/2 in total.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(0, 100);
  const Features2D f = featuresOf(24, 24, 1, 1, [&](int64_t, int64_t) { return noise(rng); });
  LiveWireCostOptions onlyD;
  onlyD.weightZ = onlyD.weightG = 0;
  onlyD.weightD = 1;
  const auto c = liveWireEdgeCosts(f, onlyD, kSteps8);
  double maxPerLen = 0;
  for (int64_t v = 1; v < 23; ++v)
    for (int64_t u = 1; u < 23; ++u)
      for (size_t k = 0; k < 8; ++k) {
        const double len = std::hypot(kSteps8[k][0], kSteps8[k][1]);
        const double fD = c[static_cast<size_t>(f.index(u, v)) * 8 + k] / len;
        EXPECT_GE(fD, 0.0);
        EXPECT_LE(fD, 1.0 + 1e-6);
        maxPerLen = std::max(maxPerLen, fD);
      }
  EXPECT_GT(maxPerLen, 0.9);  // the normalisation 2/(3 pi), not 1/pi, is what keeps this <= 1
}

TEST(LiveWireCost, CostsAreProportionalToEdgeLength) {
  // Same features at both ends (a linear ramp): a diagonal step costs sqrt(2) x the local cost.
  const Features2D f = featuresOf(9, 9, 1, 1, [](int64_t u, int64_t v) { return static_cast<float>(u + v); });
  LiveWireCostOptions o;
  o.weightD = 0;  // fD differs between directions; the other terms are per pixel
  EXPECT_NEAR(liveWireEdgeCost(f, o, 4, 4, 5, 5), std::sqrt(2.0) * liveWireEdgeCost(f, o, 4, 4, 5, 4), 1e-6);
}

TEST(LiveWireCost, GradientCostFollowsEquation12) {
  // Ramp in u with a bright half: G = 10 on the left (slope 10), 20 on the right -> Gs 127.5 / 255.
  const Features2D f = featuresOf(
      12, 4, 1, 1, [](int64_t u, int64_t) { return static_cast<float>(u <= 5 ? 10 * u : 50 + 20 * (u - 5)); });
  LiveWireCostOptions o;
  o.kind = LiveWireCostKind::Gradient;
  EXPECT_NEAR(liveWireEdgeCost(f, o, 2, 1, 3, 1), 255.0 - 127.5, 1e-3);
  EXPECT_NEAR(liveWireEdgeCost(f, o, 8, 1, 9, 1), 0.0, 1e-3);
  EXPECT_NEAR(liveWireEdgeCost(f, o, 8, 1, 9, 2), 0.0, 1e-3);
  // Robust reference: the 10% quantile (G = 10) clips everything at or above it to 255.
  o.gradientReferenceQuantile = 0.1;
  EXPECT_NEAR(liveWireEdgeCost(f, o, 2, 1, 3, 1), 0.0, 1e-3);
}

TEST(LiveWireCost, ParsesKindsAndRejectsBadOptions) {
  EXPECT_EQ(parseLiveWireCostKind("mb"), LiveWireCostKind::MortensenBarrett);
  EXPECT_EQ(parseLiveWireCostKind("gradient"), LiveWireCostKind::Gradient);
  EXPECT_EQ(liveWireCostKindName(LiveWireCostKind::Gradient), "gradient");
  EXPECT_THROW(parseLiveWireCostKind("canny"), InvalidArgument);
  const Features2D f = featuresOf(4, 4, 1, 1, [](int64_t u, int64_t) { return static_cast<float>(u); });
  LiveWireCostOptions bad;
  bad.weightG = -1;
  EXPECT_THROW(liveWireEdgeCosts(f, bad, kSteps8), InvalidArgument);
  bad = {};
  bad.weightZ = bad.weightG = bad.weightD = 0;
  EXPECT_THROW(liveWireEdgeCosts(f, bad, kSteps8), InvalidArgument);
  bad = {};
  bad.gradientReferenceQuantile = 0;
  EXPECT_THROW(liveWireEdgeCosts(f, bad, kSteps8), InvalidArgument);
  EXPECT_THROW(liveWireEdgeCost(f, {}, 0, 0, 2, 0), InvalidArgument);  // not neighbours
  EXPECT_THROW(liveWireEdgeCost(f, {}, 0, 0, -1, 0), InvalidArgument);
}

// The row-wise, vectorised bulk computation against the formulas of live_wire_cost.h evaluated
// edge by edge in double with std::acos (no shared code), on random images with flat patches
// (G == 0), isotropic and anisotropic spacing, both cost kinds, 8- and 4-neighbour steps and
// widths that exercise the vector loops' tails. Edges where D(p).e is within 1e-4 of 0 are
// skipped: eq. 11 switches L there, so float and double may legitimately pick different sides.
TEST(LiveWireCost, BulkCostsMatchTheFormulasEdgeByEdge) {
  struct Case {
    int64_t w, h;
    double su, sv, sigma;
  };
  const std::vector<std::array<int, 2>> steps4 = {{0, -1}, {-1, 0}, {1, 0}, {0, 1}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> val(0, 100);
  int64_t checked = 0;
  for (const Case& c : {Case{13, 9, 1, 1, 0}, Case{17, 6, 0.5, 1.5, 0}, Case{11, 10, 0.7, 0.7, 1.0},
                        Case{1, 5, 1, 1, 0}, Case{9, 1, 1, 1, 0}, Case{37, 5, 1.2, 0.8, 0}}) {
    std::vector<float> img(static_cast<size_t>(c.w * c.h));
    for (auto& x : img) x = val(rng);
    for (int64_t v = 0; v < std::min<int64_t>(3, c.h); ++v)
      for (int64_t u = 0; u < std::min<int64_t>(4, c.w); ++u) img[static_cast<size_t>(u + c.w * v)] = 5.0f;
    const Features2D f = featuresOf(
        c.w, c.h, c.su, c.sv, [&](int64_t u, int64_t v) { return img[static_cast<size_t>(u + c.w * v)]; }, c.sigma);
    for (const auto kind : {LiveWireCostKind::MortensenBarrett, LiveWireCostKind::Gradient})
      for (const auto* steps : {&kSteps8, &steps4}) {
        LiveWireCostOptions o;
        o.kind = kind;
        const auto K = steps->size();
        const auto cost = liveWireEdgeCosts(f, o, *steps);
        ASSERT_EQ(cost.size(), static_cast<size_t>(f.pixelCount()) * K);
        const double gref = f.maxMagnitude;
        auto rel = [&](size_t i) { return gref > 0 ? std::min<double>(f.magnitude[i], gref) / gref : 0.0; };
        auto unitD = [&](size_t i) {
          const double g = f.magnitude[i];
          return g > 0 ? std::array<double, 2>{f.gradV[i] / g, -f.gradU[i] / g} : std::array<double, 2>{0, 0};
        };
        for (int64_t v = 0; v < c.h; ++v)
          for (int64_t u = 0; u < c.w; ++u)
            for (size_t k = 0; k < K; ++k) {
              const auto p = static_cast<size_t>(f.index(u, v));
              const float got = cost[p * K + k];
              const int64_t qu = u + (*steps)[k][0], qv = v + (*steps)[k][1];
              if (!f.contains(qu, qv)) {
                EXPECT_TRUE(std::isinf(got) && got > 0);
                continue;
              }
              const auto q = static_cast<size_t>(f.index(qu, qv));
              const double eu = (*steps)[k][0] * c.su, ev = (*steps)[k][1] * c.sv, len = std::hypot(eu, ev);
              double expected = 0;
              if (kind == LiveWireCostKind::Gradient) {
                expected = len * (255.0 - (255.0 * rel(p) + 255.0 * rel(q)) / 2);
              } else {
                const auto dp = unitD(p), dq = unitD(q);
                const double pe = (dp[0] * eu + dp[1] * ev) / len;
                if (std::fabs(pe) < 1e-4 && (dp[0] != 0 || dp[1] != 0)) continue;
                const double sgn = pe >= 0 ? 1.0 : -1.0;  // L = e or -e (eq. 11)
                const double qe = sgn * (dq[0] * eu + dq[1] * ev) / len;
                const double fD = 2.0 / (3.0 * std::numbers::pi) *
                                  (std::acos(std::clamp(sgn * pe, -1.0, 1.0)) + std::acos(std::clamp(qe, -1.0, 1.0)));
                const double fZ = f.zeroCrossing[q] ? 0.0 : 1.0, fG = 1.0 - rel(q);
                expected = len * (0.43 * fZ + 0.43 * fG + 0.14 * fD);
              }
              EXPECT_NEAR(got, expected, 2e-5 * (1 + std::fabs(expected)))
                  << c.w << "x" << c.h << " (" << u << "," << v << ") step " << k << " of " << K;
              ++checked;
            }
      }
  }
  EXPECT_GT(checked, 4000);
}

TEST(LiveWireCost, RejectsStepsThatAreNotNeighbours) {
  const Features2D f = featuresOf(4, 3, 1, 1, [](int64_t u, int64_t) { return static_cast<float>(u); });
  EXPECT_THROW(liveWireEdgeCosts(f, {}, {{2, 0}}), InvalidArgument);
  EXPECT_THROW(liveWireEdgeCosts(f, {}, {{0, 0}}), InvalidArgument);
  EXPECT_THROW(liveWireEdgeCosts(f, {}, {}), InvalidArgument);
}
