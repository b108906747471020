// The cross-section models of the two-tube test (two_tubes.cpp): one partial-volume-blurred disc, or two (the own
// at the chain's radius, the other free) under one blur, fitted by Levenberg-Marquardt with a forward-difference
// Jacobian. Session 44 speedD: a Jacobian column moves one parameter, and a disc none of whose parameters moved
// has the same value at every sample as at the point it was moved from - its values are kept (`DiscParts`), not
// formed again; the one disc's radius and blur are formed once per evaluation, not once per sample. Every value is
// the one the per-sample formula gives, bit for bit (tests/tracking/disc_shapes_test.cpp).
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace vs::centreline_detail::discs {

using Vec2 = Eigen::Vector2d;
using VecX = Eigen::VectorXd;

// A cross-section's samples (plane coordinates, mm) and values; nEff: the independent samples it holds (its area
// over the voxel's extent along both plane axes: trilinear samples across a thick slice are not independent).
struct Samples {
  std::vector<Vec2> p;
  VecX v;
  double nEff = 0;
};

// A partial-volume-blurred disc: the share of lumen at p of a disc (centre c, radius r) blurred by a Gaussian (s).
double disc(const Vec2& p, const Vec2& c, double r, double s);

// Per sample, the value of each disc of a model at the parameters `th` they were formed at.
struct DiscParts {
  VecX th;
  VecX a, b;  // the own (or only) disc; the other disc (two discs only)
};

// One disc: th = (centre x, centre y, log radius, log blur).
struct OneDisc {
  static constexpr int kParams = 4;
  // shape[i] = disc(p_i, th.head<2>(), exp(th[2]), exp(th[3])); `from` unused (every parameter moves the one disc).
  void eval(const Samples& s, const VecX& th, const DiscParts* from, DiscParts& out, VecX& shape) const;
};

// Two discs: th = (own centre x, y, other centre x, y, log other radius, log blur), the own radius fixed.
// shape[i] = 1 - (1 - own_i) (1 - other_i); a disc whose parameters are bit for bit those of `from` takes its values
// from `from`.
struct TwoDiscs {
  static constexpr int kParams = 6;
  double ownR = 0;
  void eval(const Samples& s, const VecX& th, const DiscParts* from, DiscParts& out, VecX& shape) const;
};

// Two discs with the own radius free too: th = TwoDiscs' six, then the own's log radius.
struct TwoDiscsOwnFree {
  static constexpr int kParams = 7;
  void eval(const Samples& s, const VecX& th, const DiscParts* from, DiscParts& out, VecX& shape) const;
};

// The residuals of the values against background + contrast x shape (both levels by least squares).
double residualsOf(const Samples& s, const VecX& shape, VecX& res, double& contrast);

// Levenberg-Marquardt from th; returns the residual sum of squares (`contrast`: the fit's contrast).
template <class Model>
double fitShape(const Samples& s, const Model& m, VecX& th, double& contrast);

extern template double fitShape<OneDisc>(const Samples&, const OneDisc&, VecX&, double&);
extern template double fitShape<TwoDiscs>(const Samples&, const TwoDiscs&, VecX&, double&);
extern template double fitShape<TwoDiscsOwnFree>(const Samples&, const TwoDiscsOwnFree&, VecX&, double&);

}  // namespace vs::centreline_detail::discs
