// Wide trunks and the daughters that leave them (wide_trunk.h).
#include "tracking/wide_trunk.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "util/parallel.h"

namespace vs::centreline_detail {

bool ballCentre(const TrilinearSampler& sample, const Vec3& spacing, Vec3& c, double rhoMm, double level,
                BallScratch& sc) {
  const Vec3 inv = spacing.cwiseInverse();
  if (!(rhoMm > 0) || !sample.inside(c.cwiseProduct(inv))) return false;
  const double value = sample.at(c.cwiseProduct(inv));
  if (!(value != level)) return false;
  const bool bright = value > level;
  const double h = std::max(spacing.minCoeff(), rhoMm / 8);
  const int m = static_cast<int>(std::ceil(rhoMm / h)), w = 2 * m + 1;
  const size_t cells = static_cast<size_t>(w) * static_cast<size_t>(w) * static_cast<size_t>(w);
  auto id = [&](int i, int j, int k) { return static_cast<int32_t>((k * w + j) * w + i); };
  Vec3 x = c;
  for (int it = 0; it < 20; ++it) {
    sc.lumen.assign(cells, 0);
    for (int k = 0; k < w; ++k)
      for (int j = 0; j < w; ++j)
        for (int i = 0; i < w; ++i) {
          const Vec3 d = h * Vec3(i - m, j - m, k - m);
          if (d.squaredNorm() > rhoMm * rhoMm) continue;
          const Vec3 p = (x + d).cwiseProduct(inv);
          if (!sample.inside(p)) continue;
          const double v = sample.at(p);
          sc.lumen[static_cast<size_t>(id(i, j, k))] = bright ? v > level : v < level;
        }
    const int32_t start = id(m, m, m);
    if (!sc.lumen[static_cast<size_t>(start)]) break;  // the centroid left the lumen: keep the last
    // The component holding the centre (6-connected), marked 2; its centroid.
    sc.stack.assign(1, start);
    sc.lumen[static_cast<size_t>(start)] = 2;
    Vec3 sum(0, 0, 0);
    double count = 0;
    while (!sc.stack.empty()) {
      const int32_t s = sc.stack.back();
      sc.stack.pop_back();
      const int i = s % w, j = (s / w) % w, k = s / (w * w);
      sum += Vec3(i - m, j - m, k - m), count += 1;
      const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
      for (const auto& o : nb) {
        const int a = i + o[0], b = j + o[1], e = k + o[2];
        if (a < 0 || b < 0 || e < 0 || a >= w || b >= w || e >= w) continue;
        const int32_t t = id(a, b, e);
        if (sc.lumen[static_cast<size_t>(t)] != 1) continue;
        sc.lumen[static_cast<size_t>(t)] = 2;
        sc.stack.push_back(t);
      }
    }
    const Vec3 shift = (h / count) * sum;
    x += shift;
    if (shift.norm() < 0.02 * spacing.minCoeff()) break;
  }
  c = x;
  return true;
}

namespace {

constexpr size_t linePoints = 5;
constexpr double ballRadii = 1.0;

// J: the trunk's axis point nearest the daughter's axis (G, unit direction ed outward), followed
// back from a trunk radius behind G (wide_trunk.h). False where a point of the line is not lumen
// or J does not lie behind G.
bool trunkJunction(const WideTrunkInput& in, const Vec3& G, const Vec3& ed, double trunkMm, double level,
                   BallScratch& sc, Vec3& J) {
  const double rho = ballRadii * trunkMm;
  Vec3 A = G - trunkMm * ed;
  if (!ballCentre(in.sample, in.spacing, A, rho, level, sc)) return false;
  for (int it = 0; it < 3; ++it) {
    const double t = (A - G).dot(ed);
    if (t >= 0) return false;
    A = G + t * ed;
    if (!ballCentre(in.sample, in.spacing, A, rho, level, sc)) return false;
  }
  J = A;
  return (J - G).dot(ed) < -in.spacing.minCoeff();
}

}  // namespace

size_t placeWideTrunk(const WideTrunkInput& in, std::vector<Vec3>& q, std::vector<uint8_t>& frozen,
                      std::vector<uint8_t>& placed) {
  const size_t n = q.size();
  std::vector<Vec3> target = q;
  std::vector<uint8_t> moved(n, 0);
  // A wide point's trunk radius: the median section radius of the wide points within `reach` tree
  // steps of it (its own section may be cut short at an ostium).
  auto trunkRadius = [&](size_t k0) {
    constexpr int reach = 6;
    std::vector<double> r;
    std::vector<std::pair<size_t, int>> todo{{k0, 0}};
    std::vector<size_t> seen{k0};
    while (!todo.empty()) {
      const auto [k, d] = todo.back();
      todo.pop_back();
      if (in.wide[k]) r.push_back(in.radiusMm[k]);
      if (d == reach) continue;
      std::vector<size_t> nb(in.children[k].begin(), in.children[k].end());
      if (in.parent[k] >= 0) nb.push_back(static_cast<size_t>(in.parent[k]));
      for (size_t j : nb)
        if (std::find(seen.begin(), seen.end(), j) == seen.end()) seen.push_back(j), todo.emplace_back(j, d + 1);
    }
    if (r.empty()) return in.radiusMm[k0];
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    return r[r.size() / 2];
  };
  auto ball = [&](size_t k, double rMm, double level, BallScratch& sc) {
    Vec3 c = q[k];
    if (ballCentre(in.sample, in.spacing, c, ballRadii * rMm, level, sc)) target[k] = c, moved[k] = 1;
  };
  parallelFor(
      1, static_cast<int64_t>(n),
      [&](int64_t b, int64_t e) {
        BallScratch sc;
        for (int64_t i = b; i < e; ++i) {
          const size_t k = static_cast<size_t>(i);
          if (in.wide[k] && !in.children[k].empty()) ball(k, trunkRadius(k), in.sectionLevel[k], sc);
        }
      },
      16);
  BallScratch sc;
  for (size_t c = 1; c < n; ++c) {
    const int32_t pi = in.parent[c];
    if (pi <= 0 || !in.wide[static_cast<size_t>(pi)] || in.wide[c]) continue;
    const size_t p = static_cast<size_t>(pi);
    // The daughter's own lumen: linePoints points that are not wide.
    std::vector<size_t> line{c};
    for (size_t k = c; line.size() < linePoints && in.children[k].size() == 1;) {
      k = static_cast<size_t>(in.children[k][0]);
      if (in.wide[k]) break;
      line.push_back(k);
    }
    if (line.size() < linePoints) continue;
    const Vec3 G = q[c], d = q[line.back()] - G;
    if (d.norm() < in.spacing.minCoeff()) continue;
    Vec3 J(0, 0, 0);
    const double trunkMm = trunkRadius(p);
    const bool okJ = trunkJunction(in, G, d.normalized(), trunkMm, in.sectionLevel[p], sc, J);
    if (std::getenv("VS_WIDE_DEBUG"))
      std::fprintf(stderr, "exit %zu -> %zu, G %.1f %.1f %.1f, J ok %d %.1f %.1f %.1f, trunk r %.1f\n", p, c, G[0],
                   G[1], G[2], okJ, J[0], J[1], J[2], trunkMm);
    if (!okJ) continue;
    // The chain's own points, root side first: from p up to (not past) the last branch point.
    std::vector<size_t> chain;
    for (size_t k = p; k != 0 && in.children[k].size() == 1;) {
      chain.push_back(k);
      k = static_cast<size_t>(in.parent[k]);
    }
    if (chain.empty()) continue;
    std::reverse(chain.begin(), chain.end());
    for (size_t k : chain)
      if (!moved[k]) ball(k, trunkMm, in.sectionLevel[p], sc);
    size_t near = 0;
    for (size_t i = 1; i < chain.size(); ++i)
      if ((target[chain[i]] - J).norm() < (target[chain[near]] - J).norm()) near = i;
    const size_t m = chain.size() - near - 1;
    for (size_t j = 0; j < m; ++j) {
      target[chain[near + 1 + j]] = J + (static_cast<double>(j + 1) / static_cast<double>(m + 1)) * (G - J);
      moved[chain[near + 1 + j]] = 1;
    }
  }
  size_t count = 0;
  if (std::getenv("VS_WIDE_DEBUG")) {
    size_t nw = 0, nm = 0;
    for (size_t k = 0; k < n; ++k) nw += in.wide[k], nm += moved[k];
    std::fprintf(stderr, "wide: %zu points, %zu wide, %zu moved\n", n, nw, nm);
  }
  for (size_t k = 1; k < n; ++k)
    if (moved[k]) q[k] = target[k], frozen[k] = 1, placed[k] = 1, ++count;
  return count;
}

}  // namespace vs::centreline_detail
