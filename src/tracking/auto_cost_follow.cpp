// The lumen model's upper edge following the vessel's level (auto_cost.h, FollowedEdge; docs/notes/tracking.md
// session 29 aorta9).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

namespace {
constexpr float kNoLevel = std::numeric_limits<float>::quiet_NaN();

int64_t blockOf(const BlockGrid& grid, int64_t x, int64_t y, int64_t z) {
  return x / grid.blockVoxels[0] +
         grid.blocks[0] * (y / grid.blockVoxels[1] + grid.blocks[1] * (z / grid.blockVoxels[2]));
}

float medianOf(std::vector<float> v) {
  static const double q = std::getenv("VS_FOLLOW_Q") ? std::atof(std::getenv("VS_FOLLOW_Q")) : 0.5;
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<size_t>(k)];
}
}  // namespace

double FollowedEdge::cap(const LumenEstimate& e, int64_t x, int64_t y, int64_t z, double v, bool inShell) const {
  const size_t i = static_cast<size_t>(x + dims[0] * (y + dims[1] * z));
  if (!admitted.empty() && admitted[i]) return 1.0;  // judged against the level where the flood reached it
  const float lv = level.empty() ? kNoLevel : level[static_cast<size_t>(blockOf(grid, x, y, z))];
  if (std::isnan(lv)) return inShell ? 0.0 : e.upperCap(v);
  // The root's edge re-anchored at the block's level: the same multiples of the level's contrast.
  const double dir = e.polarity == TubePolarity::Bright ? 1.0 : -1.0, a = dir * (v - e.surround);
  const double lo = lv * (1 + e.upperFraction), hi = lv * (1 + 1.5 * e.upperFraction);
  return std::clamp((a - hi) / (lo - hi), 0.0, 1.0);
}

double FollowedEdge::span(const LumenEstimate& e, int64_t x, int64_t y, int64_t z, double lo, double sp) const {
  const float lv = filled.empty() ? kNoLevel : filled[static_cast<size_t>(blockOf(grid, x, y, z))];
  const double c = std::abs(e.lumen - e.surround);
  return std::isnan(lv) || !(lv > c) ? sp : (lo + sp) * lv / c - lo;
}

std::string FollowedEdge::text() const {
  if (blocks == 0) return "";
  char buf[160];
  std::snprintf(buf, sizeof buf, ", upper edge following the lumen's level in %d blocks (%lld voxels, %d rounds)",
                blocks, static_cast<long long>(admittedVoxels), rounds);
  return buf;
}

