// The root's structure for the auto cost's local background (see auto_cost.h): a second flood of the
// connected lumen, its wall and its deep part, and the zone of a wide lumen around that deep part.
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/auto_cost.h"
#include "util/parallel.h"

namespace vs {

namespace {
// `mask` grown by `voxels` voxels (26-neighbours: a cube, one axis at a time).
void dilate(const Geometry& g, std::vector<uint8_t>& mask, int voxels) {
  if (voxels <= 0) return;
  std::vector<uint8_t> out(mask.size());
  for (int a = 0; a < 3; ++a) {
    const int64_t stride = a == 0 ? 1 : a == 1 ? g.dims[0] : g.dims[0] * g.dims[1];
    parallelFor(
        0, g.voxelCount(),
        [&](int64_t i0, int64_t i1) {
          for (int64_t i = i0; i < i1; ++i) {
            const int64_t p = (i / stride) % g.dims[a];
            uint8_t m = mask[static_cast<size_t>(i)];  // 2 (the structure) stays 2, the wall grown is 1
            for (int64_t d = std::max<int64_t>(-voxels, -p); d <= std::min<int64_t>(voxels, g.dims[a] - 1 - p) && !m;
                 ++d)
              m = mask[static_cast<size_t>(i + d * stride)] ? 1 : 0;
            out[static_cast<size_t>(i)] = m;
          }
        },
        1 << 16);
    mask.swap(out);
  }
}

// The voxels of `mask`'s structure (2) at least `voxels` deep in it (a cube of that radius inside it) become 3.
void markDeep(const Geometry& g, std::vector<uint8_t>& mask, int voxels) {
  std::vector<uint8_t> deep(mask.size()), out(mask.size());
  for (size_t i = 0; i < mask.size(); ++i) deep[i] = mask[i] == 2;
  for (int a = 0; a < 3 && voxels > 0; ++a) {
    const int64_t stride = a == 0 ? 1 : a == 1 ? g.dims[0] : g.dims[0] * g.dims[1];
    parallelFor(
        0, g.voxelCount(),
        [&](int64_t i0, int64_t i1) {
          for (int64_t i = i0; i < i1; ++i) {
            const int64_t p = (i / stride) % g.dims[a];
            uint8_t m = deep[static_cast<size_t>(i)];
            for (int64_t d = -voxels; d <= voxels && m; ++d)
              m = p + d >= 0 && p + d < g.dims[a] ? deep[static_cast<size_t>(i + d * stride)] : 1;
            out[static_cast<size_t>(i)] = m;
          }
        },
        1 << 16);
    deep.swap(out);
  }
  for (size_t i = 0; i < mask.size(); ++i)
    if (deep[i]) mask[i] = 3;
}
}  // namespace

std::vector<uint8_t> rootStructure(const VolumeF32& smoothed, const Index3& root, LumenEstimate& e,
                                   const std::vector<uint8_t>& connected, const AutoCostOptions& o) {
  VS_REQUIRE(o.structureFraction >= 0 && o.structureFraction <= 1, "auto cost: structure fraction in [0,1]");
  VS_REQUIRE(o.structureWall >= 0 && o.structureWall <= 8, "auto cost: structure wall in [0,8] voxels");
  VS_REQUIRE(o.structureDepth >= 0 && o.structureDepth <= 16, "auto cost: structure depth in [0,16] voxels");
  VS_REQUIRE(o.wideWallVoxels >= 0 && o.wideWallVoxels <= 16, "auto cost: wide wall in [0,16] voxels");
  e.structureFraction = 0;
  e.structureVoxels = 0;
  if (o.structureFraction <= 0 || o.connectSteps == 0) return {};
  const bool bright = e.polarity == TubePolarity::Bright;
  // The flood of the connected lumen with the window's far edge moved to the structure's edge (never
  // nearer to L than the window's own), cut back at a spill as the window is.
  LumenEstimate s = e;
  // Towards the farther of B and the shell's median: B is the most lumen-like material of the shell,
  // which in a lumen fading along its length is the lumen itself a little farther on.
  const double tissue = std::abs(e.shellMedian - e.lumen) > std::abs(e.surround - e.lumen) ? e.shellMedian : e.surround;
  const double edge = e.lumen + o.structureFraction * (tissue - e.lumen);
  double& far = bright ? s.windowLo : s.windowHi;
  far = bright ? std::min(far, edge) : std::max(far, edge);
  std::vector<uint8_t> mask = connectRootLumen(smoothed, root, s, o.connectSteps, o.spillGrowth, o.spillShare);
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = (mask[i] || connected[i]) ? 2 : 0;
  dilate(smoothed.geometry(), mask, o.structureWall);
  markDeep(smoothed.geometry(), mask, o.structureDepth);
  e.structureFraction = o.structureFraction;
  e.structureEdge = far;
  e.structureWall = o.structureWall;
  e.structureDepth = o.structureDepth;
  e.wideWallVoxels = o.wideWallVoxels;
  for (const uint8_t m : mask) e.structureVoxels += m != 0;
  return mask;
}

std::vector<uint8_t> wideLumenZone(const Geometry& g, const std::vector<uint8_t>& structure, int voxels) {
  std::vector<uint8_t> zone;
  if (structure.empty()) return zone;
  VS_REQUIRE(structure.size() == static_cast<size_t>(g.voxelCount()), "auto cost: one structure entry per voxel");
  zone.resize(structure.size());
  for (size_t i = 0; i < structure.size(); ++i) zone[i] = structure[i] == 3 ? 2 : 0;
  dilate(g, zone, voxels);
  return zone;
}

}  // namespace vs
