// Internal to the render module: the state behind Renderer (compact voxel copy, block grids
// for empty-space skipping, gradient table, labels, overlays, options) and the sampling
// primitives the ray casts use. Preparation: renderer.cpp; ray casting: ray_cast.cpp.
// Thread safety: const member functions are safe to call from the cast's worker threads.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "render/block_walk.h"
#include "render/overlay_raster.h"
#include "render/renderer.h"

namespace vs {

struct Renderer::Impl {
  Geometry g;
  int nx = 1, ny = 1, nz = 1;
  int64_t sy = 1, sz = 1;
  int ox = 0, oy = 0, oz = 0;  // offsets of the +1 neighbour (0 along a 1-voxel axis)
  // Voxels stored compactly (cache!): uint8 volumes as they are, everything else as uint16
  // with value = q0 + q1 * stored (exact for integer data spanning < 65536 values).
  std::vector<uint8_t> v8;
  std::vector<uint16_t> v16;
  bool is8 = false;
  float q0 = 0, q1 = 1;
  size_t nvox = 0;
  float val(size_t i) const { return q0 + q1 * (is8 ? float(v8[i]) : float(v16[i])); }
  ValueRange vrange;
  WindowLevel autoWl;
  Mat3 M, Minv, D;

  TransferFunction tf;
  RenderOptions opt;
  TfTable table;
  bool tableStale = true;

  // Min/max grid of 4^3-cell blocks for empty-space skipping (MIP: block maxima).
  struct BlockGrid : BlockGridShape {
    std::vector<float> mn, mx;
    size_t at(int x, int y, int z) const {  // x, y, z: cell index
      return static_cast<size_t>((x >> shift) + bx * ((y >> shift) + static_cast<int64_t>(by) * (z >> shift)));
    }
  };
  BlockGrid coarse;
  // Per 4^3 block of trilinear cells (cell = lower corner voxel index, cells 0..max(n-2,0) per
  // axis), one 64-bit word: bit (lx + 4 ly + 16 lz) set = cell (4 bx + lx, ...) has corner values
  // spanning an interval with some non-zero opacity. A sample in a cleared cell is transparent
  // (a trilinear value stays inside its corners' range), so compositing skips it before
  // interpolating; a block whose word is 0 is skipped by the ray's DDA. Rebuilt with the TF
  // table: 8 bytes per block (1/8 bit per voxel).
  std::vector<uint64_t> blockCells;
  std::vector<uint8_t> blockOn;  // blockCells[b] != 0, compact for the DDA (1 byte per block)
  bool cellOpaque(int ix, int iy, int iz) const {
    return (blockCells[coarse.at(ix, iy, iz)] >> ((ix & 3) | ((iy & 3) << 2) | ((iz & 3) << 4))) & 1u;
  }

  std::vector<std::array<int16_t, 3>> grad;
  bool gradReady = false;

  std::vector<uint16_t> labels;

  std::vector<MeshOverlay> meshes;
  std::vector<LineOverlay> lineSets;

  // ---- sampling ----
  inline void cell(float p, int n, int& i, float& f) const {
    i = static_cast<int>(p);
    const int maxc = n > 1 ? n - 2 : 0;
    if (i < 0) i = 0;
    if (i > maxc) i = maxc;
    f = n > 1 ? std::clamp(p - static_cast<float>(i), 0.f, 1.f) : 0.f;
  }

  template <class T>
  inline float sampleT(const T* vox, float px, float py, float pz) const {
    int ix, iy, iz;
    float fx, fy, fz;
    cell(px, nx, ix, fx);
    cell(py, ny, iy, fy);
    cell(pz, nz, iz, fz);
    return interpT(vox, ix + iy * sy + iz * sz, fx, fy, fz);
  }
  // Trilinear value in the cell with lower corner index `base` (fractions fx, fy, fz).
  template <class T>
  inline float interpT(const T* vox, int64_t base, float fx, float fy, float fz) const {
    const T* b = vox + base;
    const float b0 = b[0], b1 = b[ox], b2 = b[oy], b3 = b[oy + ox], b4 = b[oz], b5 = b[oz + ox], b6 = b[oz + oy],
                b7 = b[oz + oy + ox];
    const float c00 = b0 + fx * (b1 - b0);
    const float c10 = b2 + fx * (b3 - b2);
    const float c01 = b4 + fx * (b5 - b4);
    const float c11 = b6 + fx * (b7 - b6);
    const float c0 = c00 + fy * (c10 - c00);
    const float c1 = c01 + fy * (c11 - c01);
    return q0 + q1 * (c0 + fz * (c1 - c0));
  }
  float sample(float px, float py, float pz) const {
    return is8 ? sampleT(v8.data(), px, py, pz) : sampleT(v16.data(), px, py, pz);
  }

  inline void gradientAt(int64_t base, float fx, float fy, float fz, float out[3]) const {
    const float w[8] = {
        (1 - fx) * (1 - fy) * (1 - fz), fx * (1 - fy) * (1 - fz), (1 - fx) * fy * (1 - fz), fx * fy * (1 - fz),
        (1 - fx) * (1 - fy) * fz,       fx * (1 - fy) * fz,       (1 - fx) * fy * fz,       fx * fy * fz};
    const int64_t off[8] = {0, ox, oy, oy + ox, oz, oz + ox, oz + oy, oz + oy + ox};
    out[0] = out[1] = out[2] = 0;
    for (int k = 0; k < 8; ++k) {
      const auto& q = grad[static_cast<size_t>(base + off[k])];
      out[0] += w[k] * q[0];
      out[1] += w[k] * q[1];
      out[2] += w[k] * q[2];
    }
  }

  inline int labelAt(float px, float py, float pz) const {
    const int x = std::clamp(static_cast<int>(px + 0.5f), 0, nx - 1);
    const int y = std::clamp(static_cast<int>(py + 0.5f), 0, ny - 1);
    const int z = std::clamp(static_cast<int>(pz + 0.5f), 0, nz - 1);
    return labels[static_cast<size_t>(x + y * sy + z * sz)];
  }

  WindowLevel window() const { return opt.window.window > 0 ? opt.window : autoWl; }

  // Grey of value v through the window (float for the compositing).
  static float grey(float v, const WindowLevel& wl) { return static_cast<float>(windowGrey(v, wl)); }

  // ---- preparation (renderer.cpp) ----
  void buildBlocks(BlockGrid& G, int shift);
  void buildGradients(Progress& progress);
  template <class T>
  void buildBlockCellsT(const T* vox);
  void buildBlockCells();
  double stepMm() const { return opt.sampleStep * g.spacing.minCoeff(); }
  void prepare(Progress& progress);
};

}  // namespace vs
