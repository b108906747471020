#include "render/renderer.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

#include "util/error.h"
#include "util/parallel.h"

namespace vs {

RenderMode renderModeFromName(const std::string& n) {
  if (n == "full") return RenderMode::Full;
  if (n == "cutbox") return RenderMode::CutBox;
  if (n == "triplanar") return RenderMode::Triplanar;
  if (n == "monoplanar") return RenderMode::Monoplanar;
  if (n == "mip") return RenderMode::Mip;
  throw UsageError("unknown render mode '" + n + "' (valid: full, cutbox, triplanar, monoplanar, mip, slice)");
}

std::string renderModeName(RenderMode m) {
  switch (m) {
    case RenderMode::Full: return "full";
    case RenderMode::CutBox: return "cutbox";
    case RenderMode::Triplanar: return "triplanar";
    case RenderMode::Monoplanar: return "monoplanar";
    case RenderMode::Mip: return "mip";
  }
  return "full";
}

std::array<float, 3> labelColor(int label) {
  static const float pal[12][3] = {{0.9f, 0.2f, 0.2f}, {0.2f, 0.8f, 0.2f}, {0.25f, 0.4f, 1.0f}, {1.0f, 0.85f, 0.1f},
                                   {0.9f, 0.3f, 0.9f}, {0.1f, 0.9f, 0.9f}, {1.0f, 0.55f, 0.1f}, {0.6f, 0.4f, 0.2f},
                                   {0.6f, 1.0f, 0.5f}, {0.5f, 0.5f, 1.0f}, {1.0f, 0.6f, 0.7f}, {0.7f, 0.7f, 0.7f}};
  if (label <= 0) return {0, 0, 0};
  const float* c = pal[(label - 1) % 12];
  return {c[0], c[1], c[2]};
}

namespace {

// Triplanar: a plane pixel darker than this grey (0..1) is empty space and nearly transparent.
constexpr float kPlaneClearGrey = 0.05f;
constexpr float kPlaneClearOpacity = 0.15f;

constexpr int kTile = 16;
constexpr float kInf = std::numeric_limits<float>::infinity();

struct MeshOverlay {
  TriMesh mesh;
  std::array<float, 3> color;
};
struct LineOverlay {
  std::vector<Polyline> lines;
  std::array<float, 3> color;
  double radius;
};

// Ray / axis-aligned box [lo, hi] in index space; o + t d. Returns false on a miss.
bool intersectBox(const double o[3], const double d[3], const double lo[3], const double hi[3], double& t0, double& t1) {
  t0 = -1e300;
  t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < lo[a] - 1e-9 || o[a] > hi[a] + 1e-9) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t1 >= t0;
}

// One block crossed by a ray: flat block index, block coordinates, entry/exit times (32.32
// fixed point, relative to the ray's start).
struct BlockSpan {
  int64_t Tin, Tout, bi;
  int bx, by, bz;
};

// Incremental 3D DDA (Amanatides & Woo) over a block grid with integer (32.32 fixed-point)
// crossing times. next() appends the spans of the blocks whose on[] byte is non-zero, in ray
// order, until `cap` spans are collected or the end time TB is reached. The axis choice and the
// append use masks, not branches: the walk over mostly empty blocks has no data-dependent branch
// to mispredict. The walk never leaves the grid: TB is lowered to the first grid-exit crossing.
struct BlockWalk {
  int64_t T[3], dT[3];    // next crossing time per axis, increment per block
  int64_t TB = 0;         // end time
  int64_t Tin = 0;        // entry time of the current block
  int64_t bi = 0;         // current flat block index
  int64_t bstep[3];       // flat index change per axis step
  int b[3], stp[3];
  bool done = false;

