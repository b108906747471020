#include "render/ray_cast.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "util/parallel.h"

namespace vs {

namespace {

// Triplanar: a plane pixel darker than this grey (0..1) is empty space and nearly transparent.
constexpr float kPlaneClearGrey = 0.05f;
constexpr float kPlaneClearOpacity = 0.15f;

constexpr int kTile = 16;
constexpr float kInf = std::numeric_limits<float>::infinity();

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

// One pixel's ray in index space.
struct Ray {
  Vec3 dw;                       // world direction (unit)
  double cosf;                   // view depth = t * cosf
  double o3[3], d3[3], inv3[3];  // origin, direction, 1 / direction (0 where negligible)
};

// Front-to-back compositing, C += (1 - A) a c, A += (1 - A) a (the same image as the
// back-to-front eq. 4-5), with the view depth taken where A first reaches depthThreshold.
struct Compositor {
  float C[3] = {0, 0, 0}, A = 0;
  float depth = kInf;
  double cosf, depthThreshold;
  void add(const float c[3], float a, double t) {
    const float w = (1 - A) * a;
    C[0] += w * c[0];
    C[1] += w * c[1];
    C[2] += w * c[2];
    A += w;
    if (depth == kInf && A >= depthThreshold) depth = static_cast<float>(t * cosf);
  }
};

// Sample lattice k = 0..nsteps at index-space position base + k step, in 32.32 fixed point:
// position(k) = P0 + k S exactly (integer arithmetic), whichever way k is reached, so skipping
// never moves a sample that is taken.
struct Lattice {
  int64_t P0[3], S[3];
};
inline Lattice makeLattice(const double base[3], const double step[3]) {
  Lattice L;
  for (int a = 0; a < 3; ++a) {
    L.P0[a] = std::llround(base[a] * 4294967296.0);
    L.S[a] = std::llround(step[a] * 4294967296.0);
  }
  return L;
}
// The sample's cell (clamped as Impl::cell() does) and fractions.
inline void fixedCell(int64_t p, int maxc, int& i, float& f) {
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
}

// Visits the lattice samples of the ray from t0 in order: body(k, ix, iy, iz, fx, fy, fz) for
// every k, or with empty-space skipping only in blocks whose on[] byte is set and where
// still(blockIndex) is true when the block's turn comes, and, when cellTest, only samples whose
// cell bit is set. body returns false to stop.
template <class Still, class Body>
inline void march(const CastFrame& F, const Ray& r, double t0, int64_t nsteps, const double base[3],
                  const double step[3], bool cellTest, const uint8_t* on, Still&& still, Body&& body) {
  if (nsteps < 0) return;
  const Renderer::Impl& I = F.I;
  const int* maxC = F.maxC;
  const double dt = F.dt;
  const Lattice L = makeLattice(base, step);
  if (!F.o.emptySpaceSkipping) {
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
  walkBlocks(I.coarse, r.o3, r.d3, r.inv3, t0, tEnd, on,
             [&](size_t bi, int bx, int by, int bz, double tIn, double tOut) {
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
                     const unsigned bit =
                         static_cast<unsigned>(((px >> 32) & 3) | (((py >> 32) & 3) << 2) | (((pz >> 32) & 3) << 4));
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
}

// Grey of the data at index position p through the window, with the label colour blended in.
inline void planeColour(const CastFrame& F, const double p[3], float c[3]) {
  const Renderer::Impl& I = F.I;
  const float v = I.sample(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
  const float gval = Renderer::Impl::grey(v, F.wl);
  c[0] = c[1] = c[2] = gval;
  if (F.haveLabels)
    blendLabel(c, I.labelAt(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])), F.lop);
}

// Triplanar / Monoplanar: every plane hit in front of the overlay, nearest first. Where a plane
// shows nothing (grey below kPlaneClearGrey: air, background) it is nearly clear, so planes do
// not hide each other behind empty space; a single plane is always opaque.
void castPlanes(const CastFrame& F, const Ray& r, double tOverlay, Compositor& comp) {
  std::array<double, 3> hits{};
  size_t nHits = 0;
  const double limit = std::min(tOverlay, 1e300);
  for (size_t k = 0; k < F.planes.size(); ++k) {
    const int a = F.planes[k].first;
    if (std::abs(r.d3[a]) < 1e-15) continue;
    const double t = (F.planes[k].second - r.o3[a]) / r.d3[a];
    if (t <= 0 || t >= limit) continue;
    bool inside = true;
    for (int b = 0; b < 3; ++b)
      if (b != a) {
        const double q = r.o3[b] + t * r.d3[b];
        inside = inside && q >= F.volLo[b] - 1e-6 && q <= F.volHi[b] + 1e-6;
      }
    if (inside && nHits < hits.size()) {  // insert sorted (at most three)
      size_t h = nHits++;
      for (; h > 0 && hits[h - 1] > t; --h) hits[h] = hits[h - 1];
      hits[h] = t;
    }
  }
  for (size_t h = 0; h < nHits; ++h) {
    const double t = hits[h];
    const double p[3] = {r.o3[0] + t * r.d3[0], r.o3[1] + t * r.d3[1], r.o3[2] + t * r.d3[2]};
    float c[3];
    planeColour(F, p, c);
    const bool clear = nHits > 1 && std::max({c[0], c[1], c[2]}) < kPlaneClearGrey;
    comp.add(c, clear ? kPlaneClearOpacity : 1.f, t);
  }
}

// MIP: the largest sample along the ray, in grey through the window or through the TF.
// Overlays have no occlusion here: they are drawn on top (ovDepth is consumed).
template <class T>
void castMip(const CastFrame& F, const T* vox, const Ray& r, size_t pix, float& ovDepth, Compositor& comp,
             int64_t& samples) {
  const Renderer::Impl& I = F.I;
  const double dt = F.dt;
  float vmax = -kInf;
  double tmax = 0;
  double t0 = 0, t1 = 0;
  if (intersectBox(r.o3, r.d3, F.volLo, F.volHi, t0, t1) && t1 > 0) {
    t0 = std::max(t0, 0.0);
    const int64_t nsteps = static_cast<int64_t>(std::floor((t1 - t0) / dt));
    const double base[3] = {r.o3[0] + r.d3[0] * t0, r.o3[1] + r.d3[1] * t0, r.o3[2] + r.d3[2] * t0};
    const double step[3] = {r.d3[0] * dt, r.d3[1] * dt, r.d3[2] * dt};
    march(
        F, r, t0, nsteps, base, step, false, F.mipOn.data(), [&](size_t bi) { return I.coarse.mx[bi] > vmax; },
        [&](int64_t k, int ix, int iy, int iz, float fx, float fy, float fz) {
          ++samples;
          const float v = I.interpT(vox, ix + iy * I.sy + iz * I.sz, fx, fy, fz);
          if (v > vmax) vmax = v, tmax = t0 + double(k) * dt;
          return true;
        });
  }
  // Maxima at or below mipFloor map to black either way (the block test above skips them).
  if (vmax > -kInf && vmax > F.mipFloor) {
    if (F.o.mipTransferFunction) {
      const Rgba e = I.tf.evaluate(vmax);
      const float c[3] = {e.r, e.g, e.b};
      comp.add(c, e.a, tmax);
    } else {
      const float gv = Renderer::Impl::grey(vmax, F.wl);
      const float c[3] = {gv, gv, gv};
      comp.add(c, 1.f, tmax);
    }
  }
  if (ovDepth < kInf) {
    const auto& oc = F.ob->color[pix];
    comp.C[0] = oc[0], comp.C[1] = oc[1], comp.C[2] = oc[2], comp.A = 1;
    comp.depth = ovDepth;
    ovDepth = kInf;
  }
}

// Full / CutBox: front-to-back compositing of TF colour x opacity (labels blended in, Blinn-Phong
// with a headlight when shading) up to the overlay's depth; CutBox first shows the data on the
// box's entry face with faceOpacity.
template <class T>
void castVolume(const CastFrame& F, const T* vox, const Ray& r, double tOverlay, Compositor& comp, int64_t& samples) {
  const Renderer::Impl& I = F.I;
  const RenderOptions& o = F.o;
  const double dt = F.dt;
  double t0 = 0, t1 = 0;
  if (!(intersectBox(r.o3, r.d3, F.boxLo, F.boxHi, t0, t1) && t1 > 0 && t0 < tOverlay)) return;
  t0 = std::max(t0, 0.0);
  bool faceOnly = false;
  if (o.mode == RenderMode::CutBox && o.faceOpacity > 0) {
    const double p[3] = {r.o3[0] + t0 * r.d3[0], r.o3[1] + t0 * r.d3[1], r.o3[2] + t0 * r.d3[2]};
    float c[3];
    planeColour(F, p, c);
    comp.add(c, static_cast<float>(o.faceOpacity), t0);
    faceOnly = comp.A >= o.earlyTermination;
  }
  t1 = std::min(t1, tOverlay);
  // Headlight in the index-axes frame: L = -dir, half vector H = L.
  const Vec3 L = -(F.Dt * r.dw);
  const float lx = static_cast<float>(L.x()), ly = static_cast<float>(L.y()), lz = static_cast<float>(L.z());
  const float ka = static_cast<float>(o.ambient), kd = static_cast<float>(o.diffuse),
              ks = static_cast<float>(o.specular);
  const int64_t nsteps = faceOnly ? -1 : static_cast<int64_t>(std::floor((t1 - t0) / dt));
  const float term = static_cast<float>(o.earlyTermination);
  const double base[3] = {r.o3[0] + r.d3[0] * t0, r.o3[1] + r.d3[1] * t0, r.o3[2] + r.d3[2] * t0};
  const double step[3] = {r.d3[0] * dt, r.d3[1] * dt, r.d3[2] * dt};
  march(
      F, r, t0, nsteps, base, step, true, I.blockOn.data(), [](size_t) { return true; },
      [&](int64_t k, int ix, int iy, int iz, float fx, float fy, float fz) {
        ++samples;
        const int64_t cb = ix + iy * I.sy + iz * I.sz;
        const float v = I.interpT(vox, cb, fx, fy, fz);
        const Rgba& e = I.table(v);
        if (e.a <= 0.f) return true;
        float c[3] = {e.r, e.g, e.b};
        if (F.haveLabels)
          blendLabel(c,
                     I.labels[static_cast<size_t>((ix + (fx >= 0.5f)) + (iy + (fy >= 0.5f)) * I.sy +
                                                  (iz + (fz >= 0.5f)) * I.sz)],
                     F.lop);
        if (F.shade) {
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
        comp.add(c, e.a, t0 + double(k) * dt);
        return comp.A < term;
      });
}

// One pixel: the mode's cast, then the opaque overlay behind what was composited, then the
// background.
template <class T>
void castPixel(const CastFrame& F, const T* vox, int px, int py, RenderResult& res, int64_t& samples) {
  const Renderer::Impl& I = F.I;
  const size_t pix = static_cast<size_t>(py) * F.cf.width() + px;
  Ray r;
  Vec3 ow;
  F.cf.ray(px, py, ow, r.dw);
  r.cosf = r.dw.dot(F.cf.forward());
  const Vec3 oi = I.Minv * (ow - I.g.origin), di = I.Minv * r.dw;
  r.o3[0] = oi.x(), r.o3[1] = oi.y(), r.o3[2] = oi.z();
  r.d3[0] = di.x(), r.d3[1] = di.y(), r.d3[2] = di.z();
  for (int a = 0; a < 3; ++a) r.inv3[a] = std::abs(r.d3[a]) > 1e-15 ? 1.0 / r.d3[a] : 0.0;
  float ovDepth = F.ob ? F.ob->depth[pix] : kInf;
  const double tOverlay = ovDepth < kInf ? ovDepth / r.cosf : 1e300;
  Compositor comp;
  comp.cosf = r.cosf;
  comp.depthThreshold = F.o.depthThreshold;
  if (!F.planes.empty())
    castPlanes(F, r, tOverlay, comp);
  else if (F.o.mode == RenderMode::Mip)
    castMip(F, vox, r, pix, ovDepth, comp, samples);
  else
    castVolume(F, vox, r, tOverlay, comp, samples);
  if (ovDepth < kInf && comp.A < 1.f) {  // opaque overlay behind what was composited so far
    const auto& oc = F.ob->color[pix];
    const float c[3] = {oc[0], oc[1], oc[2]};
    const float before = comp.A;
    comp.add(c, 1.f, ovDepth / r.cosf);
    if (comp.depth == kInf || before < F.o.depthThreshold) comp.depth = std::min(comp.depth, ovDepth);
  }
  uint8_t* out = res.image.at(px, py);
  for (int q = 0; q < 3; ++q) {
    const float v = comp.C[q] + (1 - comp.A) * F.bg[q];
    out[q] = static_cast<uint8_t>(std::lrint(std::clamp(v, 0.f, 1.f) * 255.f));
  }
  out[3] = 255;
  res.depth[pix] = comp.depth;
}

template <class T>
int64_t castTiles(const CastFrame& F, const T* vox, RenderResult& res, Progress& progress) {
  const int width = F.cf.width(), height = F.cf.height();
  const int tilesX = (width + kTile - 1) / kTile, tilesY = (height + kTile - 1) / kTile;
  const int64_t ntiles = int64_t(tilesX) * tilesY;
  std::atomic<int64_t> nextTile{0};
  std::atomic<int64_t> sampleCount{0};
  const int workers = std::max(1, std::min<int>(workerCount(), static_cast<int>(ntiles)));
  parallelFor(0, workers, [&](int64_t, int64_t) {
    int64_t localSamples = 0;
    for (;;) {
      const int64_t tile = nextTile.fetch_add(1);
      if (tile >= ntiles) break;
      progress.check();
      const int tx = static_cast<int>(tile % tilesX) * kTile, ty = static_cast<int>(tile / tilesX) * kTile;
      for (int py = ty; py < std::min(height, ty + kTile); ++py)
        for (int px = tx; px < std::min(width, tx + kTile); ++px) castPixel(F, vox, px, py, res, localSamples);
    }
    sampleCount += localSamples;
  });
  return sampleCount.load();
}

}  // namespace

CastFrame::CastFrame(const Renderer::Impl& impl, const CameraFrame& camera, const OverlayBuffer* overlays)
    : I(impl), o(impl.opt), cf(camera), ob(overlays) {
  dt = I.stepMm();
  wl = I.window();
  shade = o.shading && I.gradReady && (o.mode == RenderMode::Full || o.mode == RenderMode::CutBox);
  haveLabels = !I.labels.empty();
  lop = static_cast<float>(o.labelOpacity);
  const double hi[3] = {double(I.nx - 1), double(I.ny - 1), double(I.nz - 1)};
  for (int a = 0; a < 3; ++a) {
    volLo[a] = boxLo[a] = 0;
    volHi[a] = boxHi[a] = hi[a];
  }
  const bool wholeBox =
      o.box[3] == -1 && o.box[4] == -1 && o.box[5] == -1 && o.box[0] == 0 && o.box[1] == 0 && o.box[2] == 0;
  if (o.mode == RenderMode::CutBox && !wholeBox)
    for (int a = 0; a < 3; ++a) {
      boxLo[a] = std::clamp(o.box[static_cast<size_t>(a)], volLo[a], volHi[a]);
      boxHi[a] = std::clamp(o.box[static_cast<size_t>(a) + 3], volLo[a], volHi[a]);
    }
  if (o.mode == RenderMode::Triplanar)
    for (int a = 0; a < 3; ++a) planes.push_back({a, o.planes[a] >= 0 ? o.planes[a] : std::floor(volHi[a] / 2)});
  if (o.mode == RenderMode::Monoplanar)
    planes.push_back({o.planeAxis, o.planeIndex >= 0 ? o.planeIndex : std::floor(volHi[o.planeAxis] / 2)});
  maxC[0] = std::max(0, I.nx - 2), maxC[1] = std::max(0, I.ny - 2), maxC[2] = std::max(0, I.nz - 2);
  Dt = I.D.transpose();
  for (int q = 0; q < 3; ++q) bg[q] = o.background[static_cast<size_t>(q)];
  mipFloor = static_cast<float>(o.mipTransferFunction ? I.tf.opaqueRange().first : wl.level - 0.5 * wl.window);
  if (o.mode == RenderMode::Mip) {
    mipOn.resize(I.coarse.mx.size());
    for (size_t i = 0; i < mipOn.size(); ++i) mipOn[i] = I.coarse.mx[i] > mipFloor ? 1 : 0;
  }
}

int64_t castImage(const CastFrame& frame, RenderResult& res, Progress& progress) {
  return frame.I.is8 ? castTiles(frame, frame.I.v8.data(), res, progress)
                     : castTiles(frame, frame.I.v16.data(), res, progress);
}

}  // namespace vs
