// A fork whose tree branches past its junction, found from the sections along the shared chain (session 44 kindC6:
// scan60b's form (i)). See fork_sections.h.
#include "tracking/fork_sections.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vs::centreline_detail {

namespace {

// The arc length along `arm` from `from` to its point i (inclusive).
double arcAlong(const std::vector<Vec3>& q, const Vec3& from, const std::vector<size_t>& arm, size_t i) {
  double arc = 0;
  Vec3 prev = from;
  for (size_t j = 0; j <= i && j < arm.size(); ++j) arc += (q[arm[j]] - prev).norm(), prev = q[arm[j]];
  return arc;
}

// The median chord (mm, `widest`: the widest or the narrowest) of the parent arm's sections `up` lying past `reachMm`
// from b and within twice it; NaN where none is read there.
template <class Widest>
double parentChordMm(const RunInput& in, const std::vector<size_t>& up, size_t b, double reachMm, Widest&& widest) {
  std::vector<double> w;
  for (size_t i = 0; i < up.size(); ++i) {
    const double d = (in.q[up[i]] - in.q[b]).norm();
    if (d > 2 * reachMm) break;
    if (d <= reachMm) continue;
    const double c = widest(up[i]);
    if (std::isfinite(c)) w.push_back(c);
  }
  if (w.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(w.size() / 2), w.end());
  return w[w.size() / 2];
}

}  // namespace

bool sectionRun(const RunInput& in, size_t b, Vec3& J, Vec3 (&G)[3]) {
  const auto& arms = in.arms;
  if (!in.lobes || arms.size() != 3 || in.ownR.size() != 3 || arms[0].empty() || arms[1].empty() || arms[2].empty())
    return false;
  if (!(in.ownR[0] > 0) || !(in.ownR[1] > 0) || !(in.ownR[2] > 0)) return false;
  const Vec3 grid = in.spacing.minCoeff() > 0 ? in.spacing : Vec3::Constant(in.voxMm);
  const double maxMm = 2 * (in.ownR[0] + in.ownR[1] + in.ownR[2]) + 2 * in.voxMm;
  const auto chord = [&](size_t k, bool wide) {  // NaN where no wall is found within maxMm
    Vec3 dir;
    double plus = 0, minus = 0, narrowest = 0;
    if (!in.lobes(k, maxMm, dir, plus, minus, narrowest)) return std::numeric_limits<double>::quiet_NaN();
    return wide ? plus + minus : narrowest;
  };
  const auto widest = [&](size_t k) { return chord(k, true); };
  const auto narrowest = [&](size_t k) { return chord(k, false); };
  const std::vector<size_t>& up = arms[0];
  const double reachUp = 4 * in.ownR[0] + 2 * in.voxMm;
  // The parent's own lumen, read from its own sections before the fork: the median widest chord over the parent arm's
  // sections past forkJunction's reach and within as far again (its calibre where it is the parent's tube alone, as
  // the image shows it: a real vessel's section is not round, tapers, widens towards a fork - its analysed radius
  // says none of that), plus the grid's largest spacing (a wall read on the grid: each of a chord's two ends within
  // half a voxel along it, so its length within a spacing). A section wider than that holds more than the parent's
  // tube. No section there (a parent arm within the reach): no own calibre to read, no reading.
  const double roundMm = parentChordMm(in, up, b, reachUp, widest) + grid.maxCoeff();
  if (!(roundMm > 0)) return false;
  const auto fused = [&](size_t k) {  // true also where no wall is found within maxMm
    const double w = widest(k);
    return !(w <= roundMm);
  };
  // b's section fused, then up the shared chain to J, the first section that is the parent's round lumen, within
  // forkJunction's reach of b.
  if (!fused(b)) return false;
  // Two children side by side widen the lumen along one chord only: each is thinner than the parent, so the union's
  // narrowest chord is no wider than the parent's own (its sections' median narrowest chord, + a spacing: 6321's b
  // 4.49 mm across). A lumen wider across too is the parent's own widening (a bulb, a sinus, a taper towards the fork,
  // an aneurysm's neck), not a fused fork.
  const double acrossMm = parentChordMm(in, up, b, reachUp, narrowest) + grid.maxCoeff();
  if (!(narrowest(b) <= acrossMm)) return false;
  size_t j = 0;
  for (; fused(up[j]); ++j)
    if (j + 1 >= up.size() || (in.q[up[j + 1]] - in.q[b]).norm() > reachUp) return false;
  // b's parent's section the parent's own already: no shared point before b lies in the union (b itself lies in both
  // children's lobes at any fork), the tree branches at the junction (12524 / 6624: their b's straight J -> G pieces
  // cut the crotch, 99.7 -> 96.9 %, 98.3 -> 97.9 %).
  if (j == 0) return false;
  // The run from J down through b and on along both arms while fused (to the nearer arm run's end) must reach farther
  // than the junction's reach (twoDiscRun's: the parent's radius + the wider child's; a shorter one is the zone's).
  double armMm = std::numeric_limits<double>::infinity();
  for (size_t a = 1; a < 3; ++a) {
    size_t r = 0;
    while (r < arms[a].size() && fused(arms[a][r])) ++r;
    if (r == 0) return false;  // a child already out of the union at b: the tree branches at the parting
    armMm = std::min(armMm, arcAlong(in.q, in.q[b], arms[a], r - 1));
  }
  if (arcAlong(in.q, in.q[b], up, j) + armMm <= in.ownR[0] + std::max(in.ownR[1], in.ownR[2])) return false;
  J = in.q[up[j]];
  // G: each arm's first point past its zone, or its last where the zone runs to its end (a next fork close by).
  for (size_t a = 1; a < 3; ++a) G[a] = in.q[arms[a][std::min(in.zone[a], arms[a].size() - 1)]];
  return true;
}

}  // namespace vs::centreline_detail