  int next(const uint8_t* on, BlockSpan* out, int cap) {
    int64_t T0 = T[0], T1 = T[1], T2 = T[2], tin = Tin, idx = bi;
    int b0 = b[0], b1 = b[1], b2 = b[2];
    int n = 0;
    for (;;) {
      const int64_t mx = -static_cast<int64_t>((T0 <= T1) & (T0 <= T2));
      const int64_t my = ~mx & -static_cast<int64_t>(T1 <= T2);
      const int64_t mz = ~(mx | my);
      const int64_t Tout = std::min(std::min(T0, T1), T2);
      const bool last = Tout >= TB;
      out[n] = {tin, Tout, idx, b0, b1, b2};
      n += static_cast<int>((on[idx] != 0) & ((Tout > tin) | last));
      if (last) {
        done = true;
        break;
      }
      T0 += dT[0] & mx;
      T1 += dT[1] & my;
      T2 += dT[2] & mz;
      b0 += stp[0] & static_cast<int>(mx);
      b1 += stp[1] & static_cast<int>(my);
      b2 += stp[2] & static_cast<int>(mz);
      idx += (bstep[0] & mx) | (bstep[1] & my) | (bstep[2] & mz);
      tin = Tout;
      if (n == cap) break;
    }
    T[0] = T0, T[1] = T1, T[2] = T2, Tin = tin, bi = idx, b[0] = b0, b[1] = b1, b[2] = b2;
    return n;
  }
};

inline float ipow(float x, double p) {
  const int n = static_cast<int>(p);
  if (n == p && n >= 0 && n <= 64) {
    float r = 1.f, b = x;
    for (int e = n; e; e >>= 1, b *= b)
      if (e & 1) r *= b;
    return r;
  }
  return std::pow(x, static_cast<float>(p));
}

}  // namespace

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
  struct BlockGrid {
    int shift = 2;
    int bx = 1, by = 1, bz = 1;
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

  inline void gradient(float px, float py, float pz, float out[3]) const {
    int ix, iy, iz;
    float fx, fy, fz;
    cell(px, nx, ix, fx);
    cell(py, ny, iy, fy);
    cell(pz, nz, iz, fz);
    gradientAt(ix + iy * sy + iz * sz, fx, fy, fz, out);
  }
  inline void gradientAt(int64_t base, float fx, float fy, float fz, float out[3]) const {
    const float w[8] = {(1 - fx) * (1 - fy) * (1 - fz), fx * (1 - fy) * (1 - fz), (1 - fx) * fy * (1 - fz),
                        fx * fy * (1 - fz),             (1 - fx) * (1 - fy) * fz, fx * (1 - fy) * fz,
                        (1 - fx) * fy * fz,             fx * fy * fz};
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

  float grey(float v, const WindowLevel& wl) const {
    return std::clamp(static_cast<float>((v - (wl.level - 0.5 * wl.window)) / wl.window), 0.f, 1.f);
  }

  // ---- preparation ----
  void buildBlocks(BlockGrid& G, int shift) {
    G.shift = shift;
    G.bx = std::max(1, ((nx - 1) + (1 << shift) - 1) >> shift);
    G.by = std::max(1, ((ny - 1) + (1 << shift) - 1) >> shift);
    G.bz = std::max(1, ((nz - 1) + (1 << shift) - 1) >> shift);
    const size_t nb = static_cast<size_t>(G.bx) * G.by * G.bz;
    G.mn.assign(nb, kInf);
    G.mx.assign(nb, -kInf);
    parallelFor(0, G.bz, [&](int64_t b0, int64_t b1) {
      for (int64_t kb = b0; kb < b1; ++kb)
        for (int jb = 0; jb < G.by; ++jb)
          for (int ib = 0; ib < G.bx; ++ib) {
            float lo = kInf, hi = -kInf;
            // Voxels [2^s b, 2^s (b+1)] inclusive: a trilinear sample in the block's cells reads them.
            const int z1 = std::min<int>(nz - 1, static_cast<int>((kb + 1) << shift));
            const int y1 = std::min<int>(ny - 1, (jb + 1) << shift);
            const int x1 = std::min<int>(nx - 1, (ib + 1) << shift);
            for (int z = static_cast<int>(kb << shift); z <= z1; ++z)
              for (int y = jb << shift; y <= y1; ++y) {
                const size_t row = static_cast<size_t>(y * sy + z * sz);
                for (int x = ib << shift; x <= x1; ++x) {
                  const float v = val(row + static_cast<size_t>(x));
                  lo = std::min(lo, v);
                  hi = std::max(hi, v);
                }
              }
            const size_t bi = static_cast<size_t>(ib + G.bx * (jb + static_cast<int64_t>(G.by) * kb));
            G.mn[bi] = lo;
            G.mx[bi] = hi;
          }
    });
  }

  void buildGradients(Progress& progress) {
    const size_t n = nvox;
    grad.assign(n, {0, 0, 0});
    const double sx_ = g.spacing.x(), sy_ = g.spacing.y(), sz_ = g.spacing.z();
    auto central = [&](int x, int y, int z, float out[3]) {
      const int xm = std::max(0, x - 1), xp = std::min(nx - 1, x + 1);
      const int ym = std::max(0, y - 1), yp = std::min(ny - 1, y + 1);
      const int zm = std::max(0, z - 1), zp = std::min(nz - 1, z + 1);
      auto V = [&](int a, int b, int c) { return val(static_cast<size_t>(a + b * sy + c * sz)); };
      // Eq. 1-3 with the reading notes' correction: divide by the spacing.
      out[0] = xp > xm ? static_cast<float>((V(xp, y, z) - V(xm, y, z)) / ((xp - xm) * sx_)) : 0.f;
      out[1] = yp > ym ? static_cast<float>((V(x, yp, z) - V(x, ym, z)) / ((yp - ym) * sy_)) : 0.f;
      out[2] = zp > zm ? static_cast<float>((V(x, y, zp) - V(x, y, zm)) / ((zp - zm) * sz_)) : 0.f;
    };
    std::vector<float> sliceMax(static_cast<size_t>(nz), 0.f);
    parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z) {
        float m = 0;
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x) {
            float gv[3];
            central(x, y, static_cast<int>(z), gv);
            m = std::max({m, std::abs(gv[0]), std::abs(gv[1]), std::abs(gv[2])});
          }
        sliceMax[static_cast<size_t>(z)] = m;
      }
    });
    progress.report(0.5, "gradients");
    const float gmax = *std::max_element(sliceMax.begin(), sliceMax.end());
    const float q = gmax > 0 ? 32767.f / gmax : 0.f;
    parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z)
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x) {
            float gv[3];
            central(x, y, static_cast<int>(z), gv);
            auto& o = grad[static_cast<size_t>(x + y * sy + z * sz)];
            for (int a = 0; a < 3; ++a) o[a] = static_cast<int16_t>(std::lrint(std::clamp(gv[a] * q, -32767.f, 32767.f)));
          }
    });
    gradReady = true;
  }

  template <class T>
  void buildBlockCellsT(const T* vox) {
    const BlockGrid& G = coarse;
    blockCells.assign(static_cast<size_t>(G.bx) * G.by * G.bz, 0);
    // Cells exist for lower corners 0..n-2 (0 along a 1-voxel axis, whose offset is 0), as in cell().
    const int mc[3] = {std::max(0, nx - 2), std::max(0, ny - 2), std::max(0, nz - 2)};
    parallelFor(0, G.bz, [&](int64_t kb0, int64_t kb1) {
      for (int64_t kb = kb0; kb < kb1; ++kb)
        for (int jb = 0; jb < G.by; ++jb)
          for (int ib = 0; ib < G.bx; ++ib) {
            uint64_t word = 0;
            for (int lz = 0; lz < 4; ++lz) {
              const int z = static_cast<int>(kb) * 4 + lz;
              if (z > mc[2]) break;
              for (int ly = 0; ly < 4; ++ly) {
                const int y = jb * 4 + ly;
                if (y > mc[1]) break;
                for (int lx = 0; lx < 4; ++lx) {
                  const int x = ib * 4 + lx;
                  if (x > mc[0]) break;
                  const T* b = vox + (x + y * sy + z * sz);
                  T lo = b[0], hi = b[0];
                  for (const int64_t o : {int64_t(ox), int64_t(oy), int64_t(oy + ox), int64_t(oz), int64_t(oz + ox),
                                          int64_t(oz + oy), int64_t(oz + oy + ox)}) {
                    lo = std::min(lo, b[o]);
                    hi = std::max(hi, b[o]);
                  }
                  if (!table.transparent(q0 + q1 * float(lo), q0 + q1 * float(hi))) word |= uint64_t(1) << (lx + 4 * ly + 16 * lz);
                }
              }
            }
            blockCells[static_cast<size_t>(ib + G.bx * (jb + static_cast<int64_t>(G.by) * kb))] = word;
          }
    });
    blockOn.resize(blockCells.size());
    for (size_t i = 0; i < blockCells.size(); ++i) blockOn[i] = blockCells[i] != 0 ? 1 : 0;
  }
  void buildBlockCells() {
    if (is8)
      buildBlockCellsT(v8.data());
    else
      buildBlockCellsT(v16.data());
  }

  double stepMm() const { return opt.sampleStep * g.spacing.minCoeff(); }

  void prepare(Progress& progress) {
    if (tableStale) {
      table = TfTable(tf, vrange.min, vrange.max, stepMm());
      buildBlockCells();
      tableStale = false;
    }
    const bool needGrad = opt.shading && (opt.mode == RenderMode::Full || opt.mode == RenderMode::CutBox);
    if (needGrad && !gradReady) buildGradients(progress);
    progress.report(1.0, "prepare");
  }

  // ---- overlays ----
  struct OverlayBuffer {
    std::vector<float> depth;  // view depth mm, inf = none
    std::vector<std::array<float, 3>> color;
  };

  void rasterise(const CameraFrame& cf, OverlayBuffer& ob) const {
    const int W = cf.width(), H = cf.height();
    auto plot = [&](int x, int y, float z, const std::array<float, 3>& c, float shade) {
      const size_t i = static_cast<size_t>(y) * W + x;
      if (z < ob.depth[i] && z > 0) {
        ob.depth[i] = z;
        ob.color[i] = {c[0] * shade, c[1] * shade, c[2] * shade};
      }
    };
    const bool persp = cf.camera().perspective;
    for (const auto& mo : meshes) {
      const auto& m = mo.mesh;
      const bool vn = m.normals.size() == m.positions.size();
      for (const auto& tri : m.triangles) {
        double sx[3], sy_[3], sz_[3];
        bool ok = true;
        for (int k = 0; k < 3; ++k) ok = ok && cf.project(m.positions[static_cast<size_t>(tri[k])], sx[k], sy_[k], sz_[k]);
        if (!ok) continue;
        const Vec3& p0 = m.positions[static_cast<size_t>(tri[0])];
        Vec3 fn = (m.positions[static_cast<size_t>(tri[1])] - p0).cross(m.positions[static_cast<size_t>(tri[2])] - p0);
        if (fn.norm() > 0) fn.normalize();
        const double area = (sx[1] - sx[0]) * (sy_[2] - sy_[0]) - (sx[2] - sx[0]) * (sy_[1] - sy_[0]);
        if (std::abs(area) < 1e-12) continue;
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({sx[0], sx[1], sx[2]}))));
        const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({sy_[0], sy_[1], sy_[2]}))));
        const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({sy_[0], sy_[1], sy_[2]}))));
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            double w0 = ((sx[1] - px) * (sy_[2] - py) - (sx[2] - px) * (sy_[1] - py)) / area;
            double w1 = ((sx[2] - px) * (sy_[0] - py) - (sx[0] - px) * (sy_[2] - py)) / area;
            double w2 = 1.0 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            double z;
            if (persp) {
              const double iz = w0 / sz_[0] + w1 / sz_[1] + w2 / sz_[2];
              const double b0 = w0 / sz_[0] / iz, b1 = w1 / sz_[1] / iz, b2 = w2 / sz_[2] / iz;
              z = 1.0 / iz;
              w0 = b0, w1 = b1, w2 = b2;
            } else {
              z = w0 * sz_[0] + w1 * sz_[1] + w2 * sz_[2];
            }
            Vec3 n = fn;
            if (vn) {
              n = w0 * m.normals[static_cast<size_t>(tri[0])] + w1 * m.normals[static_cast<size_t>(tri[1])] +
                  w2 * m.normals[static_cast<size_t>(tri[2])];
              if (n.norm() > 0) n.normalize();
            }
            const float shade = static_cast<float>(0.25 + 0.75 * std::abs(n.dot(cf.forward())));
            plot(x, y, static_cast<float>(z), mo.color, shade);
          }
      }
    }
    for (const auto& lo : lineSets) {
      for (const auto& pl : lo.lines) {
        const size_t n = pl.points.size();
        const size_t segs = n < 2 ? n : (pl.closed ? n : n - 1);
        for (size_t s = 0; s < segs; ++s) {
          const size_t ia = s, ib = n < 2 ? s : (s + 1) % n;
          double ax, ay, az, bx_, by_, bz_;
          if (!cf.project(pl.points[ia], ax, ay, az) || !cf.project(pl.points[ib], bx_, by_, bz_)) continue;
          auto radiusPx = [&](size_t i, double z) {
            double r = lo.radius > 0 ? lo.radius : (pl.radii.size() == n ? pl.radii[i] : 0.0);
            const double px = r > 0 ? r / cf.pixelSizeAt(z) : 1.5;
            return std::max(px, 1.0);
          };
          const double ra = radiusPx(ia, az), rb = radiusPx(ib, bz_);
          const double rmax = std::max(ra, rb);
          const int x0 = std::max(0, static_cast<int>(std::floor(std::min(ax, bx_) - rmax)));
          const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max(ax, bx_) + rmax)));
          const int y0 = std::max(0, static_cast<int>(std::floor(std::min(ay, by_) - rmax)));
          const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max(ay, by_) + rmax)));
          const double dx = bx_ - ax, dy = by_ - ay, len2 = dx * dx + dy * dy;
          for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
              const double px = x + 0.5, py = y + 0.5;
              double t = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
              t = std::clamp(t, 0.0, 1.0);
              const double qx = ax + t * dx - px, qy = ay + t * dy - py;
              const double d = std::sqrt(qx * qx + qy * qy);
              const double r = ra + t * (rb - ra);
              if (d > r) continue;
              double z = persp ? 1.0 / ((1 - t) / az + t / bz_) : (1 - t) * az + t * bz_;
              const double bulge = std::sqrt(std::max(0.0, r * r - d * d));
              z -= bulge * cf.pixelSizeAt(z);  // front surface of the tube
              plot(x, y, static_cast<float>(z), lo.color, static_cast<float>(0.4 + 0.6 * bulge / r));
            }
        }
      }
    }
  }
};

