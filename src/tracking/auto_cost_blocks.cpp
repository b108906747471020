// A block's samples for the local background and their percentiles (auto_cost.h: sampleBlock, blockPercentile,
// capAtBackgroundTail).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

void sampleBlock(const VolumeF32& vol, const int64_t lo[3], const int64_t blockVoxels[3], const int64_t step[3],
                 bool bright, float edge, const float* up, float hiUp, const uint8_t* bm, BlockSamples& s) {
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
        const bool keep = (bright ? v < edge : v > edge) && !(up && (bright ? up[i] > hiUp : up[i] < hiUp));
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

// The percentile-th of `vals` counted as `p` (bright: 100 - percentile), or NaN with fewer than
// min(8, half the block's samples) values (a block of lumen).
float blockPercentile(std::vector<float>& vals, size_t sampled, double p) {
  if (vals.empty() || vals.size() < std::min<size_t>(8, (sampled + 1) / 2))
    return std::numeric_limits<float>::quiet_NaN();
  const auto k = static_cast<std::ptrdiff_t>(std::lround(p / 100.0 * static_cast<double>(vals.size() - 1)));
  std::nth_element(vals.begin(), vals.begin() + k, vals.end());
  return vals[static_cast<size_t>(k)];
}

// The block's value r (its percentile p counted as in blockPercentile) no farther towards the lumen than its
// background side's quartile q (the percentile counted from the other side) plus the larger of k times q's distance
// to the tail (the percentile / 5 from that side) and `floorWidth` (k root noise spreads: a flat or quantised tail).
// Gaussian noise: r lies 1.35 noise spreads beyond q, the cap 4.8 (k 5): no change; only where lumen fills the block
// beyond the percentile.
void capAtBackgroundTail(std::vector<float>& vals, size_t sampled, double p, double percentile, bool bright,
                         double floorWidth, double k, float& r) {
  if (std::isnan(r) || vals.size() < 8) return;
  const float q = blockPercentile(vals, sampled, 100.0 - p);
  const float tail = blockPercentile(vals, sampled, bright ? percentile / 5 : 100.0 - percentile / 5);
  if (std::isnan(q) || std::isnan(tail)) return;
  const double width = std::max(k * std::abs(double(q) - double(tail)), floorWidth);
  const float cap = static_cast<float>(bright ? q + width : q - width);
  if (bright ? r > cap : r < cap) r = cap;
}

}  // namespace vs
