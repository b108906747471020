// A block's samples for the local background (auto_cost.h: sampleBlock).
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

void sampleBlock(const VolumeF32& vol, const int64_t lo[3], const int64_t blockVoxels[3], const int64_t step[3],
                 bool bright, float edge, const uint8_t* up, float hiUp, const uint8_t* bm, BlockSamples& s) {
  const Geometry& g = vol.geometry();
  int64_t hi[3], count[3];
  for (int a = 0; a < 3; ++a) {
    hi[a] = std::min(g.dims[a], lo[a] + blockVoxels[a]);
    count[a] = (hi[a] - lo[a] + step[a] - 1) / step[a];
  }
  const auto cap = static_cast<size_t>(count[0] * count[1] * count[2]);
  s.vals.resize(cap);
  s.diffs.resize(cap);
  s.valIn.resize(bm ? cap : 0);
  s.diffIn.resize(bm ? cap : 0);
  s.deepVals.clear();
  s.sampled = cap;
  s.inStructure = 0;
  const float* data = vol.data();
  size_t nv = 0, nd = 0;
  for (int64_t z = lo[2]; z < hi[2]; z += step[2]) {
    // A block's row is a line or two, the next sampled row often another page: the slab's rows are
    // asked for at once (their misses overlap).
    for (int64_t y = lo[1]; y < hi[1]; y += step[1]) {
      const int64_t i = g.linear(lo[0], y, z);
      __builtin_prefetch(data + i);
      __builtin_prefetch(data + g.linear(hi[0] - 1, y, z));
      if (up) __builtin_prefetch(up + i);
      if (bm) __builtin_prefetch(bm + i);
    }
    for (int64_t y = lo[1]; y < hi[1]; y += step[1]) {
      const int64_t row = g.linear(0, y, z);
      for (int64_t x = lo[0]; x < hi[0]; x += step[0]) {
        const int64_t i = row + x;
        const bool hasNext = x + 1 < g.dims[0];
        const int64_t j = hasNext ? i + 1 : i;
        const float v = data[i], w = data[j];
        // Bone or metal and their shell (beyond the upper edge) are no background either.
        const bool keep = (bright ? v < edge : v > edge) && !(up && (up[i] || (bright ? v > hiUp : v < hiUp)));
        // Neighbour differences: noise and texture (lung parenchyma), not the block's slow trends or
        // its few edges (the median of them).
        const bool pair = keep && hasNext && (bright ? w < edge : w > edge);
        s.vals[nv] = v;
        s.diffs[nd] = std::abs(w - v);
        if (bm) {
          const uint8_t m = bm[i];
          s.inStructure += m >= 2;
          if (m == 3) s.deepVals.push_back(v);
          s.valIn[nv] = m != 0;
          s.diffIn[nd] = m != 0 || bm[j] != 0;
        }
        nv += keep;
        nd += pair;
      }
    }
  }
  s.vals.resize(nv);
  s.diffs.resize(nd);
  if (bm) s.valIn.resize(nv);
  if (bm) s.diffIn.resize(nd);
}

}  // namespace vs
