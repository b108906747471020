// See disc_shapes.h.
#include "tracking/disc_shapes.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

namespace vs::centreline_detail::discs {

double disc(const Vec2& p, const Vec2& c, double r, double s) {
  return 0.5 * std::erfc(((p - c).norm() - r) / (std::sqrt(2.0) * s));
}

namespace {

// Whether th[k] and from->th[k] hold the same bits for every k in ks (a disc of those parameters has the same values).
template <size_t N>
bool sameAt(const VecX& th, const DiscParts* from, const int (&ks)[N]) {
  if (!from || from->th.size() != th.size()) return false;
  for (int k : ks)
    if (std::bit_cast<uint64_t>(th[k]) != std::bit_cast<uint64_t>(from->th[k])) return false;
  return true;
}

}  // namespace

void OneDisc::eval(const Samples& s, const VecX& th, const DiscParts* /*from*/, DiscParts& out, VecX& shape) const {
  const Eigen::Index n = s.v.size();
  const Vec2 c = th.head<2>();
  const double r = std::exp(th[2]), blur = std::exp(th[3]);
  out.th = th, out.a.resize(n), shape.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) shape[i] = out.a[i] = disc(s.p[static_cast<size_t>(i)], c, r, blur);
}

namespace {

// Two blurred discs sharing the blur th[5], the other's centre th[2..3] and log radius th[4]; the own disc's centre
// th[0..1] at radius ownR. A disc none of whose parameters moved since `from` is kept (keepOwn: the caller's own
// parameters, which differ between the fixed and the free own radius).
void evalTwoDiscs(const Samples& s, const VecX& th, const DiscParts* from, DiscParts& out, VecX& shape, bool keepOwn,
                  double ownR) {
  const Eigen::Index n = s.v.size();
  const bool keepOther = sameAt(th, from, {2, 3, 4, 5});
  const double blur = std::exp(th[5]);
  if (keepOwn) {
    out.a = from->a;
  } else {
    const Vec2 c = th.head<2>();
    out.a.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) out.a[i] = disc(s.p[static_cast<size_t>(i)], c, ownR, blur);
  }
  if (keepOther) {
    out.b = from->b;
  } else {
    const Vec2 c = th.segment<2>(2);
    const double r = std::exp(th[4]);
    out.b.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) out.b[i] = disc(s.p[static_cast<size_t>(i)], c, r, blur);
  }
  out.th = th, shape.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) shape[i] = 1 - (1 - out.a[i]) * (1 - out.b[i]);
}

}  // namespace

void TwoDiscs::eval(const Samples& s, const VecX& th, const DiscParts* from, DiscParts& out, VecX& shape) const {
  evalTwoDiscs(s, th, from, out, shape, sameAt(th, from, {0, 1, 5}), ownR);
}

void TwoDiscsOwnFree::eval(const Samples& s, const VecX& th, const DiscParts* from, DiscParts& out, VecX& shape) const {
  evalTwoDiscs(s, th, from, out, shape, sameAt(th, from, {0, 1, 5, 6}), std::exp(th[6]));
}

double residualsOf(const Samples& s, const VecX& shape, VecX& res, double& contrast) {
  const Eigen::Index n = s.v.size();
  const double ms = shape.mean(), mv = s.v.mean();
  const double sxx = (shape.array() - ms).square().sum();
  contrast = sxx > 1e-12 ? ((shape.array() - ms) * (s.v.array() - mv)).sum() / sxx : 0.0;
  res = s.v - (VecX::Constant(n, mv - contrast * ms) + contrast * shape);
  return res.squaredNorm();
}

// Levenberg-Marquardt (forward-difference Jacobian) from th; returns the residual sum of squares. Kept over Eigen's
// unsupported LevenbergMarquardt (session 31 lm32, docs/notes/tracking.md): on the same sections Eigen's ended the
// two-disc fit at a higher residual in 17 of 163 sections (lower in 2), which lowers the decision's BIC gain.
// `at` holds the discs' values at th; a trial's or a column's evaluation keeps those of a disc whose parameters it
// did not move.
template <class Model>
double fitShape(const Samples& s, const Model& m, VecX& th, double& contrast) {
  VecX r, r2, shape;
  DiscParts at, trial;
  m.eval(s, th, nullptr, at, shape);
  double cost = residualsOf(s, shape, r, contrast), lambda = 1e-3, c2 = 0;
  for (int it = 0; it < 60; ++it) {
    Eigen::MatrixXd J(r.size(), th.size());
    for (Eigen::Index j = 0; j < th.size(); ++j) {
      VecX t = th;
      const double h = 1e-5 * std::max(1.0, std::abs(th[j]));
      t[j] += h;
      m.eval(s, t, &at, trial, shape);
      residualsOf(s, shape, r2, c2);
      J.col(j) = (r2 - r) / h;
    }
    const Eigen::MatrixXd A = J.transpose() * J;
    const VecX g = J.transpose() * r;
    bool better = false;
    for (int tries = 0; tries < 12 && !better; ++tries, lambda *= 10) {
      Eigen::MatrixXd Ad = A;
      Ad.diagonal() += lambda * A.diagonal() + VecX::Constant(th.size(), 1e-12);
      const VecX t = th - Ad.ldlt().solve(g);
      m.eval(s, t, &at, trial, shape);
      const double c = residualsOf(s, shape, r2, c2);
      if (c < cost) {
        better = cost - c > 1e-9 * cost;
        th = t, r = r2, cost = c, contrast = c2, lambda *= 0.03;
        std::swap(at, trial);
        if (!better) return cost;
      }
    }
    if (!better) break;
  }
  return cost;
}

template double fitShape<OneDisc>(const Samples&, const OneDisc&, VecX&, double&);
template double fitShape<TwoDiscs>(const Samples&, const TwoDiscs&, VecX&, double&);
template double fitShape<TwoDiscsOwnFree>(const Samples&, const TwoDiscsOwnFree&, VecX&, double&);

}  // namespace vs::centreline_detail::discs
