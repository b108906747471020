// A daughter's axis read from the image near a wide trunk (daughter_tube.h).
#include "tracking/daughter_tube.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace vs::centreline_detail {

namespace {

constexpr size_t minVoxels = 30;

// The voxels taking part: their centres (mm) and values.
struct TubeSamples {
  std::vector<Vec3> x;
  std::vector<double> v;
};

// The cylinder's parameters: the axis moved across (p0, p1 along u1, u2) from c0, its direction e0 + p2 u1 +
// p3 u2, and its radius p4.
using Params = Eigen::Matrix<double, 5, 1>;

struct TubeModel {
  Vec3 c0, e0, u1, u2, spacing;
  Vec3 centre(const Params& p) const { return c0 + p[0] * u1 + p[1] * u2; }
  Vec3 dir(const Params& p) const { return (e0 + p[2] * u1 + p[3] * u2).normalized(); }
  // Per voxel: the fraction of it inside the cylinder, a linear ramp over its extent along the normal.
  void coverage(const TubeSamples& s, const Params& p, Eigen::VectorXd& cov) const {
    const Vec3 c = centre(p), e = dir(p);
    cov.resize(static_cast<Eigen::Index>(s.x.size()));
    for (size_t i = 0; i < s.x.size(); ++i) {
      const Vec3 w = s.x[i] - c, off = w - w.dot(e) * e;
      const double d = off.norm();
      const Vec3 n = d > 1e-12 ? Vec3(off / d) : u1;
      const double extent = n.cwiseAbs().dot(spacing);
      cov[static_cast<Eigen::Index>(i)] = std::clamp(0.5 - (d - p[4]) / extent, 0.0, 1.0);
    }
  }
  // The residuals of the best levels (background + contrast x coverage, least squares) for p; false where
  // the coverage does not vary (no edge in the window).
  bool residuals(const TubeSamples& s, const Params& p, Eigen::VectorXd& r, double* contrast = nullptr) const {
    Eigen::VectorXd cov;
    coverage(s, p, cov);
    const Eigen::Map<const Eigen::VectorXd> v(s.v.data(), static_cast<Eigen::Index>(s.v.size()));
    const double n = static_cast<double>(cov.size()), mc = cov.mean(), mv = v.mean();
    const double var = (cov.array() - mc).square().sum();
    if (!(var > 1e-9 * n)) return false;
    const double b = ((cov.array() - mc) * (v.array() - mv)).sum() / var, a = mv - b * mc;
    r = (a + b * cov.array()).matrix() - v;
    if (contrast) *contrast = b;
    return true;
  }
};

// Levenberg-Marquardt on the five parameters, Jacobian by forward differences.
bool fitTube(const TubeModel& m, const TubeSamples& s, Params& p) {
  const std::array<double, 5> h{1e-3, 1e-3, 1e-4, 1e-4, 1e-3};
  Eigen::VectorXd r, rp;
  if (!m.residuals(s, p, r)) return false;
  double cost = r.squaredNorm(), lambda = 1e-3;
  for (int it = 0; it < 100; ++it) {
    Eigen::MatrixXd J(r.size(), 5);
    for (int k = 0; k < 5; ++k) {
      Params q = p;
      q[k] += h[static_cast<size_t>(k)];
      if (!m.residuals(s, q, rp)) return false;
      J.col(k) = (rp - r) / h[static_cast<size_t>(k)];
    }
    const Eigen::Matrix<double, 5, 5> JtJ = J.transpose() * J;
    const Params g = J.transpose() * r;
    bool stepped = false;
    for (int tries = 0; tries < 10 && !stepped; ++tries) {
      Eigen::Matrix<double, 5, 5> A = JtJ;
      A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12);
      const Params step = A.ldlt().solve(-g);
      const Params q = p + step;
      if (!(q[4] > 0) || !m.residuals(s, q, rp)) {
        lambda *= 10;
        continue;
      }
      const double c = rp.squaredNorm();
      if (c < cost) {
        const double gain = cost - c;
        p = q, r = rp, cost = c, lambda = std::max(lambda / 10, 1e-9), stepped = true;
        if (gain < 1e-10 * cost && step.cwiseAbs().maxCoeff() < 1e-6) return true;
      } else {
        lambda *= 10;
      }
    }
    if (!stepped) return true;  // no step lowers the cost: a minimum
  }
  return true;
}

}  // namespace

