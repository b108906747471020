// Session 44 speedD: the two-tube test's disc models keep a disc's values where a Jacobian column or a step moved
// none of its parameters; every shape, residual and fit must be bit for bit the per-sample formula's (the code before:
// a std::function shape formed at every sample, both discs and their radius and blur formed again each time).
#include "tracking/disc_shapes.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>

namespace vs::centreline_detail::discs {
namespace {

using Shape = std::function<double(const VecX&, const Vec2&)>;

// The code before speedD, as it was (two_tubes.cpp): the reference every kept value is checked against.
double refResiduals(const Samples& s, const Shape& f, const VecX& th, VecX& res, double& contrast) {
  const Eigen::Index n = s.v.size();
  VecX shape(n);
  for (Eigen::Index i = 0; i < n; ++i) shape[i] = f(th, s.p[static_cast<size_t>(i)]);
  const double ms = shape.mean(), mv = s.v.mean();
  const double sxx = (shape.array() - ms).square().sum();
  contrast = sxx > 1e-12 ? ((shape.array() - ms) * (s.v.array() - mv)).sum() / sxx : 0.0;
  res = s.v - (VecX::Constant(n, mv - contrast * ms) + contrast * shape);
  return res.squaredNorm();
}

double refFit(const Samples& s, const Shape& f, VecX& th, double& contrast) {
  VecX r, r2;
  double cost = refResiduals(s, f, th, r, contrast), lambda = 1e-3, c2 = 0;
  for (int it = 0; it < 60; ++it) {
    Eigen::MatrixXd J(r.size(), th.size());
    for (Eigen::Index j = 0; j < th.size(); ++j) {
      VecX t = th;
      const double h = 1e-5 * std::max(1.0, std::abs(th[j]));
      t[j] += h;
      refResiduals(s, f, t, r2, c2);
      J.col(j) = (r2 - r) / h;
    }
    const Eigen::MatrixXd A = J.transpose() * J;
    const VecX g = J.transpose() * r;
    bool better = false;
    for (int tries = 0; tries < 12 && !better; ++tries, lambda *= 10) {
      Eigen::MatrixXd Ad = A;
      Ad.diagonal() += lambda * A.diagonal() + VecX::Constant(th.size(), 1e-12);
      const VecX t = th - Ad.ldlt().solve(g);
      const double c = refResiduals(s, f, t, r2, c2);
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

Shape refOne() {
  return [](const VecX& th, const Vec2& p) { return disc(p, th.head<2>(), std::exp(th[2]), std::exp(th[3])); };
}
Shape refTwo(double ownR) {
  return [ownR](const VecX& th, const Vec2& p) {
    const double blur = std::exp(th[5]);
    return 1 - (1 - disc(p, th.head<2>(), ownR, blur)) * (1 - disc(p, th.segment<2>(2), std::exp(th[4]), blur));
  };
}

bool sameBits(double a, double b) { return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b); }
bool sameBits(const VecX& a, const VecX& b) {
  if (a.size() != b.size()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (!sameBits(a[i], b[i])) return false;
  return true;
}

// A blob's section: two blurred discs side by side (own radius ownR), noise, a window of half-voxel samples.
Samples blob(std::mt19937& rng, double ownR, double otherR, double sep, double blur, double noise) {
  std::normal_distribution<double> n01(0, 1);
  Samples s;
  std::vector<double> v;
  const double reach = 1.6 * (0.5 * (sep + ownR + otherR)) + 0.6, h = 0.3;
  const Vec2 own(0.5 * sep, 0.1), other(-0.5 * sep, -0.2);
  for (double x = -reach; x <= reach; x += h)
    for (double y = -reach; y <= reach; y += h) {
      if (x * x + y * y > reach * reach) continue;
      const Vec2 p(x, y);
      const double shape = 1 - (1 - disc(p, own, ownR, blur)) * (1 - disc(p, other, otherR, blur));
      s.p.push_back(p), v.push_back(100 + 300 * shape + noise * n01(rng));
    }
  s.v = Eigen::Map<VecX>(v.data(), static_cast<Eigen::Index>(v.size()));
  s.nEff = static_cast<double>(v.size()) / 4;
  return s;
}

TEST(DiscShapes, AKeptDiscEqualsTheOneFormedAgain) {
  std::mt19937 rng(4401);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  int kept = 0;
  for (int k = 0; k < 50; ++k) {
    const Samples s = blob(rng, 1 + 0.3 * u(rng), 1 + 0.3 * u(rng), 1.5 + u(rng), 0.3 + 0.1 * u(rng), 5);
    const TwoDiscs two{1.2 + 0.2 * u(rng)};
    VecX th(6);
    th << u(rng), u(rng), u(rng), u(rng), 0.2 * u(rng), -1 + 0.2 * u(rng);
    DiscParts at, moved, fresh;
    VecX shape, shapeFresh;
    two.eval(s, th, nullptr, at, shape);
    for (Eigen::Index i = 0; i < shape.size(); ++i)
      ASSERT_TRUE(sameBits(shape[i], refTwo(two.ownR)(th, s.p[static_cast<size_t>(i)])));
    for (Eigen::Index j = 0; j <= 6; ++j) {  // each column's move, and all six at once
      VecX t = th;
      if (j < 6)
        t[j] += 1e-5 * std::max(1.0, std::abs(th[j]));
      else
        t.array() += 1e-3;
      two.eval(s, t, &at, moved, shape);
      two.eval(s, t, nullptr, fresh, shapeFresh);
      EXPECT_TRUE(sameBits(shape, shapeFresh)) << k << " column " << j;
      EXPECT_TRUE(sameBits(moved.a, fresh.a) && sameBits(moved.b, fresh.b)) << k << " column " << j;
      kept += j < 5;  // columns 0-4 keep one disc (5, the blur, moves both)
    }
  }
  EXPECT_EQ(kept, 250);
}

TEST(DiscShapes, EveryFitEqualsThePerSampleFormulasFit) {
  std::mt19937 rng(4402);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 40; ++k) {
    const double ownR = 1 + 0.4 * u(rng), otherR = 1 + 0.4 * u(rng), blur = 0.35 + 0.15 * u(rng);
    const Samples s = blob(rng, ownR, otherR, 1.6 + 0.8 * u(rng), blur, 2 + 10 * (k % 4));
    VecX one(4), oneRef(4);
    one << 0.1 * u(rng), 0.1 * u(rng), std::log(1.5 + 0.3 * u(rng)), std::log(0.3);
    oneRef = one;
    double c = 0, cRef = 0;
    const double rss1 = fitShape(s, OneDisc{}, one, c), rss1Ref = refFit(s, refOne(), oneRef, cRef);
    EXPECT_TRUE(sameBits(rss1, rss1Ref) && sameBits(one, oneRef) && sameBits(c, cRef)) << k << " one disc";
    VecX two(6), twoRef(6);
    two << 0.5, 0, -0.8 + 0.3 * u(rng), 0.2 * u(rng), std::log(1 + 0.3 * u(rng)), std::log(0.3);
    twoRef = two;
    const double rss2 = fitShape(s, TwoDiscs{ownR}, two, c), rss2Ref = refFit(s, refTwo(ownR), twoRef, cRef);
    EXPECT_TRUE(sameBits(rss2, rss2Ref) && sameBits(two, twoRef) && sameBits(c, cRef)) << k << " two discs";
  }
}

}  // namespace
}  // namespace vs::centreline_detail::discs