// Rounds: per block the level (median contrast against B, a = signed distance from B towards the lumen) of the
// region's voxels there; a block whose level exceeds the root's (and rises from its neighbours' by at most
// maxRise x: a wash-in, not a step into bone) takes the root's edge re-anchored at it; the region is flooded again
// from the blocks whose edge rose, a voxel admitted when it lies between the window's far edge and the edge of its
// block (a block without a level: the edge it was reached with). Until no block's edge rises.
FollowedEdge followUpperEdge(const VolumeF32& sm, const LumenEstimate& e, std::vector<uint8_t>& connected,
                             double blockMm, const FollowOptions& o) {
  FollowedEdge out;
  const Geometry& g = sm.geometry();
  out.dims = g.dims;
  if (!e.hasUpperEdge() || e.connectSteps == 0 || o.maxRounds <= 0) return out;
  const double dir = e.polarity == TubePolarity::Bright ? 1.0 : -1.0;
  const double c = dir * (e.lumen - e.surround);
  const double aFar = dir * ((dir > 0 ? e.windowLo : e.windowHi) - e.surround);
  const double ratio = 1 + 1.5 * e.upperFraction, rootEdge = c * ratio, farShare = aFar / c;
  out.grid = blockGrid(g, blockMm);
  const BlockGrid& grid = out.grid;
  const int64_t nb = grid.blocks[0] * grid.blocks[1] * grid.blocks[2], n = g.voxelCount();
  out.level.assign(static_cast<size_t>(nb), kNoLevel);
  std::vector<std::vector<float>> vals(static_cast<size_t>(nb));
  std::vector<float> edge(static_cast<size_t>(nb), static_cast<float>(rootEdge));
  const float* v = sm.data();
  auto aOf = [&](int64_t i) { return dir * (static_cast<double>(v[i]) - e.surround); };
  for (int64_t i = 0; i < n; ++i)
    if (connected[static_cast<size_t>(i)]) {
      const Index3 p = g.unlinear(i);
      vals[static_cast<size_t>(blockOf(grid, p[0], p[1], p[2]))].push_back(static_cast<float>(aOf(i)));
    }
  out.admitted.assign(static_cast<size_t>(n), 0);
  std::vector<uint8_t> dirty(static_cast<size_t>(nb), 1);
  for (int round = 0; round < o.maxRounds; ++round) {
    // The levels of blocks whose region changed; a level counts where it exceeds the root's and rises gradually.
    std::vector<uint8_t> rose(static_cast<size_t>(nb), 0);
    const std::vector<float> before = out.level;
    bool any = false;
    for (int64_t b = 0; b < nb; ++b) {
      if (!dirty[static_cast<size_t>(b)] || vals[static_cast<size_t>(b)].size() < o.minVoxels) continue;
      const double lv = medianOf(vals[static_cast<size_t>(b)]);
      if (!(lv > c)) continue;
      const int64_t bx = b % grid.blocks[0], by = (b / grid.blocks[0]) % grid.blocks[1],
                    bz = b / (grid.blocks[0] * grid.blocks[1]);
      double nbMax = c;
      for (int64_t dz = -1; dz <= 1; ++dz)
        for (int64_t dy = -1; dy <= 1; ++dy)
          for (int64_t dx = -1; dx <= 1; ++dx) {
            const int64_t qx = bx + dx, qy = by + dy, qz = bz + dz;
            if ((dx | dy | dz) == 0 || qx < 0 || qy < 0 || qz < 0 || qx >= grid.blocks[0] || qy >= grid.blocks[1] ||
                qz >= grid.blocks[2])
              continue;
            const float q = before[static_cast<size_t>(qx + grid.blocks[0] * (qy + grid.blocks[1] * qz))];
            if (!std::isnan(q)) nbMax = std::max(nbMax, static_cast<double>(q));
          }
      const double used = std::min(lv, o.maxRise * nbMax);
      if (std::isnan(before[static_cast<size_t>(b)]) || used > before[static_cast<size_t>(b)]) {
        out.level[static_cast<size_t>(b)] = static_cast<float>(used);
        if (used * ratio > edge[static_cast<size_t>(b)] * (1 + 1e-6)) {
          edge[static_cast<size_t>(b)] = static_cast<float>(used * ratio);
          rose[static_cast<size_t>(b)] = 1;
          any = true;
        }
      }
    }
    std::fill(dirty.begin(), dirty.end(), 0);
    if (!any) break;
    ++out.rounds;
    // Seeds: the region's voxels in or beside a block whose edge rose.
    std::deque<std::pair<int64_t, float>> queue;
    for (int64_t i = 0; i < n; ++i) {
      if (!connected[static_cast<size_t>(i)]) continue;
      const Index3 p = g.unlinear(i);
      const int64_t b = blockOf(grid, p[0], p[1], p[2]);
      if (rose[static_cast<size_t>(b)]) queue.emplace_back(i, out.level[static_cast<size_t>(b)]);
    }
    while (!queue.empty()) {
      const auto [i, carried] = queue.front();
      queue.pop_front();
      const Index3 p = g.unlinear(i);
      for (int64_t dz = -1; dz <= 1; ++dz)
        for (int64_t dy = -1; dy <= 1; ++dy)
          for (int64_t dx = -1; dx <= 1; ++dx) {
            const int64_t x = p[0] + dx, y = p[1] + dy, z = p[2] + dz;
            if (x < 0 || y < 0 || z < 0 || x >= g.dims[0] || y >= g.dims[1] || z >= g.dims[2]) continue;
            const int64_t j = g.linear(x, y, z);
            if (connected[static_cast<size_t>(j)]) continue;
            const int64_t b = blockOf(grid, x, y, z);
            // The window re-anchored at the level: from its far edge's fraction of it to the edge's multiple.
            const float own =
                std::isnan(out.level[static_cast<size_t>(b)]) ? carried : out.level[static_cast<size_t>(b)];
            const double a = aOf(j);
            if (!(a >= own * farShare && a <= own * ratio)) continue;
            connected[static_cast<size_t>(j)] = 1;
            out.admitted[static_cast<size_t>(j)] = 1;
            ++out.admittedVoxels;
            vals[static_cast<size_t>(b)].push_back(static_cast<float>(a));
            dirty[static_cast<size_t>(b)] = 1;
            queue.emplace_back(j, own);
          }
    }
  }
  for (float lv : out.level) out.blocks += !std::isnan(lv);
  // The local contrast's scale everywhere: a block without the connected lumen takes the nearest block's level that
  // has it (the root's where that one's did not rise): tissue beside the bright vessel is measured on its scale.
  if (out.blocks > 0) {
    out.filled.assign(static_cast<size_t>(nb), kNoLevel);
    std::vector<int64_t> wave, next;
    for (int64_t b = 0; b < nb; ++b)
      if (vals[static_cast<size_t>(b)].size() >= o.minVoxels) {
        const float lv = out.level[static_cast<size_t>(b)];
        out.filled[static_cast<size_t>(b)] = std::isnan(lv) ? static_cast<float>(c) : lv;
        wave.push_back(b);
      }
    while (!wave.empty()) {
      next.clear();
      for (int64_t b : wave) {
        const int64_t bx = b % grid.blocks[0], by = (b / grid.blocks[0]) % grid.blocks[1],
                      bz = b / (grid.blocks[0] * grid.blocks[1]);
        for (int64_t dz = -1; dz <= 1; ++dz)
          for (int64_t dy = -1; dy <= 1; ++dy)
            for (int64_t dx = -1; dx <= 1; ++dx) {
              const int64_t qx = bx + dx, qy = by + dy, qz = bz + dz;
              if (qx < 0 || qy < 0 || qz < 0 || qx >= grid.blocks[0] || qy >= grid.blocks[1] || qz >= grid.blocks[2])
                continue;
              const auto q = static_cast<size_t>(qx + grid.blocks[0] * (qy + grid.blocks[1] * qz));
              if (!std::isnan(out.filled[q])) continue;
              out.filled[q] = out.filled[static_cast<size_t>(b)];
              next.push_back(static_cast<int64_t>(q));
            }
      }
      wave.swap(next);
    }
  }
  if (const char* dbg = std::getenv("VS_FOLLOW_DUMP")) {  // DEBUG, not for commit
    FILE* f = std::fopen(dbg, "wb");
    std::fwrite(out.admitted.data(), 1, out.admitted.size(), f);
    std::fclose(f);
    std::string lp = std::string(dbg) + ".lv";
    f = std::fopen(lp.c_str(), "wb");
    std::fwrite(out.level.data(), 4, out.level.size(), f);
    std::fclose(f);
  }
  if (out.admittedVoxels == 0) out.admitted.clear();
  return out;
}

}  // namespace vs