bool fitDaughterTube(const TrilinearSampler& sample, const Vec3& spacing, const std::vector<Vec3>& chordIn,
                     const Vec3& ac, const Vec3& ea, double trunkMm, double daughterMm, int side, Vec3& centre,
                     Vec3& dir) {
  if (!(daughterMm > 0)) return false;
  // The window holds the daughter's own voxels only beyond the trunk's partial volume: a chord that lies within
  // it (a fork of near-equal calibres at a shallow angle: the chest CTA's carina, the aorta's bifurcation) has
  // nothing there to fit, and the few voxels past it left J moved 12 mm; so the chord beyond it, 3 points or more.
  const double ext = spacing.maxCoeff();
  std::vector<Vec3> chord;
  for (const Vec3& x : chordIn)
    if (const Vec3 v = x - ac; (v - v.dot(ea) * ea).norm() > trunkMm + ext) chord.push_back(x);
  if (chord.size() < 3) return false;
  TubeModel m;
  m.spacing = spacing;
  m.c0 = Vec3(0, 0, 0);
  for (const Vec3& x : chord) m.c0 += x;
  m.c0 /= static_cast<double>(chord.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& x : chord) cov += (x - m.c0) * (x - m.c0).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  m.e0 = es.eigenvectors().col(2);
  if (m.e0.dot(chord.back() - chord.front()) < 0) m.e0 = -m.e0;
  m.u1 = m.e0.unitOrthogonal(), m.u2 = m.e0.cross(m.u1);
  double tlo = std::numeric_limits<double>::infinity(), thi = -tlo;
  for (const Vec3& x : chord) tlo = std::min(tlo, (x - m.c0).dot(m.e0)), thi = std::max(thi, (x - m.c0).dot(m.e0));
  tlo -= daughterMm;
  const double reach = daughterMm + 2 * ext;
  // The window: the voxels near the chord's line, beyond the trunk's wall and its partial volume.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& x : chord) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  lo = (lo.array() - reach - daughterMm).matrix().cwiseQuotient(spacing);
  hi = (hi.array() + reach + daughterMm).matrix().cwiseQuotient(spacing);
  TubeSamples s;
  for (double z = std::ceil(lo[2]); z <= hi[2]; ++z)
    for (double y = std::ceil(lo[1]); y <= hi[1]; ++y)
      for (double x = std::ceil(lo[0]); x <= hi[0]; ++x) {
        const Vec3 idx(x, y, z);
        if (!sample.inside(idx)) continue;
        const Vec3 p = idx.cwiseProduct(spacing), v = p - ac, w = p - m.c0;
        const double t = w.dot(m.e0);
        if (t <= tlo || t >= thi) continue;
        if ((v - v.dot(ea) * ea).norm() <= trunkMm + ext || (w - t * m.e0).norm() >= reach) continue;
        s.x.push_back(p), s.v.push_back(sample.at(idx));
      }
  if (s.x.size() < minVoxels) return false;
  Params p;
  p << 0, 0, 0, 0, daughterMm;
  double contrast = 0;
  Eigen::VectorXd r;
  if (!fitTube(m, s, p) || !(p[4] > 0 && p[4] <= 3 * daughterMm) || !m.residuals(s, p, r, &contrast)) return false;
  if (!(side * contrast > 0)) return false;
  // The tube the chord's points lie in: each of them inside the fitted lumen (else the fit took another tube or
  // a bend the straight cylinder cannot follow: the chest CTA's bronchus at the carina, J moved 12 mm).
  const Vec3 c = m.centre(p), e = m.dir(p);
  for (const Vec3& x : chord)
    if (((x - c) - (x - c).dot(e) * e).norm() > p[4]) return false;
  centre = c, dir = e;
  return true;
}

}  // namespace vs::centreline_detail
