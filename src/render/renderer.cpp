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

  // Min/max grids for empty-space skipping: coarse 4^3 blocks and fine 2^3 blocks (the
  // fine level pays off in noisy backgrounds where a few voxels spoil most coarse blocks).
  struct BlockGrid {
    int shift = 2;
    int bx = 1, by = 1, bz = 1;
    std::vector<float> mn, mx;
    std::vector<uint8_t> empty;
    std::vector<uint8_t> mask;  // coarse grid: bit q set = fine sub-block q (x + 2y + 4z) empty
    size_t at(int x, int y, int z) const {  // x, y, z: cell index
      return static_cast<size_t>((x >> shift) + bx * ((y >> shift) + static_cast<int64_t>(by) * (z >> shift)));
    }
  };
  BlockGrid coarse, fine;
  std::vector<int64_t> fineOf;  // coarse block * 8 + q -> fine block index (-1: outside the fine grid)
  // Per trilinear cell (indexed by its lower corner voxel, x fastest): bit set = the 8 corner
  // values span an interval with some non-zero opacity. A sample in a cleared cell is
  // transparent (trilinear values stay inside the corners' range), so compositing skips it
  // before interpolating. Rebuilt with the TF table; nvox bits.
  std::vector<uint64_t> cellBits;
  bool cellOpaque(int64_t base) const { return (cellBits[static_cast<size_t>(base >> 6)] >> (base & 63)) & 1u; }

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
  void buildCellBitsT(const T* vox) {
    std::vector<uint8_t> flag(nvox, 0);
    parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z)
        for (int y = 0; y < ny; ++y) {
          const int64_t row = y * sy + z * sz;
          for (int x = 0; x < nx; ++x) {
            // Same cell clamping as cell(): the last voxel along an axis uses the cell below it,
            // but a flag per voxel index is only read for clamped indices, so edge voxels just
            // repeat their own neighbourhood (offsets 0 along 1-voxel axes).
            const int64_t i = row + x;
            const int64_t dx = x + 1 < nx ? ox : 0, dy = y + 1 < ny ? oy : 0, dz = z + 1 < nz ? oz : 0;
            const T* b = vox + i;
            T lo = b[0], hi = b[0];
            for (const int64_t o : {dx, dy, dy + dx, dz, dz + dx, dz + dy, dz + dy + dx}) {
              lo = std::min(lo, b[o]);
              hi = std::max(hi, b[o]);
            }
            flag[static_cast<size_t>(i)] = table.transparent(q0 + q1 * float(lo), q0 + q1 * float(hi)) ? 0 : 1;
          }
        }
    });
    const size_t nw = (nvox + 63) / 64;
    cellBits.assign(nw, 0);
    parallelFor(0, static_cast<int64_t>(nw), [&](int64_t w0, int64_t w1) {
      for (int64_t w = w0; w < w1; ++w) {
        uint64_t bits = 0;
        const size_t i0 = static_cast<size_t>(w) * 64, i1 = std::min(nvox, i0 + 64);
        for (size_t i = i0; i < i1; ++i) bits |= uint64_t(flag[i]) << (i - i0);
        cellBits[static_cast<size_t>(w)] = bits;
      }
    });
  }
  void buildCellBits() {
    if (is8)
      buildCellBitsT(v8.data());
    else
      buildCellBitsT(v16.data());
  }

  double stepMm() const { return opt.sampleStep * g.spacing.minCoeff(); }

  void prepare(Progress& progress) {
    if (tableStale) {
      table = TfTable(tf, vrange.min, vrange.max, stepMm());
      for (BlockGrid* G : {&coarse, &fine}) {
        const size_t nb = G->mn.size();
        G->empty.assign(nb, 0);
        for (size_t i = 0; i < nb; ++i) G->empty[i] = table.transparent(G->mn[i], G->mx[i]) ? 1 : 0;
      }
      coarse.mask.assign(coarse.empty.size(), 0);
      for (size_t bi = 0; bi < coarse.mask.size(); ++bi) {
        unsigned m = 0;
        for (int q = 0; q < 8; ++q) {
          const int64_t f = fineOf[bi * 8 + static_cast<size_t>(q)];
          if (f < 0 || fine.empty[static_cast<size_t>(f)]) m |= 1u << q;
        }
        coarse.mask[bi] = static_cast<uint8_t>(m);
      }
      buildCellBits();
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
  I.buildBlocks(I.fine, 1);
  I.fineOf.assign(I.coarse.mn.size() * 8, -1);
  for (int k = 0; k < I.coarse.bz; ++k)
    for (int j = 0; j < I.coarse.by; ++j)
      for (int i = 0; i < I.coarse.bx; ++i)
        for (int q = 0; q < 8; ++q) {
          const int fi = 2 * i + (q & 1), fj = 2 * j + ((q >> 1) & 1), fk = 2 * k + ((q >> 2) & 1);
          if (fi >= I.fine.bx || fj >= I.fine.by || fk >= I.fine.bz) continue;
          const size_t bi = static_cast<size_t>(i + I.coarse.bx * (j + static_cast<int64_t>(I.coarse.by) * k));
          I.fineOf[bi * 8 + static_cast<size_t>(q)] = fi + I.fine.bx * (fj + static_cast<int64_t>(I.fine.by) * fk);
        }
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
  auto test = [&](const Vec3& w) {
    const Vec3 i = I.g.worldToIndex(w);
    ++total;
    if (i.x() < -1 || i.y() < -1 || i.z() < -1 || i.x() > I.nx || i.y() > I.ny || i.z() > I.nz) ++outside;
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
          // 3D DDA (Amanatides & Woo) over the blocks of 2^shift voxels of one grid, from ray
          // parameter tA to tB (world mm): visit(grid, blockIndex, tIn, tOut) per block crossed,
          // in order; stops early when visit returns false (and returns false).
          auto dda = [&](const Impl::BlockGrid& G, double tA, double tB, auto&& visit) -> bool {
            const int shift = G.shift;
            const double B = double(1 << shift);
            const int nb[3] = {G.bx, G.by, G.bz};
            int b[3], stp[3];
            double tMax[3], tDelta[3];
            const double tp = std::min(tA + 1e-7, 0.5 * (tA + tB));
            for (int a = 0; a < 3; ++a) {
              const double p = o3[a] + d3[a] * tp;
              b[a] = std::clamp(static_cast<int>(std::floor(p / B)), 0, nb[a] - 1);
              if (inv3[a] > 0) {
                stp[a] = 1;
                tMax[a] = ((b[a] + 1) * B - o3[a]) * inv3[a];
                tDelta[a] = B * inv3[a];
              } else if (inv3[a] < 0) {
                stp[a] = -1;
                tMax[a] = (b[a] * B - o3[a]) * inv3[a];
                tDelta[a] = -B * inv3[a];
              } else {
                stp[a] = 0;
                tMax[a] = 1e300;
                tDelta[a] = 0;
              }
            }
            double tIn = tA;
            for (;;) {
              const int a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
              const double tOut = std::min(tMax[a], tB);
              const size_t bi = static_cast<size_t>(b[0] + G.bx * (b[1] + static_cast<int64_t>(G.by) * b[2]));
              if (tOut > tIn || tOut >= tB)
                if (!visit(G, bi, tIn, tOut)) return false;
              if (tOut >= tB) return true;
              b[a] += stp[a];
              if (b[a] < 0 || b[a] >= nb[a]) return true;
              tIn = tOut;
              tMax[a] += tDelta[a];
            }
          };
          // Visits the lattice samples k = 0..nsteps (position base + k step, index space) in
          // order; with empty-space skipping only those in blocks where blockEmpty(grid, index)
          // is false (coarse 4^3 blocks, then fine 2^3 blocks inside non-empty coarse ones).
          // Samples stay on the lattice t0 + k dt, so skipping never moves a sample that is taken.
          // body(k, x, y, z) returns false to stop.
          auto march = [&](int64_t nsteps, const double base[3], const double step[3], auto&& blockEmpty, auto&& body) {
            auto run = [&](int64_t kS, int64_t kE) {
              for (int64_t k = kS; k < kE; ++k) {
                const float x = static_cast<float>(base[0] + step[0] * double(k));
                const float y = static_cast<float>(base[1] + step[1] * double(k));
                const float z = static_cast<float>(base[2] + step[2] * double(k));
                if (!body(k, x, y, z)) return false;
              }
              return true;
            };
            if (nsteps < 0) return;
            if (!o.emptySpaceSkipping) {
              run(0, nsteps + 1);
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
            dda(I.coarse, t0, tEnd, [&](const Impl::BlockGrid& G, size_t bi, double tIn, double tOut) {
              // mask: bit i set = fine 2^3 sub-block i (x + 2y + 4z) of this 4^3 block is empty.
              const unsigned mask = blockEmpty(G, bi);
              if (mask == 0xFFu) return true;
              const int64_t kS = kOf(tIn), kE = tOut >= tEnd ? nsteps + 1 : kOf(tOut);
              if (mask == 0) return run(kS, kE);
              for (int64_t k = kS; k < kE; ++k) {
                const float x = static_cast<float>(base[0] + step[0] * double(k));
                const float y = static_cast<float>(base[1] + step[1] * double(k));
                const float z = static_cast<float>(base[2] + step[2] * double(k));
                const int ix = std::min(static_cast<int>(x), maxC[0]), iy = std::min(static_cast<int>(y), maxC[1]),
                          iz = std::min(static_cast<int>(z), maxC[2]);
                const unsigned bit = ((ix >> 1) & 1u) | (((iy >> 1) & 1u) << 1) | (((iz >> 1) & 1u) << 2);
                if ((mask >> bit) & 1u) continue;
                if (!body(k, x, y, z)) return false;
              }
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
            double best = std::min(tOverlay, 1e300);
            int bestPlane = -1;
            for (size_t k = 0; k < planes.size(); ++k) {
              const int a = planes[k].first;
              if (std::abs(d3[a]) < 1e-15) continue;
              const double t = (planes[k].second - o3[a]) / d3[a];
              if (t <= 0 || t >= best) continue;
              bool inside = true;
              for (int b = 0; b < 3; ++b)
                if (b != a) {
                  const double q = o3[b] + t * d3[b];
                  inside = inside && q >= volLo[b] - 1e-6 && q <= volHi[b] + 1e-6;
                }
              if (inside) best = t, bestPlane = static_cast<int>(k);
            }
            if (bestPlane >= 0) {
              const double p[3] = {o3[0] + best * d3[0], o3[1] + best * d3[1], o3[2] + best * d3[2]};
              float c[3];
              planeColour(p, c);
              composite(c, 1.f, best);
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
                  nsteps, base, step, [&](const Impl::BlockGrid& G, size_t bi) {
                    // Coarse level only: the fine test costs more than it saves in MIP.
                    return G.mx[bi] <= std::max(vmax, mipFloor) ? 0xFFu : 0u;
                  },
                  [&](int64_t k, float x, float y, float z) {
                    ++localSamples;
                    const float v = I.sampleT(vox, x, y, z);
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
                  nsteps, base, step, [](const Impl::BlockGrid& G, size_t bi) { return unsigned(G.mask[bi]); },
                  [&](int64_t k, float x, float y, float z) {
                ++localSamples;
                int ix, iy, iz;
                float fx, fy, fz;
                I.cell(x, I.nx, ix, fx);
                I.cell(y, I.ny, iy, fy);
                I.cell(z, I.nz, iz, fz);
                const int64_t cb = ix + iy * I.sy + iz * I.sz;
                if (o.emptySpaceSkipping && !I.cellOpaque(cb)) return true;  // all 8 corners transparent
                const float v = I.interpT(vox, cb, fx, fy, fz);
                const Rgba& e = I.table(v);
                if (e.a <= 0.f) return true;
                float c[3] = {e.r, e.g, e.b};
                if (haveLabels) {
                  const int l = I.labelAt(x, y, z);
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