Renderer::Renderer(const AnyVolume& volume, Progress& progress) : impl_(std::make_unique<Impl>()) {
  auto& I = *impl_;
  requireFinite(volume, "render volume");
  I.g = geometryOf(volume);
  I.g.validate();
  VS_REQUIRE(I.g.dims[0] < (1 << 30) && I.g.dims[1] < (1 << 30) && I.g.dims[2] < (1 << 30), "render: volume too large");
  I.nx = static_cast<int>(I.g.dims[0]);
  I.ny = static_cast<int>(I.g.dims[1]);
  I.nz = static_cast<int>(I.g.dims[2]);
  I.sy = I.nx;
  I.sz = static_cast<int64_t>(I.nx) * I.ny;
  I.ox = I.nx > 1 ? 1 : 0;
  I.oy = I.ny > 1 ? static_cast<int>(I.sy) : 0;
  I.oz = I.nz > 1 ? static_cast<int>(I.sz) : 0;
  I.vrange = valueRange(volume);
  I.nvox = static_cast<size_t>(I.g.voxelCount());
  if (const auto* u8 = std::get_if<VolumeU8>(&volume)) {
    I.is8 = true;
    I.v8 = u8->voxels();
  } else {
    const double span = I.vrange.max - I.vrange.min;
    const bool integer = !std::holds_alternative<VolumeF32>(volume);
    I.q0 = static_cast<float>(I.vrange.min);
    I.q1 = integer || span <= 0 ? 1.f : static_cast<float>(span / 65535.0);
    if (integer && span > 65535) I.q1 = static_cast<float>(span / 65535.0);
    I.v16.resize(I.nvox);
    std::visit(
        [&](const auto& vol) {
          const auto* d = vol.data();
          const double inv = 1.0 / I.q1;
          for (size_t i = 0; i < I.nvox; ++i)
            I.v16[i] = static_cast<uint16_t>(std::clamp(std::lrint((double(d[i]) - I.vrange.min) * inv), 0L, 65535L));
        },
        volume);
  }
  progress.report(0.3, "load");
  I.D = I.g.direction;
  I.M = I.g.direction * I.g.spacing.asDiagonal();
  I.Minv = I.M.inverse();
  // Automatic window: 1st..99.5th percentile from a 4096-bin histogram.
  {
    const int nb = 4096;
    std::vector<int64_t> h(nb, 0);
    const double lo = I.vrange.min, span = std::max(I.vrange.max - I.vrange.min, 1e-12);
    for (size_t i = 0; i < I.nvox; ++i) h[static_cast<size_t>(std::clamp(static_cast<int>((I.val(i) - lo) / span * (nb - 1)), 0, nb - 1))]++;
    auto pct = [&](double f) {
      const int64_t target = static_cast<int64_t>(f * static_cast<double>(I.nvox));
      int64_t acc = 0;
      for (int i = 0; i < nb; ++i) {
        acc += h[static_cast<size_t>(i)];
        if (acc > target) return lo + span * i / (nb - 1);
      }
      return I.vrange.max;
    };
    double a = pct(0.01), b = pct(0.995);
    if (!(b > a)) a = I.vrange.min, b = I.vrange.max > I.vrange.min ? I.vrange.max : I.vrange.min + 1;
    I.autoWl = {b - a, 0.5 * (a + b)};
  }
  I.buildBlocks(I.coarse, 2);
  I.tf = TransferFunction::preset("auto", I.vrange);
  progress.report(1.0, "load");
}

