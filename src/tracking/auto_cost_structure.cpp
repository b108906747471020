// The root's connected lumen and its structure for the auto cost's local background (see auto_cost.h): one
// minimax flood from the root gives both (the structure is the flood continued past the window), and the
// structure's wall, deep part and wide-lumen zone are grown from its voxel list, never by full-volume passes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

namespace {
// The 26-neighbours of voxel i inside the volume (linear offsets away from the faces, clamped at them).
struct Neighbours {
  const Geometry& g;
  int64_t offset[26];
  explicit Neighbours(const Geometry& geo) : g(geo) {
    int k = 0;
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx)
          if (dx || dy || dz) offset[k++] = g.linear(dx, dy, dz);
  }
  template <class F>
  void each(int64_t i, F&& fn) const {
    const int64_t x = i % g.dims[0], y = (i / g.dims[0]) % g.dims[1], z = i / (g.dims[0] * g.dims[1]);
    if (x > 0 && y > 0 && z > 0 && x < g.dims[0] - 1 && y < g.dims[1] - 1 && z < g.dims[2] - 1) {
      for (const int64_t o : offset) fn(i + o);
      return;
    }
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx)
          if ((dx || dy || dz) && x + dx >= 0 && y + dy >= 0 && z + dz >= 0 && x + dx < g.dims[0] &&
              y + dy < g.dims[1] && z + dz < g.dims[2])
            fn(g.linear(x + dx, y + dy, z + dz));
  }
};

// The minimax flood's result: the level per voxel and the voxels in the order they were settled
// (those of levels <= k are the first settledBy[k]).
struct Flood {
  std::vector<uint8_t> level;
  std::vector<int64_t> order;
  std::vector<size_t> settledBy;
  int windowStop = 0;     // the window's last step (cut back at a spill)
  int structureStop = 0;  // the structure's last step (>= windowStop)
};

