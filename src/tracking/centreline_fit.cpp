// The refined line's points fitted along their stretch (centreline_junctions.h: fitAlongStretches).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

namespace {

// The points of k's plain stretch within `reach` mm of k along the tree (k included), with their arc offsets from k
// (negative towards the root). False where the stretch does not run the whole reach on both sides: a fork, an end,
// the root (a clicked point, not centred) or a fixed point (a junction's zone) lies within it, beyond which the points
// are not of one lumen's axis with k's, and a window cut short on one side makes the fit lean to the other (the points
// a root clicked off the axis pulled aside would pull their neighbours).
bool stretchAround(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                   const std::vector<uint8_t>& fixed, const std::vector<Vec3>& q, size_t k, double reach,
                   std::vector<std::pair<double, size_t>>& out) {
  out.assign(1, {0.0, k});
  double s = 0;
  for (size_t i = k;;) {
    if (parent[i] <= 0) return false;
    const size_t p = static_cast<size_t>(parent[i]);
    s += (q[i] - q[p]).norm();
    if (s > reach) break;
    if (fixed[p] || children[p].size() != 1) return false;
    out.emplace_back(-s, p);
    i = p;
  }
  s = 0;
  for (size_t i = k;;) {
    if (children[i].size() != 1) return false;
    const size_t c = static_cast<size_t>(children[i][0]);
    s += (q[c] - q[i]).norm();
    if (s > reach) break;
    if (fixed[c]) return false;
    out.emplace_back(s, c);
    i = c;
  }
  return true;
}

}  // namespace

void fitAlongStretches(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                       const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& wideTrunk,
                       const std::vector<double>& radiusMm, std::vector<Vec3>& q) {
  const std::vector<Vec3> from = q;
  // A wide trunk's points (wideTrunk 1: each at its own ball's centre, frozen) are fitted as the others are; the
  // junctions' zones stay.
  std::vector<uint8_t> fixed(frozen);
  for (size_t k = 0; k < fixed.size() && k < wideTrunk.size(); ++k)
    if (wideTrunk[k] == 1) fixed[k] = 0;
  std::vector<std::pair<double, size_t>> st;
  std::vector<Vec3> move(q.size(), Vec3::Zero());
  std::vector<uint8_t> fitted(q.size(), 0);
  for (size_t k = 1; k < q.size(); ++k) {
    if (fixed[k] || children[k].size() != 1) continue;  // ends, forks and junctions' points stay
    const double reach = 2 * radiusMm[k];
    if (!stretchAround(parent, children, fixed, from, k, reach, st)) continue;
    int before = 0, after = 0;
    for (const auto& [s, i] : st) {
      if (s < 0) ++before;
      if (s > 0) ++after;
    }
    if (before < 2 || after < 2) continue;  // too few points for a quadratic on a side
    // Weighted least squares of x(s) = c0 + c1 s + c2 s^2 (Gaussian weights, sigma reach / 2): a bend (constant
    // curvature) is fitted exactly, a side-to-side alternation between neighbours is not.
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Matrix<double, 3, 3> atb = Eigen::Matrix<double, 3, 3>::Zero();
    for (const auto& [s, i] : st) {
      const double w = std::exp(-2.0 * (s / reach) * (s / reach));
      const Eigen::Vector3d b(1.0, s, s * s);
      ata += w * b * b.transpose();
      atb += w * b * from[i].transpose();
    }
    const Eigen::Matrix3d c = ata.ldlt().solve(atb);  // rows: c0, c1, c2 (each a position / direction)
    const Vec3 at = c.row(0).transpose(), along = c.row(1).transpose();
    if (!at.allFinite() || along.norm() < 1e-9) continue;
    const Vec3 t = along.normalized();
    Vec3& m = move[k];
    m = at - from[k];
    m -= m.dot(t) * t;  // sideways only: the points' spacing along the line stays
    // At most half the radius: the point stays well inside the lumen it was centred in.
    if (m.norm() > 0.5 * radiusMm[k]) m *= 0.5 * radiusMm[k] / m.norm();
    fitted[k] = 1;
  }
  for (size_t k = 1; k < q.size(); ++k)
    if (fitted[k]) q[k] = from[k] + move[k];
}

}  // namespace vs::centreline_detail
