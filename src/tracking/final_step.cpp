// The refinement's final centring step where the rounds were swinging (session 36 kiss36). See centreline_junctions.h.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

void RoundSteps::begin(const std::vector<Vec3>& q) {
  before = q;
  last.resize(q.size(), Vec3::Zero());
  reversed.resize(q.size(), 0);
}

void RoundSteps::end(const std::vector<Vec3>& q) {
  for (size_t k = 0; k < q.size() && k < before.size(); ++k) {
    const Vec3 step = q[k] - before[k];
    reversed[k] = step.dot(last[k]) < 0;
    last[k] = step;
  }
}

void RoundSteps::copy(size_t k) {
  if (k >= last.size()) return;
  last.push_back(last[k]);
  reversed.push_back(reversed[k]);
}

size_t holdReversedSteps(const JunctionInput& in, const CentrelineOptions& o, const RoundSteps& rounds,
                         const std::vector<Vec3>& rested, const std::vector<Vec3>& stepped, std::vector<Vec3>& q) {
  const size_t n = std::min({q.size(), rounds.reversed.size(), rested.size(), stepped.size(), in.radius.size()});
  if (!in.raw || !(o.lobeForkRadii > 0)) return 0;
  const bool debug = std::getenv("VS_KISS36_DEBUG") != nullptr;
  std::vector<size_t> upK, upJ;
  size_t held = 0;
  for (size_t k = 1; k < n; ++k) {
    const Vec3 step = stepped[k] - rested[k];
    if (!rounds.reversed[k] || !(q[k] == stepped[k]) || !(step.dot(rounds.last[k]) > 0)) continue;
    bool towards = false;
    for (size_t j = 0; j < n && !towards; ++j) {
      const Vec3 voxel = in.raw(j);
      if (j == k || !((voxel - rested[k]).norm() <= in.radius[k] + in.radius[j]) ||
          !((voxel - stepped[k]).norm() < (voxel - rested[k]).norm()))
        continue;
      towards = !withinForkReach(in, o, k, j, upK, upJ);
    }
    if (!towards) continue;
    if (debug)
      std::fprintf(stderr, "[kiss36] hold %zu: step %.2f mm back to %.2f %.2f %.2f\n", k, step.norm(), rested[k][0],
                   rested[k][1], rested[k][2]);
    q[k] = rested[k], ++held;
  }
  return held;
}

}  // namespace vs::centreline_detail