// Steps of h from L: 0 on the lumen's side of L, `never` beyond `lastStep` (255: not reached).
// `upper` (upperShell): voxels the upper edge tests as beyond its far end whatever their own value (nullptr: none).
// A voxel's level is max(its own step, the level of the neighbour that reaches it first); buckets are settled in
// increasing steps, so once a voxel holds a level above the current step it holds its own step, which no later
// neighbour lowers: its intensity is read once, when it is first reached (the flood's time went to reading the
// intensities of the voxels around the region again and again, from each neighbour settled).
Flood flood(const VolumeF32& vol, const Index3& root, LumenEstimate& e, int steps, int lastStep, double spillGrowth,
            double spillShare, const std::vector<uint8_t>* upper) {
  const Geometry& g = vol.geometry();
  const int64_t n = g.voxelCount();
  const bool bright = e.polarity == TubePolarity::Bright;
  const double far = bright ? e.windowLo : e.windowHi;  // the window's edge away from the lumen
  const double h = std::abs(far - e.lumen) / steps;     // > 0: the contrast exceeds the noise
  const auto kEnd = static_cast<uint8_t>(lastStep), none = static_cast<uint8_t>(255), never = static_cast<uint8_t>(254);
  const bool up = e.hasUpperEdge();
  const uint8_t* shell = up && upper ? upper->data() : nullptr;
  auto stepOf = [&](int64_t i) -> uint8_t {
    const float v = vol.data()[i];
    // Not next to values beyond the upper edge's far end (bone, metal and their partial-volume shell).
    if (up && ((shell && shell[i]) || (bright ? v > e.upperHi : v < e.upperHi))) return none;
    const double d = bright ? e.lumen - v : v - e.lumen;
    if (!(d > 0)) return d <= 0 ? 0 : none;  // NaN: never
    const double k = std::ceil(d / h);
    return k > lastStep ? none : static_cast<uint8_t>(k);
  };
  Flood f;
  f.level.assign(static_cast<size_t>(n), none);
  f.settledBy.assign(static_cast<size_t>(lastStep) + 1, 0);
  std::vector<std::vector<int64_t>> bucket(static_cast<size_t>(lastStep) + 1);
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx) {
        const int64_t x = root[0] + dx, y = root[1] + dy, z = root[2] + dz;
        if (!g.contains({x, y, z})) continue;
        const int64_t i = g.linear(x, y, z);
        const uint8_t k = stepOf(i);
        if (k <= kEnd && k < f.level[static_cast<size_t>(i)]) {
          f.level[static_cast<size_t>(i)] = k;
          bucket[k].push_back(i);
        }
      }
  const double noiseSteps = 3 * e.spread / h;  // steps within 3 noise spreads of L are the lumen itself
  const Neighbours nb(g);
  // The structure's spill test compares the region with the one structureStride steps before (the
  // structure's own steps: its range cut into `steps`, as the window's).
  const int stride = std::max(1, static_cast<int>(std::lround(static_cast<double>(lastStep) / steps)));
  f.windowStop = steps;
  f.structureStop = lastStep;
  for (int k = 0; k <= lastStep; ++k) {
    std::vector<int64_t>& q = bucket[static_cast<size_t>(k)];
    for (size_t head = 0; head < q.size(); ++head) {  // q grows while it is read
      const int64_t i = q[head];
      if (f.level[static_cast<size_t>(i)] != k) continue;  // reached at a lower step since
      f.order.push_back(i);
      nb.each(i, [&](int64_t j) {
        uint8_t& lj = f.level[static_cast<size_t>(j)];
        if (lj != none) return;  // settled, waiting in a bucket at its own step, or never
        const uint8_t s = std::max(static_cast<uint8_t>(k), stepOf(j));
        if (s > kEnd) {
          lj = never;
          return;
        }
        lj = s;
        bucket[s].push_back(j);
      });
    }
    q.clear();
    q.shrink_to_fit();
    const size_t total = f.order.size();
    f.settledBy[static_cast<size_t>(k)] = total;
    if (std::getenv("VS_CONNECT_DEBUG"))
      std::fprintf(stderr, "connect step %d (%.6g): %zu voxels\n", k, bright ? e.lumen - k * h : e.lumen + k * h,
                   total);
    // A spill: the region (the voxels of steps <= k) grows past spillGrowth x and the share of the
    // volume in one step, beyond the lumen's own noise: the window ends at the step before. Past the
    // window (the structure) the same over the structure's own step.
    const int back = k <= steps ? 1 : stride;
    const size_t before = k >= back ? f.settledBy[static_cast<size_t>(k - back)] : 0;
    if (k >= 2 && k > noiseSteps && static_cast<double>(total) > spillGrowth * static_cast<double>(before) &&
        static_cast<double>(total) > spillShare * static_cast<double>(n)) {
      if (std::getenv("VS_CONNECT_DEBUG")) std::fprintf(stderr, "connect spill at step %d\n", k);
      if (k <= steps) {
        f.windowStop = std::max(1, k - 1);
        f.structureStop = f.windowStop;  // the structure is the window's region then
        e.spillVoxels = static_cast<int64_t>(total);
      } else {
        f.structureStop = std::max(steps, k - back);
      }
      break;
    }
  }
  return f;
}

// Grows `mask` (value `mark` where it was 0) by `layers` 26-neighbour layers (a cube) from `front`;
// returns the number of voxels added.
size_t grow(const Geometry& g, std::vector<uint8_t>& mask, std::vector<int64_t> front, int layers, uint8_t mark) {
  std::vector<int64_t> next;
  size_t added = 0;
  const Neighbours nb(g);
  for (int l = 0; l < layers && !front.empty(); ++l) {
    next.clear();
    for (const int64_t i : front)
      nb.each(i, [&](int64_t j) {
        if (mask[static_cast<size_t>(j)] == 0) {
          mask[static_cast<size_t>(j)] = mark;
          next.push_back(j);
        }
      });
    added += next.size();
    front.swap(next);
  }
  return added;
}

// The structure's voxels (value 2 in `mask`) with a cube of radius `voxels` inside it (the volume's
// outside counts as inside) become 3; returned as a list. Separable along the axes, on the voxel list.
std::vector<int64_t> markDeep(const Geometry& g, std::vector<uint8_t>& mask, const std::vector<int64_t>& in,
                              int voxels) {
  std::vector<int64_t> deep;
  if (voxels <= 0) {
    for (const int64_t i : in) mask[static_cast<size_t>(i)] = 3;
    return in;
  }
  const uint8_t need[3] = {2, 0x10, 0x20}, set[3] = {0x10, 0x20, 0x40};
  for (int a = 0; a < 3; ++a) {
    const int64_t stride = a == 0 ? 1 : a == 1 ? g.dims[0] : g.dims[0] * g.dims[1];
    for (const int64_t i : in) {
      uint8_t& m = mask[static_cast<size_t>(i)];
      if (!(m & need[a])) continue;
      const int64_t p = g.unlinear(i)[static_cast<size_t>(a)];
      bool ok = true;
      for (int64_t d = -voxels; d <= voxels && ok; ++d)
        ok = p + d < 0 || p + d >= g.dims[a] || (mask[static_cast<size_t>(i + d * stride)] & need[a]);
      if (ok) m |= set[a];
    }
  }
  for (const int64_t i : in) {
    uint8_t& m = mask[static_cast<size_t>(i)];
    const bool isDeep = m & 0x40;
    m = isDeep ? 3 : 2;
    if (isDeep) deep.push_back(i);
  }
  return deep;
}