Renderer::~Renderer() = default;

const Geometry& Renderer::geometry() const { return impl_->g; }
ValueRange Renderer::range() const { return impl_->vrange; }
WindowLevel Renderer::autoWindow() const { return impl_->autoWl; }
const TransferFunction& Renderer::transferFunction() const { return impl_->tf; }
const RenderOptions& Renderer::options() const { return impl_->opt; }

void Renderer::setTransferFunction(const TransferFunction& tf) {
  VS_REQUIRE(!tf.empty(), "render: empty transfer function");
  impl_->tf = tf;
  impl_->tableStale = true;
}

void Renderer::setOptions(const RenderOptions& o) {
  auto& I = *impl_;
  VS_REQUIRE(std::isfinite(o.sampleStep) && o.sampleStep > 0.01 && o.sampleStep <= 16,
             "render: sample step must be in (0.01, 16] voxels");
  VS_REQUIRE(o.earlyTermination > 0 && o.earlyTermination <= 1, "render: early termination must be in (0, 1]");
  VS_REQUIRE(o.depthThreshold > 0 && o.depthThreshold <= 1, "render: depth threshold must be in (0, 1]");
  VS_REQUIRE(o.faceOpacity >= 0 && o.faceOpacity <= 1, "render: face opacity must be in [0, 1]");
  VS_REQUIRE(o.labelOpacity >= 0 && o.labelOpacity <= 1, "render: label opacity must be in [0, 1]");
  VS_REQUIRE(o.ambient >= 0 && o.ambient <= 1 && o.diffuse >= 0 && o.diffuse <= 1 && o.specular >= 0 && o.specular <= 1,
             "render: lighting: ambient, diffuse and specular coefficients must be in [0, 1]");
  VS_REQUIRE(o.specularPower >= 0 && o.specularPower <= 128, "render: lighting: specular power must be in [0, 128]");
  VS_REQUIRE(!(o.window.window < 0) && std::isfinite(o.window.window) && std::isfinite(o.window.level),
             "render: window must be >= 0 and finite");
  const int n[3] = {I.nx, I.ny, I.nz};
  const char* axn = "xyz";
  const bool wholeBox = o.box[0] == 0 && o.box[1] == 0 && o.box[2] == 0 && o.box[3] == -1 && o.box[4] == -1 && o.box[5] == -1;
  if (o.mode == RenderMode::CutBox && !wholeBox) {
    for (int a = 0; a < 3; ++a) {
      const double lo = o.box[static_cast<size_t>(a)], hi = o.box[static_cast<size_t>(a) + 3];
      VS_REQUIRE(std::isfinite(lo) && std::isfinite(hi), "render: cut box must be finite");
      VS_REQUIRE(hi > lo || (n[a] == 1 && hi == lo),
                 std::string("render: cut box is empty along ") + axn[a] + " (" + std::to_string(lo) + " .. " +
                     std::to_string(hi) + "); give x0,y0,z0,x1,y1,z1 with x0 < x1 etc.");
      VS_REQUIRE(hi >= 0 && lo <= n[a] - 1, std::string("render: cut box lies outside the volume along ") + axn[a] +
                                                " (volume index 0.." + std::to_string(n[a] - 1) + ")");
    }
  }
  if (o.mode == RenderMode::Triplanar)
    for (int a = 0; a < 3; ++a)
      VS_REQUIRE(o.planes[a] < 0 || o.planes[a] <= n[a] - 1,
                 std::string("render: plane ") + axn[a] + "=" + std::to_string(o.planes[a]) +
                     " is outside the volume (0.." + std::to_string(n[a] - 1) + ")");
  if (o.mode == RenderMode::Monoplanar) {
    VS_REQUIRE(o.planeAxis >= 0 && o.planeAxis <= 2, "render: plane axis must be 0 (x), 1 (y) or 2 (z)");
    VS_REQUIRE(o.planeIndex < 0 || o.planeIndex <= n[o.planeAxis] - 1,
               std::string("render: plane ") + axn[o.planeAxis] + "=" + std::to_string(o.planeIndex) +
                   " is outside the volume (0.." + std::to_string(n[o.planeAxis] - 1) + ")");
  }
  if (o.sampleStep != I.opt.sampleStep) I.tableStale = true;
  I.opt = o;
}

