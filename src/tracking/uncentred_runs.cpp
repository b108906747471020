// Runs of points no cast ever centred (session 36 contact36), put on the line between their chain's centred points.
// See centreline_junctions.h (lineUncentred).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

size_t lineUncentred(const JunctionInput& in, const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& cast,
                     const CentrelineOptions& o, const Vec3& spacing, std::vector<Vec3>& q,
                     std::vector<double>& radiusOut) {
  if (!in.raw || o.iterations <= 0 || !(o.lobeForkRadii > 0)) return 0;
  const size_t n = q.size();
  const bool debug = std::getenv("VS_UNCENTRED_DEBUG") != nullptr;
  const auto plain = [&](size_t k) { return k > 0 && !frozen[k] && in.children[k].size() == 1; };
  const auto uncentred = [&](size_t k) { return plain(k) && cast[k] == 1; };
  // A run's end: a plain chain point (no branch point, no end, not placed) that its own casts centred.
  const auto centred = [&](size_t k) { return plain(k) && cast[k] == 2; };
  std::vector<uint8_t> seen(n, 0);
  std::vector<size_t> run;
  size_t moved = 0;
  for (size_t k = 1; k < n; ++k) {
    if (seen[k] || !uncentred(k)) continue;
    size_t first = k, last = k;
    while (in.parent[first] > 0 && uncentred(static_cast<size_t>(in.parent[first])))
      first = static_cast<size_t>(in.parent[first]);
    while (uncentred(static_cast<size_t>(in.children[last][0]))) last = static_cast<size_t>(in.children[last][0]);
    run.clear();
    for (size_t at = first;; at = static_cast<size_t>(in.children[at][0])) {
      run.push_back(at), seen[at] = 1;
      if (at == last) break;
    }
    if (in.parent[first] < 0) continue;
    const size_t a = static_cast<size_t>(in.parent[first]), b = static_cast<size_t>(in.children[last][0]);
    if (debug && (!centred(a) || !centred(b)))
      std::fprintf(stderr,
                   "[contact36] run %zu..%zu left: end %zu cast %d children %zu frozen %d, end %zu cast %d "
                   "children %zu frozen %d\n",
                   first, last, a, cast[a], in.children[a].size(), frozen[a], b, cast[b], in.children[b].size(),
                   frozen[b]);
    if (!centred(a) || !centred(b) || !(in.radius[a] > 0) || !(in.radius[b] > 0)) continue;
    // One tube either side: neither end's section a bump against the other's (fusedBumpRadii, the fused-bump rule's
    // ratio) - an end in a junction blob or a wider lumen is not the run's own axis (the head CTA's dim target 3: ends
    // 1.67 / 8.72 mm).
    const double rA = in.radius[a], rB = in.radius[b];
    if (debug && std::max(rA, rB) > o.fusedBumpRadii * std::min(rA, rB))
      std::fprintf(stderr, "[contact36] run %zu..%zu left: ends %zu %zu r %.2f %.2f unlike\n", first, last, a, b, rA,
                   rB);
    if (std::max(rA, rB) > o.fusedBumpRadii * std::min(rA, rB)) continue;
    // Along the path voxels from a to each run point and to b; every run point within lobeForkRadii x each end's
    // radius of that end (the reach over which the lumen counts as one tube going on; as the own-lobe rule's).
    std::vector<double> along(run.size());
    double total = 0;
    Vec3 prev = in.raw(a);
    for (size_t i = 0; i < run.size(); ++i)
      total += (in.raw(run[i]) - prev).norm(), along[i] = total, prev = in.raw(run[i]);
    total += (in.raw(b) - prev).norm();
    bool within = total > 0;
    for (size_t i = 0; i < run.size() && within; ++i)
      within = along[i] <= o.lobeForkRadii * in.radius[a] && total - along[i] <= o.lobeForkRadii * in.radius[b];
    if (debug)
      std::fprintf(stderr, "[contact36] run %zu..%zu (%zu) ends %zu %zu r %.2f %.2f along %.2f within %d\n", first,
                   last, run.size(), a, b, in.radius[a], in.radius[b], total, int(within));
    if (!within) continue;
    for (size_t i = 0; i < run.size(); ++i) {
      const size_t j = run[i];
      const double share = along[i] / total;
      const Vec3 line = q[a] + (q[b] - q[a]) * share;
      const double ownR = in.radius[a] + (in.radius[b] - in.radius[a]) * share;
      // The lumen test (xfit34's / kiss39's): the own axis lies within the own radius of the path voxel's cell.
      const bool inLumen = (line - in.raw(j)).norm() <= ownR + 0.5 * spacing.norm();
      if (debug)
        std::fprintf(stderr, "[contact36]   point %zu shift %.2f raw %.2f own %.2f r %.2f in %d\n", j,
                     (line - q[j]).norm(), (line - in.raw(j)).norm(), ownR, in.radius[j], int(inLumen));
      if (!inLumen) continue;
      q[j] = line, radiusOut[j] = ownR, ++moved;
    }
  }
  return moved;
}

}  // namespace vs::centreline_detail