// The root's window region (`front`) and the voxels within `layers` 26-neighbour layers of it: 2 in `zone` where it
// is 0, `near` is 1 (within reach of the wide lumen's deep part) and `core` is not 3 (the deep part's core).
void markWindowWall(const Geometry& g, std::vector<uint8_t>& zone, const std::vector<uint8_t>& near,
                    const std::vector<uint8_t>& core, std::vector<int64_t> front, int layers) {
  const auto take = [&](int64_t j) {
    const auto k = static_cast<size_t>(j);
    if (zone[k] != 0 || near[k] != 1 || core[k] == 3) return false;
    zone[k] = 2;
    return true;
  };
  for (const int64_t i : front) take(i);
  std::vector<int64_t> next;
  const Neighbours nb(g);
  for (int l = 0; l < layers && !front.empty(); ++l) {
    next.clear();
    for (const int64_t i : front)
      nb.each(i, [&](int64_t j) {
        if (take(j)) next.push_back(j);
      });
    front.swap(next);
  }
}
}  // namespace

std::vector<uint8_t> connectRootLumen(const VolumeF32& vol, const Index3& root, LumenEstimate& e, int steps,
                                      double spillGrowth, double spillShare) {
  AutoCostOptions o;
  o.connectSteps = steps;
  o.spillGrowth = spillGrowth;
  o.spillShare = spillShare;
  o.structureFraction = 0;
  return connectRootLumen(vol, root, e, o, nullptr);
}

