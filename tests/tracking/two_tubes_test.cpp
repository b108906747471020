// The two-tube section fit of the kissing refinement (src/tracking/two_tubes.cpp, issue 21; session 31 lm32): known
// discs on a synthetic section are recovered, and one disc is not read as two.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <random>

#include "tracking/centreline_junctions.h"

namespace vs {
namespace {

// A partial-volume-blurred disc's share of lumen at distance d from its centre (radius r, Gaussian blur s).
double blurredDisc(double d, double r, double s) { return 0.5 * std::erfc((d - r) / (std::sqrt(2.0) * s)); }

// A section normal to z through the origin: background 100 plus 200 x the union of the discs (own at ownC, radius
// ownR; other at otherC, radius otherR; blur 0.5 mm), with Gaussian noise (sd 4) drawn per position (the same at the
// same point, whatever the order of sampling), so the fit's residual is never zero.
struct Section {
  Vec3 ownC, otherC;
  double ownR, otherR, blur = 0.5;
  bool two = true;
  double operator()(const Vec3& p) const {
    std::mt19937 rng(
        static_cast<uint32_t>(std::llround(p[0] * 1000) * 73856093 ^ std::llround(p[1] * 1000) * 19349663));
    std::normal_distribution<double> noise(0, 4);
    const Vec3 inPlane(p[0], p[1], 0);
    const double a = blurredDisc((inPlane - ownC).norm(), ownR, blur);
    const double b = two ? blurredDisc((inPlane - otherC).norm(), otherR, blur) : 0;
    return 100 + 200 * (1 - (1 - a) * (1 - b)) + noise(rng);
  }
};

TEST(TwoTubeSection, RecoversTwoKnownDiscsOnASyntheticSection) {
  const Vec3 spacings[] = {Vec3(1, 1, 1), Vec3(0.6, 0.6, 1.8)};
  for (const Vec3& spacing : spacings) {
    const Section sec{Vec3(0.8, 0.2, 0), Vec3(-1.9, -0.4, 0), 1.5, 2.2};
    const std::function<double(const Vec3&)> value = [&](const Vec3& p) { return sec(p); };
    // The chain's line 0.4 mm off the own centre, the blob's median ray 2.8 mm (the blob spans 4.1 + 2.3 mm).
    const auto f = centreline_detail::fitTwoTubeSection(Vec3::Zero(), Vec3(0, 0, 1), Vec3(0.5, -0.1, 0), sec.ownR, 2.8,
                                                        spacing, value, 10.0);
    EXPECT_TRUE(f.decisive) << "dBic " << f.dBic;
    EXPECT_LT((f.own - sec.ownC).norm(), 0.15) << f.own.transpose();
    EXPECT_LT((f.otherAt - sec.otherC).norm(), 0.15) << f.otherAt.transpose();
    EXPECT_NEAR(f.other, sec.otherR, 0.15);
    EXPECT_NEAR(f.blur, sec.blur, 0.15);
    EXPECT_NEAR(f.sep, (sec.ownC - sec.otherC).norm(), 0.2);
  }
}

TEST(TwoTubeSection, OneDiscIsNotTwoTubes) {
  Section sec{Vec3(0.3, 0, 0), Vec3::Zero(), 2.5, 0};
  sec.two = false;
  const std::function<double(const Vec3&)> value = [&](const Vec3& p) { return sec(p); };
  const auto f = centreline_detail::fitTwoTubeSection(Vec3::Zero(), Vec3(0, 0, 1), Vec3(0.2, 0, 0), 1.2, 2.5,
                                                      Vec3(1, 1, 1), value, 10.0);
  EXPECT_FALSE(f.decisive) << "dBic " << f.dBic << " sep " << f.sep << " other " << f.other;
}

}  // namespace
}  // namespace vs
