// Internal to the shortest-path engine: where a 3-D grid node's record lives. Node ids stay
// linear (x + nx*(y + ny*z)) everywhere (queue, back pointers, API); only the record array is
// stored in bricks of 8x8x8 records (8 KiB, x fastest inside a brick, bricks x, y, z order).
//
// Why (session 22, docs/notes/engine.md): with the row layout the 3x3x3 neighbourhood of a node
// spans 9 rows nx*16 B apart, so the search's wavefront touches 9 different 4 KiB pages per node
// and its lines are spread over the whole volume; at 256^3 (268 MB of records) the loop waits on
// memory. In bricks a neighbourhood lies in 1-8 bricks (mostly one or two), the wavefront's
// records share lines, pages and cache sets far better (simulated: several times fewer
// last-level and TLB misses), and nothing else changes: the same nodes are relaxed in the same
// order with the same float64 arithmetic, so every total and back pointer is bit-identical.
#pragma once

#include <cstdint>

namespace vs::engine {

// Exact division of a 32-bit value by a fixed divisor (multiply by a 64-bit reciprocal,
// Lemire et al. 2019: exact for every 32-bit numerator and divisor >= 2).
struct FastDiv {
  uint64_t m = 0;
  uint32_t d = 1;
  FastDiv() = default;
  explicit FastDiv(uint64_t divisor) : m(divisor >= 2 ? ~uint64_t(0) / divisor + 1 : 0), d(uint32_t(divisor)) {}
  uint32_t div(uint32_t v) const {
    if (d == 1) return v;
    return uint32_t((static_cast<unsigned __int128>(m) * v) >> 64);
  }
};

struct BrickLayout {
  static constexpr int kLog = 3;
  static constexpr int64_t kB = int64_t(1) << kLog;  // brick edge
  static constexpr int64_t kMask = kB - 1;
  static constexpr int64_t kRecs = kB * kB * kB;  // records per brick
  int64_t nx = 1, ny = 1, nz = 1;
  int64_t nbx = 1, nby = 1, nbz = 1;  // bricks per axis (dims rounded up)
  FastDiv divX, divXY;
  // Record-index step of +1 along an axis from the last record of a brick into the next brick
  // (the first record along that axis there); inside a brick the step is 1, kB, kB^2.
  int64_t crossX = 0, crossY = 0, crossZ = 0;

  BrickLayout() = default;
  BrickLayout(int64_t x, int64_t y, int64_t z)
      : nx(x),
        ny(y),
        nz(z),
        nbx((x + kMask) >> kLog),
        nby((y + kMask) >> kLog),
        nbz((z + kMask) >> kLog),
        divX(uint64_t(x)),
        divXY(uint64_t(x * y)) {
    crossX = kRecs - kMask;
    crossY = nbx * kRecs - kMask * kB;
    crossZ = nbx * nby * kRecs - kMask * kB * kB;
  }
  int64_t recordCount() const { return nbx * nby * nbz * kRecs; }
  int64_t slabRecords() const { return nbx * nby * kRecs; }  // one brick layer (kB slices)
  int64_t at(int64_t x, int64_t y, int64_t z) const {
    const int64_t brick = ((z >> kLog) * nby + (y >> kLog)) * nbx + (x >> kLog);
    return (brick << (3 * kLog)) | ((z & kMask) << (2 * kLog)) | ((y & kMask) << kLog) | (x & kMask);
  }
  uint32_t zOf(uint32_t v) const { return divXY.div(v); }
  int64_t of(uint32_t v) const {
    const uint32_t z = divXY.div(v);
    const uint32_t r = v - z * uint32_t(nx * ny);
    const uint32_t y = divX.div(r);
    return at(int64_t(r - y * uint32_t(nx)), int64_t(y), int64_t(z));
  }
  // Record-index offsets of the neighbours at d = -1, 0, +1 along each axis from record index r
  // (its position inside the brick decides whether a step crosses into the next brick).
  struct Steps {
    int64_t x[3], y[3], z[3];
  };
  Steps steps(int64_t r) const {
    const int64_t lx = r & kMask, ly = (r >> kLog) & kMask, lz = (r >> (2 * kLog)) & kMask;
    Steps s;
    s.x[0] = lx == 0 ? -crossX : -1;
    s.x[1] = 0;
    s.x[2] = lx == kMask ? crossX : 1;
    s.y[0] = ly == 0 ? -crossY : -kB;
    s.y[1] = 0;
    s.y[2] = ly == kMask ? crossY : kB;
    s.z[0] = lz == 0 ? -crossZ : -kB * kB;
    s.z[1] = 0;
    s.z[2] = lz == kMask ? crossZ : kB * kB;
    return s;
  }
};

// The neighbour directions of connectivity K in the engine's order (dz slowest, dy, dx fastest;
// GridGraph's order), as compile-time constants for the unrolled relaxation.
struct Dir3 {
  int x, y, z;
};
template <int K>
struct Directions {
  Dir3 d[K > 0 ? K : 1]{};
  constexpr Directions() {
    const int maxNonZero = (K == 4 || K == 6) ? 1 : (K == 18 ? 2 : 3);
    const bool twoD = K == 4 || K == 8;
    int k = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nzero = (dx != 0) + (dy != 0) + (dz != 0);
          if (nzero == 0 || nzero > maxNonZero || (twoD && dz != 0)) continue;
          d[k++] = {dx, dy, dz};
        }
  }
};

}  // namespace vs::engine