std::vector<uint8_t> connectRootLumen(const VolumeF32& vol, const Index3& root, LumenEstimate& e,
                                      const AutoCostOptions& o, RootStructure* structure,
                                      const std::vector<uint8_t>* upper) {
  const Geometry& g = vol.geometry();
  const int64_t n = g.voxelCount();
  const int steps = o.connectSteps;
  VS_REQUIRE(steps >= 0 && steps <= 250, "auto cost: connect steps in [0,250]");
  VS_REQUIRE(o.spillGrowth > 1 && std::isfinite(o.spillGrowth), "auto cost: spill growth must be > 1");
  VS_REQUIRE(o.spillShare >= 0 && o.spillShare <= 1, "auto cost: spill share in [0,1]");
  VS_REQUIRE(g.contains(root), "auto cost: the root is outside the volume");
  VS_REQUIRE(o.structureFraction >= 0 && o.structureFraction <= 1, "auto cost: structure fraction in [0,1]");
  VS_REQUIRE(o.structureWall >= 0 && o.structureWall <= 8, "auto cost: structure wall in [0,8] voxels");
  VS_REQUIRE(o.structureDepth >= 0 && o.structureDepth <= 16, "auto cost: structure depth in [0,16] voxels");
  VS_REQUIRE(o.wideWallVoxels >= 0 && o.wideWallVoxels <= 16, "auto cost: wide wall in [0,16] voxels");
  e.connectSteps = steps;
  e.spillVoxels = 0;
  e.structureFraction = 0;
  e.structureVoxels = 0;
  if (structure) *structure = RootStructure{};
  if (steps == 0) {
    e.connectedVoxels = n;
    return std::vector<uint8_t>(static_cast<size_t>(n), 1);
  }
  const bool bright = e.polarity == TubePolarity::Bright;
  const double far = bright ? e.windowLo : e.windowHi;
  const double h = std::abs(far - e.lumen) / steps;
  // The structure's edge: structureFraction of the way from L towards the farther of B and the shell's
  // median (B is the most lumen-like material of the shell, which in a lumen fading along its length is
  // the lumen itself a little farther on), never nearer to L than the window's; in steps of the window's.
  int lastStep = steps;
  const bool withStructure = structure && o.structureFraction > 0;
  if (withStructure) {
    const double tissue =
        std::abs(e.shellMedian - e.lumen) > std::abs(e.surround - e.lumen) ? e.shellMedian : e.surround;
    const double reach = o.structureFraction * std::abs(tissue - e.lumen);
    lastStep = std::clamp(static_cast<int>(std::ceil(reach / h - 1e-9)), steps, 250);
  }
  Flood f = flood(vol, root, e, steps, lastStep, o.spillGrowth, o.spillShare, upper);
  const int stop = f.windowStop;
  if (stop < steps) {
    e.spillFrom = far;
    (bright ? e.windowLo : e.windowHi) = bright ? e.lumen - stop * h : e.lumen + stop * h;
  }
  e.connectedVoxels = static_cast<int64_t>(f.settledBy[static_cast<size_t>(stop)]);
  // The connected lumen (1) and the structure's voxels (2 in its mask), from the levels in one pass.
  std::vector<uint8_t> in = std::move(f.level);
  if (withStructure) structure->mask.resize(static_cast<size_t>(n));
  uint8_t* mask = withStructure ? structure->mask.data() : nullptr;
  const auto structureStop = static_cast<uint8_t>(f.structureStop), windowStop = static_cast<uint8_t>(stop);
  for (size_t i = 0; i < in.size(); ++i) {
    if (mask) mask[i] = in[i] <= structureStop ? 2 : 0;
    in[i] = in[i] <= windowStop ? 1 : 0;
  }
  if (!withStructure) return in;
  // The structure: the flood's voxels up to its stop (2), its wall (1), its deep part (3).
  RootStructure& s = *structure;
  const std::vector<int64_t> region(
      f.order.begin(),
      f.order.begin() + static_cast<std::ptrdiff_t>(f.settledBy[static_cast<size_t>(f.structureStop)]));
  const size_t wall = grow(g, s.mask, region, o.structureWall, 1);
  s.deep = markDeep(g, s.mask, region, o.structureDepth);
  if (!s.deep.empty()) {
    // Beside a wide lumen: the voxels within structureDepth + wideWallVoxels of the deep part (1: the wall test by
    // half-maximum), and among them the root's window region and its wall (2; the root's window model, s_root,
    // centres paths there and its partial-volume wall is measured against the window's far edge), but not the deep
    // part's core (wideWallVoxels deeper): a lumen voxel deeper than the wall (a wide lumen fading past the window's
    // far edge along its length) is not measured against the window's far edge, nor is a voxel farther from the
    // deep part (a daughter leaving the wide lumen).
    s.wideZone.assign(static_cast<size_t>(n), 0);
    const int reach = o.structureDepth + o.wideWallVoxels;
    std::vector<uint8_t> near(static_cast<size_t>(n), 0), core(static_cast<size_t>(n), 0);
    for (const int64_t i : s.deep) near[static_cast<size_t>(i)] = 1;
    grow(g, near, s.deep, reach, 1);
    for (const int64_t i : s.deep) core[static_cast<size_t>(i)] = 2;
    markDeep(g, core, s.deep, o.wideWallVoxels);  // the core: 3
    markWindowWall(g, s.wideZone, near, core,
                   std::vector<int64_t>(f.order.begin(), f.order.begin() + static_cast<std::ptrdiff_t>(
                                                                               f.settledBy[static_cast<size_t>(stop)])),
                   o.wideWallVoxels);
    std::vector<int64_t> beyond;
    for (const int64_t i : s.deep)
      if (!s.wideZone[static_cast<size_t>(i)]) {
        s.wideZone[static_cast<size_t>(i)] = 1;
        beyond.push_back(i);
      }
    grow(g, s.wideZone, beyond, reach, 1);
  }
  e.structureFraction = o.structureFraction;
  e.structureEdge = bright ? e.lumen - f.structureStop * h : e.lumen + f.structureStop * h;
  e.structureWall = o.structureWall;
  e.structureDepth = o.structureDepth;
  e.wideWallVoxels = o.wideWallVoxels;
  e.structureVoxels = static_cast<int64_t>(region.size() + wall);
  return in;
}

