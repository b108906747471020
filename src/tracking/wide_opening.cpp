// A daughter's own lumen walked back to its opening in a wide trunk's wall (wide_trunk.h: openingCourse).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/wide_trunk.h"
#include "volume/plane_basis.h"

namespace vs::centreline_detail {

// wide_trunk.h
std::vector<Vec3> openingCourse(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& G, const Vec3& ed,
                                const Vec3& J, double daughterMm, double level, int side) {
  std::vector<Vec3> out;
  if (!(daughterMm > 0) || side == 0) return out;
  const Vec3 inv = spacing.cwiseInverse();
  const double step = 0.5 * spacing.minCoeff();
  // The section's disc: the daughter's lumen and as much again round it; the grid at most a third of its radius.
  const double rim = 2 * daughterMm, h = std::min(step, daughterMm / 3);
  const int m = static_cast<int>(std::ceil(rim / h)), w = 2 * m + 1;
  const PlaneBasis basis = planeBasis(ed);
  const Vec3 &u = basis.u, &v = basis.v;
  std::vector<uint8_t> cell(static_cast<size_t>(w) * static_cast<size_t>(w));
  std::vector<int> stack;
  Vec3 x = G;
  const double len = (G - J).dot(ed);
  for (double walked = 0; walked < len; walked += step) {
    std::fill(cell.begin(), cell.end(), 0);
    for (int j = 0; j < w; ++j)
      for (int i = 0; i < w; ++i) {
        const double a = h * (i - m), b = h * (j - m);
        if (a * a + b * b > rim * rim) continue;
        const Vec3 p = (x + a * u + b * v).cwiseProduct(inv);
        if (sample.inside(p) && side * (sample.at(p) - level) > 0) cell[static_cast<size_t>(j * w + i)] = 1;
      }
    const int start = m * w + m;
    if (!cell[static_cast<size_t>(start)]) break;  // the section's centre is not lumen: lost
    // The component holding the centre (4-connected); where it reaches the disc's rim, the section has joined
    // the trunk's lumen (or another one): the opening is behind.
    stack.assign(1, start);
    cell[static_cast<size_t>(start)] = 2;
    double sa = 0, sb = 0, count = 0;
    bool joined = false;
    while (!stack.empty()) {
      const int s = stack.back();
      stack.pop_back();
      const int i = s % w, j = s / w;
      const double a = h * (i - m), b = h * (j - m);
      if (a * a + b * b > (rim - h) * (rim - h)) joined = true;
      sa += a, sb += b, count += 1;
      const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
      for (const auto& o : nb) {
        const int ii = i + o[0], jj = j + o[1];
        if (ii < 0 || jj < 0 || ii >= w || jj >= w) continue;
        const int t = jj * w + ii;
        if (cell[static_cast<size_t>(t)] != 1) continue;
        cell[static_cast<size_t>(t)] = 2;
        stack.push_back(t);
      }
    }
    if (joined) break;
    const Vec3 c = x + (sa / count) * u + (sb / count) * v;
    out.push_back(c);
    x = c - step * ed;
  }
  return out;
}

}  // namespace vs::centreline_detail
