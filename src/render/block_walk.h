// Ray traversal of the ray caster's block grid (empty-space skipping): the ray/box clip and an
// incremental 3D DDA (Amanatides & Woo) over blocks of 2^shift trilinear cells, in index space.
// Internal to the render module; header-only so the per-ray calls inline into the cast loops.
// Thread safety: plain values, one walk per ray.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace vs {

// Ray o + t d against the axis-aligned box [lo, hi]; false on a miss, else the parameter interval
// [t0, t1] (unclipped at 0).
inline bool intersectBox(const double o[3], const double d[3], const double lo[3], const double hi[3], double& t0,
                         double& t1) {
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

// The block grid: bx * by * bz blocks of 2^shift cells per axis, x fastest.
struct BlockGridShape {
  int shift = 2;
  int bx = 1, by = 1, bz = 1;
};

// One block crossed by a ray: flat block index, block coordinates, entry/exit times (32.32
// fixed point, relative to the ray's start).
struct BlockSpan {
  int64_t Tin, Tout, bi;
  int bx, by, bz;
};

// Incremental 3D DDA over a block grid with integer (32.32 fixed-point) crossing times. next()
// appends the spans of the blocks whose on[] byte is non-zero, in ray order, until `cap` spans
// are collected or the end time TB is reached. The axis choice and the append use masks, not
// branches: the walk over mostly empty blocks has no data-dependent branch to mispredict. The
// walk never leaves the grid: TB is lowered to the first grid-exit crossing.
struct BlockWalk {
  int64_t T[3], dT[3];  // next crossing time per axis, increment per block
  int64_t TB = 0;       // end time
  int64_t Tin = 0;      // entry time of the current block
  int64_t bi = 0;       // current flat block index
  int64_t bstep[3];     // flat index change per axis step
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

// Walks the blocks crossed by the ray o + t d (index space; inv[a] = 1 / d[a], 0 where |d[a]| is
// negligible) from parameter tA to tB, calling visit(blockIndex, bx, by, bz, tIn, tOut) for each block
// whose on[] byte is set, in order; stops early when visit returns false. The first block gets
// exactly tA and the last exactly tB; interior boundaries are shared by the two blocks they
// separate, so the samples of [tA, tB] are partitioned exactly.
template <class Visit>
inline void walkBlocks(const BlockGridShape& G, const double o[3], const double d[3], const double inv[3], double tA,
                       double tB, const uint8_t* on, Visit&& visit) {
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
    const double p = o[a] + d[a] * tp;
    w.b[a] = std::clamp(static_cast<int>(std::floor(p / B)), 0, nb[a] - 1);
    int64_t crossings = 0;  // until the walk would leave the grid along this axis
    if (inv[a] > 0) {
      w.stp[a] = 1;
      w.T[a] = fix(((w.b[a] + 1) * B - o[a]) * inv[a] - tA);
      w.dT[a] = fix(B * inv[a]);
      crossings = nb[a] - w.b[a];
    } else if (inv[a] < 0) {
      w.stp[a] = -1;
      w.T[a] = fix((w.b[a] * B - o[a]) * inv[a] - tA);
      w.dT[a] = fix(-B * inv[a]);
      crossings = w.b[a] + 1;
    } else {
      w.stp[a] = 0;
      w.T[a] = kNever;
      w.dT[a] = 0;
    }
    w.bstep[a] = w.stp[a] * stride[a];
    if (crossings > 0 && w.T[a] < kNever && double(w.T[a]) + double(crossings - 1) * double(w.dT[a]) < double(kNever))
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
}

}  // namespace vs