void Renderer::setLabels(const AnyVolume& labels) {
  auto& I = *impl_;
  const auto& lg = geometryOf(labels);
  VS_REQUIRE(lg.dims == I.g.dims, "render: label volume " + lg.describe() + " does not match the volume " + I.g.describe());
  const VolumeF32 f = toFloat(labels);
  I.labels.resize(f.voxels().size());
  for (size_t i = 0; i < I.labels.size(); ++i) {
    const float v = f.voxels()[i];
    I.labels[i] = static_cast<uint16_t>(std::isfinite(v) ? std::clamp(v, 0.f, 65535.f) : 0.f);
  }
}

void Renderer::clearLabels() { impl_->labels.clear(); }

void Renderer::addMesh(const TriMesh& mesh, const std::array<float, 3>& color) {
  mesh.validate();
  impl_->meshes.push_back({mesh, color});
}

void Renderer::addPolylines(const std::vector<Polyline>& lines, const std::array<float, 3>& color, double radiusMm) {
  for (const auto& l : lines)
    for (const auto& p : l.points)
      VS_REQUIRE(std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()), "render: overlay point is not finite");
  impl_->lineSets.push_back({lines, color, radiusMm});
}

void Renderer::clearOverlays() {
  impl_->meshes.clear();
  impl_->lineSets.clear();
}

double Renderer::overlayFractionOutside() const {
  const auto& I = *impl_;
  int64_t total = 0, outside = 0;
  auto test = [&](const Vec3& w) {  // the overlay readers' check (io/overlay_io.h)
    ++total;
    if (!I.g.nearVolume(w)) ++outside;
  };
  for (const auto& m : I.meshes)
    for (const auto& p : m.mesh.positions) test(p);
  for (const auto& l : I.lineSets)
    for (const auto& pl : l.lines)
      for (const auto& p : pl.points) test(p);
  return total ? double(outside) / double(total) : 0.0;
}

void Renderer::prepare(Progress& progress) { impl_->prepare(progress); }