// Per block 1 where it holds, or touches a block that holds, a voxel of `deep` (beside a wide lumen).
std::vector<uint8_t> nearDeepBlocks(const BlockGrid& bg, const Geometry& g, const std::vector<int64_t>& deep) {
  const int64_t nb = bg.blocks[0] * bg.blocks[1] * bg.blocks[2];
  std::vector<uint8_t> deepBlock(static_cast<size_t>(nb)), nearDeep(static_cast<size_t>(nb));
  for (const int64_t i : deep) {
    const Index3 p = g.unlinear(i);
    deepBlock[static_cast<size_t>(((p[2] / bg.blockVoxels[2]) * bg.blocks[1] + p[1] / bg.blockVoxels[1]) *
                                      bg.blocks[0] +
                                  p[0] / bg.blockVoxels[0])] = 1;
  }
  for (int64_t k = 0; k < bg.blocks[2]; ++k)
    for (int64_t j = 0; j < bg.blocks[1]; ++j)
      for (int64_t i = 0; i < bg.blocks[0]; ++i) {
        if (!deepBlock[static_cast<size_t>((k * bg.blocks[1] + j) * bg.blocks[0] + i)]) continue;
        for (int64_t c = std::max<int64_t>(0, k - 1); c <= std::min(bg.blocks[2] - 1, k + 1); ++c)
          for (int64_t b = std::max<int64_t>(0, j - 1); b <= std::min(bg.blocks[1] - 1, j + 1); ++b)
            for (int64_t a = std::max<int64_t>(0, i - 1); a <= std::min(bg.blocks[0] - 1, i + 1); ++a)
              nearDeep[static_cast<size_t>((c * bg.blocks[1] + b) * bg.blocks[0] + a)] = 1;
      }
  return nearDeep;
}

// The wide lumen's level per block: its own where it has one, else the median of its 26 neighbours' (NaN: none).
std::vector<float> levelFilter(const BlockGrid& bg, const std::vector<float>& raw) {
  std::vector<float> out(raw), near;
  for (int64_t k = 0; k < bg.blocks[2]; ++k)
    for (int64_t j = 0; j < bg.blocks[1]; ++j)
      for (int64_t i = 0; i < bg.blocks[0]; ++i) {
        const size_t at = static_cast<size_t>((k * bg.blocks[1] + j) * bg.blocks[0] + i);
        if (!std::isnan(raw[at])) continue;
        near.clear();
        for (int64_t c = std::max<int64_t>(0, k - 1); c <= std::min(bg.blocks[2] - 1, k + 1); ++c)
          for (int64_t b = std::max<int64_t>(0, j - 1); b <= std::min(bg.blocks[1] - 1, j + 1); ++b)
            for (int64_t a = std::max<int64_t>(0, i - 1); a <= std::min(bg.blocks[0] - 1, i + 1); ++a)
              if (const float v = raw[static_cast<size_t>((c * bg.blocks[1] + b) * bg.blocks[0] + a)]; !std::isnan(v))
                near.push_back(v);
        if (near.empty()) continue;
        const auto m = near.begin() + static_cast<std::ptrdiff_t>(near.size() / 2);
        std::nth_element(near.begin(), m, near.end());
        out[at] = *m;
      }
  return out;
}

void markDiffers(BlockGrid& f, const BlockGrid& now) {
  // Where no block within one of a voxel's own differs, the two backgrounds are the same there.
  f.differs.assign(f.value.size(), 0);
  for (int64_t c = 0; c < f.blocks[2]; ++c)
    for (int64_t b = 0; b < f.blocks[1]; ++b)
      for (int64_t a = 0; a < f.blocks[0]; ++a) {
        if (f.value[static_cast<size_t>((c * f.blocks[1] + b) * f.blocks[0] + a)] ==
            now.value[static_cast<size_t>((c * f.blocks[1] + b) * f.blocks[0] + a)])
          continue;
        for (int64_t kk = std::max<int64_t>(0, c - 1); kk <= std::min(f.blocks[2] - 1, c + 1); ++kk)
          for (int64_t jj = std::max<int64_t>(0, b - 1); jj <= std::min(f.blocks[1] - 1, b + 1); ++jj)
            for (int64_t ii = std::max<int64_t>(0, a - 1); ii <= std::min(f.blocks[0] - 1, a + 1); ++ii)
              f.differs[static_cast<size_t>((kk * f.blocks[1] + jj) * f.blocks[0] + ii)] = 1;
      }
}

}  // namespace vs