RenderResult Renderer::render(const Camera& camera, int width, int height, Progress& progress) {
  VS_REQUIRE(width >= 1 && height >= 1 && width <= kMaxImageSide && height <= kMaxImageSide,
             "render: image size " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1x1 .. " +
                 std::to_string(kMaxImageSide) + "x" + std::to_string(kMaxImageSide));
  const CameraFrame cf(camera, width, height);
  auto& I = *impl_;
  I.prepare(progress);
  const RenderOptions& o = I.opt;

  RenderResult res;
  res.image = RgbaImage(width, height);
  const size_t npx = static_cast<size_t>(width) * height;
  res.depth.assign(npx, kInf);

  Impl::OverlayBuffer ob;
  const bool haveOverlays = !I.meshes.empty() || !I.lineSets.empty();
  if (haveOverlays) {
    ob.depth.assign(npx, kInf);
    ob.color.assign(npx, {0, 0, 0});
    I.rasterise(cf, ob);
  }

  const double dt = I.stepMm();
  const WindowLevel wl = I.window();
  const bool shade = o.shading && I.gradReady && (o.mode == RenderMode::Full || o.mode == RenderMode::CutBox);
  const bool haveLabels = !I.labels.empty();
  const float lop = static_cast<float>(o.labelOpacity);
  const double volLo[3] = {0, 0, 0};
  const double volHi[3] = {double(I.nx - 1), double(I.ny - 1), double(I.nz - 1)};
  double boxLo[3] = {volLo[0], volLo[1], volLo[2]}, boxHi[3] = {volHi[0], volHi[1], volHi[2]};
  const bool wholeBox = o.box[3] == -1 && o.box[4] == -1 && o.box[5] == -1 && o.box[0] == 0 && o.box[1] == 0 && o.box[2] == 0;
  if (o.mode == RenderMode::CutBox && !wholeBox)
    for (int a = 0; a < 3; ++a) {
      boxLo[a] = std::clamp(o.box[static_cast<size_t>(a)], volLo[a], volHi[a]);
      boxHi[a] = std::clamp(o.box[static_cast<size_t>(a) + 3], volLo[a], volHi[a]);
    }
  // Planes for triplanar / monoplanar, in index space.
  std::vector<std::pair<int, double>> planes;
  if (o.mode == RenderMode::Triplanar)
    for (int a = 0; a < 3; ++a) planes.push_back({a, o.planes[a] >= 0 ? o.planes[a] : std::floor(volHi[a] / 2)});
  if (o.mode == RenderMode::Monoplanar)
    planes.push_back({o.planeAxis, o.planeIndex >= 0 ? o.planeIndex : std::floor(volHi[o.planeAxis] / 2)});

  const int tilesX = (width + kTile - 1) / kTile, tilesY = (height + kTile - 1) / kTile;
  const int64_t ntiles = int64_t(tilesX) * tilesY;
  std::atomic<int64_t> nextTile{0};
  std::atomic<int64_t> sampleCount{0};
  const int workers = std::max(1, std::min<int>(workerCount(), static_cast<int>(ntiles)));
  const Mat3 Dt = I.D.transpose();
  const int maxC[3] = {std::max(0, I.nx - 2), std::max(0, I.ny - 2), std::max(0, I.nz - 2)};
  const float bg[3] = {o.background[0], o.background[1], o.background[2]};
  // MIP: the largest value that still maps to black (window low end, or where the TF's opacity
  // starts); blocks whose maximum is at or below it (or the ray's running maximum) are skipped.
  const float mipFloor = static_cast<float>(o.mipTransferFunction ? I.tf.opaqueRange().first : wl.level - 0.5 * wl.window);
  std::vector<uint8_t> mipOn;
  if (o.mode == RenderMode::Mip) {
    mipOn.resize(I.coarse.mx.size());
    for (size_t i = 0; i < mipOn.size(); ++i) mipOn[i] = I.coarse.mx[i] > mipFloor ? 1 : 0;
  }

  auto castRays = [&](const auto* vox) {
  parallelFor(0, workers, [&](int64_t, int64_t) {
    int64_t localSamples = 0;
    for (;;) {
      const int64_t tile = nextTile.fetch_add(1);
      if (tile >= ntiles) break;
      progress.check();
      const int tx = static_cast<int>(tile % tilesX) * kTile, ty = static_cast<int>(tile / tilesX) * kTile;
      for (int py = ty; py < std::min(height, ty + kTile); ++py)
        for (int px = tx; px < std::min(width, tx + kTile); ++px) {
          const size_t pix = static_cast<size_t>(py) * width + px;
          Vec3 ow, dw;
          cf.ray(px, py, ow, dw);
          const double cosf = dw.dot(cf.forward());  // view depth = t * cosf
          const Vec3 oi = I.Minv * (ow - I.g.origin), di = I.Minv * dw;
          const double o3[3] = {oi.x(), oi.y(), oi.z()}, d3[3] = {di.x(), di.y(), di.z()};
          const double inv3[3] = {std::abs(d3[0]) > 1e-15 ? 1.0 / d3[0] : 0.0, std::abs(d3[1]) > 1e-15 ? 1.0 / d3[1] : 0.0,
                                  std::abs(d3[2]) > 1e-15 ? 1.0 / d3[2] : 0.0};
          double t0 = 0, t1 = 0;  // ray interval inside the (cut) box, world mm
          // Block walk (BlockWalk) over the 4^3 blocks from ray parameter tA to tB (world mm):
          // visit(blockIndex, bx, by, bz, tIn, tOut) for each block crossed whose on[] byte is set,
          // in order; stops early when visit returns false. The first block gets exactly tA and
          // the last exactly tB; interior boundaries are shared by the two blocks they separate,
          // so the samples are partitioned exactly.
          auto dda = [&](double tA, double tB, const uint8_t* on, auto&& visit) {
            const Impl::BlockGrid& G = I.coarse;
            constexpr double kFix = 4294967296.0, kInvFix = 1.0 / 4294967296.0;
            constexpr int64_t kNever = std::numeric_limits<int64_t>::max() / 4;
            const double B = double(1 << G.shift);
            const int nb[3] = {G.bx, G.by, G.bz};
            const int64_t stride[3] = {1, G.bx, int64_t(G.bx) * G.by};
            BlockWalk w;
            const double tp = std::min(tA + 1e-7, 0.5 * (tA + tB));
            auto fix = [&](double t) {  // relative fixed-point time; far away = never
              return t > 1e6 ? kNever : std::llround(t * kFix);
            };
            w.TB = fix(tB - tA);
            for (int a = 0; a < 3; ++a) {
              const double p = o3[a] + d3[a] * tp;
              w.b[a] = std::clamp(static_cast<int>(std::floor(p / B)), 0, nb[a] - 1);
              int64_t crossings = 0;  // until the walk would leave the grid along this axis
              if (inv3[a] > 0) {
                w.stp[a] = 1;
                w.T[a] = fix(((w.b[a] + 1) * B - o3[a]) * inv3[a] - tA);
                w.dT[a] = fix(B * inv3[a]);
                crossings = nb[a] - w.b[a];
              } else if (inv3[a] < 0) {
                w.stp[a] = -1;
                w.T[a] = fix((w.b[a] * B - o3[a]) * inv3[a] - tA);
                w.dT[a] = fix(-B * inv3[a]);
                crossings = w.b[a] + 1;
              } else {
                w.stp[a] = 0;
                w.T[a] = kNever;
                w.dT[a] = 0;
              }
              w.bstep[a] = w.stp[a] * stride[a];
              if (crossings > 0 && w.T[a] < kNever &&
                  double(w.T[a]) + double(crossings - 1) * double(w.dT[a]) < double(kNever))
                w.TB = std::min(w.TB, w.T[a] + (crossings - 1) * w.dT[a]);
            }
            w.bi = w.b[0] + stride[1] * w.b[1] + stride[2] * w.b[2];
            BlockSpan buf[32];
            while (!w.done) {
              const int n = w.next(on, buf, 32);
              for (int i = 0; i < n; ++i) {
                const BlockSpan& sp = buf[i];
                const double tIn = sp.Tin <= 0 ? tA : tA + double(sp.Tin) * kInvFix;
                const double tOut = sp.Tout >= w.TB ? tB : tA + double(sp.Tout) * kInvFix;
                if (!visit(static_cast<size_t>(sp.bi), sp.bx, sp.by, sp.bz, tIn, tOut)) return;
              }
            }
          };
          // Sample lattice k = 0..nsteps at index-space position base + k step, in 32.32 fixed
          // point: position(k) = P0 + k S exactly (integer arithmetic), whichever way k is reached,
          // so skipping never moves a sample that is taken. Gives the sample's cell (clamped as
          // cell() does) and fractions.
          struct Lattice {
            int64_t P0[3], S[3];
          };
          auto makeLattice = [](const double base[3], const double step[3]) {
            Lattice L;
            for (int a = 0; a < 3; ++a) {
              L.P0[a] = std::llround(base[a] * 4294967296.0);
              L.S[a] = std::llround(step[a] * 4294967296.0);
            }
            return L;
          };
          auto fixedCell = [](int64_t p, int maxc, int& i, float& f) {
            i = static_cast<int>(p >> 32);
            f = static_cast<float>(static_cast<uint32_t>(p)) * 0x1p-32f;
            if (static_cast<unsigned>(i) > static_cast<unsigned>(maxc)) {
              if (i < 0) {
                i = 0;
                f = 0.f;
              } else {
                i = maxc;
                f = 1.f;
              }
            }
          };
          // Visits the lattice samples in order: body(k, ix, iy, iz, fx, fy, fz) for every k, or
          // with empty-space skipping only in blocks whose on[] byte is set and where still(blockIndex)
          // is true when the block's turn comes, and, when
          // cellTest, only samples whose cell bit is set. body returns false to stop.
          auto march = [&](int64_t nsteps, const double base[3], const double step[3], bool cellTest, const uint8_t* on,
                           auto&& still,
                           auto&& body) {
            if (nsteps < 0) return;
            const Lattice L = makeLattice(base, step);
            if (!o.emptySpaceSkipping) {
              for (int64_t k = 0; k <= nsteps; ++k) {
                int ix, iy, iz;
                float fx, fy, fz;
                fixedCell(L.P0[0] + k * L.S[0], maxC[0], ix, fx);
                fixedCell(L.P0[1] + k * L.S[1], maxC[1], iy, fy);
                fixedCell(L.P0[2] + k * L.S[2], maxC[2], iz, fz);
                if (!body(k, ix, iy, iz, fx, fy, fz)) return;
              }
              return;
            }
            const double tEnd = t0 + double(nsteps) * dt;
            const double invDt = 1.0 / dt;
            auto kOf = [&](double t) {  // first k with t0 + k dt >= t
              const double q = (t - t0) * invDt;
              int64_t k = static_cast<int64_t>(q);
              if (double(k) < q) ++k;
              return std::clamp<int64_t>(k, 0, nsteps + 1);
            };
            dda(t0, tEnd, on, [&](size_t bi, int bx, int by, int bz, double tIn, double tOut) {
              if (!still(bi)) return true;  // MIP: the running maximum may have grown meanwhile
              const int64_t kS = kOf(tIn), kE = tOut >= tEnd ? nsteps + 1 : kOf(tOut);
              if (kS >= kE) return true;
              auto take = [&](int64_t k, int64_t px, int64_t py, int64_t pz) {
                int ix, iy, iz;
                float fx, fy, fz;
                fixedCell(px, maxC[0], ix, fx);
                fixedCell(py, maxC[1], iy, fy);
                fixedCell(pz, maxC[2], iz, fz);
                return body(k, ix, iy, iz, fx, fy, fz);
              };
              if (cellTest) {
                const uint64_t word = I.blockCells[bi];
                // Raw cell (before clamping) of a sample inside this block and <= the last cell?
                // Positions are monotone along the ray, so checking the first and last sample of
                // the block's range covers all of them.
                const int bxyz[3] = {bx, by, bz};
                bool inside = true;
                for (int a = 0; a < 3; ++a)
                  for (const int64_t k : {kS, kE - 1}) {
                    const int c = static_cast<int>((L.P0[a] + k * L.S[a]) >> 32);
                    inside = inside && c >= 0 && c <= maxC[a] && (c >> 2) == bxyz[a];
                  }
                if (inside) {
                  // Fast path: the cell bit straight from the position's integer bits, positions
                  // stepped incrementally (the same integers as P0 + k S).
                  int64_t px = L.P0[0] + kS * L.S[0], py = L.P0[1] + kS * L.S[1], pz = L.P0[2] + kS * L.S[2];
                  for (int64_t k = kS; k < kE; ++k, px += L.S[0], py += L.S[1], pz += L.S[2]) {
                    const unsigned bit = static_cast<unsigned>(((px >> 32) & 3) | (((py >> 32) & 3) << 2) | (((pz >> 32) & 3) << 4));
                    if (((word >> bit) & 1u) && !take(k, px, py, pz)) return false;
                  }
                  return true;
                }
                // Near a block face (or the volume's last cell) rounding may put a sample's cell
                // in the neighbour block, whose own word then decides.
                for (int64_t k = kS; k < kE; ++k) {
                  const int64_t px = L.P0[0] + k * L.S[0], py = L.P0[1] + k * L.S[1], pz = L.P0[2] + k * L.S[2];
                  const int cx = std::clamp(static_cast<int>(px >> 32), 0, maxC[0]);
                  const int cy = std::clamp(static_cast<int>(py >> 32), 0, maxC[1]);
                  const int cz = std::clamp(static_cast<int>(pz >> 32), 0, maxC[2]);
                  if (I.cellOpaque(cx, cy, cz) && !take(k, px, py, pz)) return false;
                }
                return true;
              }
              for (int64_t k = kS; k < kE; ++k)
                if (!take(k, L.P0[0] + k * L.S[0], L.P0[1] + k * L.S[1], L.P0[2] + k * L.S[2])) return false;
              return true;
            });
          };
          float ovDepth = haveOverlays ? ob.depth[pix] : kInf;
          const double tOverlay = ovDepth < kInf ? ovDepth / cosf : 1e300;
          float C[3] = {0, 0, 0}, A = 0;
          float depth = kInf;
          auto composite = [&](const float c[3], float a, double t) {
            const float w = (1 - A) * a;
            C[0] += w * c[0];
            C[1] += w * c[1];
            C[2] += w * c[2];
            A += w;
            if (depth == kInf && A >= o.depthThreshold) depth = static_cast<float>(t * cosf);
          };
          auto planeColour = [&](const double p[3], float c[3]) {
            const float v = I.sample(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
            const float gval = I.grey(v, wl);
            c[0] = c[1] = c[2] = gval;
            if (haveLabels) {
              const int l = I.labelAt(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
              if (l > 0) {
                const auto lc = labelColor(l);
                for (int k = 0; k < 3; ++k) c[k] = (1 - lop) * c[k] + lop * lc[static_cast<size_t>(k)];
              }
            }
          };

          if (!planes.empty()) {
            // Every plane hit in front of the overlays, nearest first. Where a plane shows
            // nothing (grey below kPlaneClearGrey: air, background) it is nearly clear, so
            // planes do not hide each other behind empty space.
            std::array<double, 3> hits{};
            size_t nHits = 0;
            const double limit = std::min(tOverlay, 1e300);
            for (size_t k = 0; k < planes.size(); ++k) {
              const int a = planes[k].first;
              if (std::abs(d3[a]) < 1e-15) continue;
              const double t = (planes[k].second - o3[a]) / d3[a];
              if (t <= 0 || t >= limit) continue;
              bool inside = true;
              for (int b = 0; b < 3; ++b)
                if (b != a) {
                  const double q = o3[b] + t * d3[b];
                  inside = inside && q >= volLo[b] - 1e-6 && q <= volHi[b] + 1e-6;
                }
              if (inside && nHits < hits.size()) hits[nHits++] = t;
            }
            std::sort(hits.begin(), hits.begin() + static_cast<std::ptrdiff_t>(nHits));
            for (size_t h = 0; h < nHits; ++h) {
              const double t = hits[h];
              const double p[3] = {o3[0] + t * d3[0], o3[1] + t * d3[1], o3[2] + t * d3[2]};
              float c[3];
              planeColour(p, c);
              const bool clear = nHits > 1 && std::max({c[0], c[1], c[2]}) < kPlaneClearGrey;
              composite(c, clear ? kPlaneClearOpacity : 1.f, t);
            }
          } else if (o.mode == RenderMode::Mip) {
            float vmax = -kInf;
            double tmax = 0;
            if (intersectBox(o3, d3, volLo, volHi, t0, t1) && t1 > 0) {
              t0 = std::max(t0, 0.0);
              const double dix = d3[0] * dt, diy = d3[1] * dt, diz = d3[2] * dt;
              const int64_t nsteps = static_cast<int64_t>(std::floor((t1 - t0) / dt));
              const double base[3] = {o3[0] + d3[0] * t0, o3[1] + d3[1] * t0, o3[2] + d3[2] * t0};
              const double step[3] = {dix, diy, diz};
              march(
                  nsteps, base, step, false, mipOn.data(), [&](size_t bi) { return I.coarse.mx[bi] > vmax; },
                  [&](int64_t k, int ix, int iy, int iz, float fx, float fy, float fz) {
                    ++localSamples;
                    const float v = I.interpT(vox, ix + iy * I.sy + iz * I.sz, fx, fy, fz);
                    if (v > vmax) vmax = v, tmax = t0 + double(k) * dt;
                    return true;
                  });
            }
            // Maxima at or below mipFloor map to black either way (the block test above skips them).
            if (vmax > -kInf && vmax > mipFloor) {
              if (o.mipTransferFunction) {
                const Rgba e = I.tf.evaluate(vmax);
                const float c[3] = {e.r, e.g, e.b};
                composite(c, e.a, tmax);
              } else {
                const float gv = I.grey(vmax, wl);
                const float c[3] = {gv, gv, gv};
                composite(c, 1.f, tmax);
              }
            }
            if (ovDepth < kInf) {  // MIP has no occlusion: overlays are drawn on top.
              C[0] = ob.color[pix][0], C[1] = ob.color[pix][1], C[2] = ob.color[pix][2], A = 1;
              depth = ovDepth;
              ovDepth = kInf;
            }
          } else {
            // Full / CutBox: front-to-back compositing.
            if (intersectBox(o3, d3, boxLo, boxHi, t0, t1) && t1 > 0 && t0 < tOverlay) {
              t0 = std::max(t0, 0.0);
              bool faceOnly = false;
              if (o.mode == RenderMode::CutBox && o.faceOpacity > 0) {
                const double p[3] = {o3[0] + t0 * d3[0], o3[1] + t0 * d3[1], o3[2] + t0 * d3[2]};
                float c[3];
                planeColour(p, c);
                composite(c, static_cast<float>(o.faceOpacity), t0);
                faceOnly = A >= o.earlyTermination;
              }
              t1 = std::min(t1, tOverlay);
              // Headlight in the index-axes frame: L = -dir, half vector H = L.
              const Vec3 L = -(Dt * dw);
              const float lx = static_cast<float>(L.x()), ly = static_cast<float>(L.y()), lz = static_cast<float>(L.z());
              const float ka = static_cast<float>(o.ambient), kd = static_cast<float>(o.diffuse),
                          ks = static_cast<float>(o.specular);
              const double dix = d3[0] * dt, diy = d3[1] * dt, diz = d3[2] * dt;
              const double bx0 = o3[0] + d3[0] * t0, by0 = o3[1] + d3[1] * t0, bz0 = o3[2] + d3[2] * t0;
              const int64_t nsteps = faceOnly ? -1 : static_cast<int64_t>(std::floor((t1 - t0) / dt));
              const float term = static_cast<float>(o.earlyTermination);
              const double base[3] = {bx0, by0, bz0};
              const double step[3] = {dix, diy, diz};
              march(
                  nsteps, base, step, true, I.blockOn.data(), [](size_t) { return true; },
                  [&](int64_t k, int ix, int iy, int iz, float fx, float fy, float fz) {
                ++localSamples;
                const int64_t cb = ix + iy * I.sy + iz * I.sz;
                const float v = I.interpT(vox, cb, fx, fy, fz);
                const Rgba& e = I.table(v);
                if (e.a <= 0.f) return true;
                float c[3] = {e.r, e.g, e.b};
                if (haveLabels) {
                  const int l = I.labels[static_cast<size_t>((ix + (fx >= 0.5f)) + (iy + (fy >= 0.5f)) * I.sy +
                                                             (iz + (fz >= 0.5f)) * I.sz)];
                  if (l > 0) {
                    const auto lc = labelColor(l);
                    for (int q = 0; q < 3; ++q) c[q] = (1 - lop) * c[q] + lop * lc[static_cast<size_t>(q)];
                  }
                }
                if (shade) {
                  float gv[3];
                  I.gradientAt(cb, fx, fy, fz, gv);
                  const float n2 = gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2];
                  float diff = 1.f, spec = 0.f;
                  if (n2 > 1e-6f) {
                    const float ndl = std::abs(gv[0] * lx + gv[1] * ly + gv[2] * lz) / std::sqrt(n2);
                    diff = ndl;
                    spec = ipow(ndl, o.specularPower);
                  }
                  const float f = ka + kd * diff;
                  for (int q = 0; q < 3; ++q) c[q] = c[q] * f + ks * spec;
                }
                const float w = (1 - A) * e.a;
                C[0] += w * c[0];
                C[1] += w * c[1];
                C[2] += w * c[2];
                A += w;
                if (depth == kInf && A >= o.depthThreshold) depth = static_cast<float>((t0 + double(k) * dt) * cosf);
                return A < term;
              });
            }
          }
          if (ovDepth < kInf && A < 1.f) {  // opaque overlay behind what was composited so far
            const auto& oc = ob.color[pix];
            const float c[3] = {oc[0], oc[1], oc[2]};
            const float before = A;
            composite(c, 1.f, ovDepth / cosf);
            if (depth == kInf || before < o.depthThreshold) depth = std::min(depth, ovDepth);
          }
          uint8_t* out = res.image.at(px, py);
          for (int q = 0; q < 3; ++q) {
            const float v = C[q] + (1 - A) * bg[q];
            out[q] = static_cast<uint8_t>(std::lrint(std::clamp(v, 0.f, 1.f) * 255.f));
          }
          out[3] = 255;
          res.depth[pix] = depth;
        }
    }
    sampleCount += localSamples;
  });
  };
  if (I.is8)
    castRays(I.v8.data());
  else
    castRays(I.v16.data());
  res.samples = sampleCount.load();
  progress.report(1.0, "render");
  return res;
}

}  // namespace vs
