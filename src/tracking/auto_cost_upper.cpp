// The lumen model's upper edge (auto_cost.h; docs/notes/tracking.md session 15 bone1): values far beyond the
// lumen (bright: bone, calcium, metal) and the partial-volume shell around them are not lumen.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "tracking/auto_cost.h"
#include "util/parallel.h"

namespace vs {

namespace {
std::string upperFmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}
}  // namespace

double LumenEstimate::upperCap(double v) const {
  if (!hasUpperEdge()) return 1.0;
  return std::clamp((v - upperHi) / (upperLo - upperHi), 0.0, 1.0);  // both polarities (upperLo nearer to L)
}

// ", upper edge 149.4..162 (full lumen up to 1 contrast beyond the lumen, none from 1.5)".
std::string LumenEstimate::upperText() const {
  if (!hasUpperEdge()) return ", no upper edge";
  return upperFmt(polarity == TubePolarity::Bright ? ", upper edge %.6g..%.6g" : ", lower edge %.6g..%.6g", upperLo,
                  upperHi) +
         upperFmt(" (lumen up to %.3g contrasts beyond it, none from %.3g)", upperFraction, 1.5 * upperFraction);
}

// Per voxel 1 in the shell (see auto_cost.h), else 0: beside a value beyond the edge's far end (its 3x3x3
// neighbourhood, cut at the faces), not beyond it itself, its neighbourhood's least lumen-beyond value beyond the
// window on the background's side. The shell's test value, its neighbourhood's most lumen-beyond value, is beyond the
// far end (a neighbour's is), so the upper edge tests it as beyond: a byte says as much as that value did, and the
// volume's own values serve everywhere else (a float volume of test values was 4 x the memory and a serial copy:
// 13.6 % of the head CTA trace's page faults, docs/notes/tracking.md session 17 speed4).
// The beyond flags ORed along x and y per slice, into a ring of three slices per thread, then along z: one output
// byte per voxel and no other volume-sized buffer. A slice with no value beyond the far end in it or either slice
// beside it has no shell voxel: it is left 0 unread (session 47 speed2: the chest CTA and the aorta MRA have no such
// value in most or all of their slices; the flags cost more than the rest of the lumen model's pass over them).
std::vector<uint8_t> upperShell(const VolumeF32& sm, const LumenEstimate& e) {
  const bool bright = e.polarity == TubePolarity::Bright;
  const float hi = static_cast<float>(e.upperHi), bg = static_cast<float>(bright ? e.windowLo : e.windowHi);
  const Geometry& g = sm.geometry();
  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2], slice = nx * ny;
  std::vector<uint8_t> out(static_cast<size_t>(g.voxelCount()));
  const float* v = sm.data();
  auto beyond = [bright, hi](float w) { return bright ? w > hi : w < hi; };
  std::vector<uint8_t> sliceHas(static_cast<size_t>(nz));  // slice z holds a value beyond the far end
  parallelFor(
      0, nz,
      [&](int64_t z0, int64_t z1) {
        for (int64_t z = z0; z < z1; ++z) {
          const float* s = v + z * slice;
          int64_t n = 0;
          for (int64_t k = 0; k < slice; ++k) n += beyond(s[k]);
          sliceHas[static_cast<size_t>(z)] = n > 0;
        }
      },
      4);
  const auto needed = [&](int64_t z) {
    return sliceHas[static_cast<size_t>(z)] || (z > 0 && sliceHas[static_cast<size_t>(z - 1)]) ||
           (z + 1 < nz && sliceHas[static_cast<size_t>(z + 1)]);
  };
  parallelFor(
      0, nz,
      [&](int64_t z0, int64_t z1) {
        // xr: slice z's beyond flags ORed along x (padded by a zero column each side); ring[z % 3]: ORed along y too.
        std::vector<uint8_t> xr(static_cast<size_t>((nx + 2) * ny)), ring(static_cast<size_t>(3 * slice));
        auto orSlice = [&](int64_t z) {
          const float* s = v + z * slice;
          for (int64_t y = 0; y < ny; ++y) {
            uint8_t* t = xr.data() + y * (nx + 2);
            for (int64_t x = 0; x < nx; ++x) t[x + 1] = beyond(s[y * nx + x]);
            t[0] = 0;  // the left padding (the last row's result is left here)
            for (int64_t x = 0; x < nx; ++x) t[x] = static_cast<uint8_t>(t[x] | t[x + 1] | t[x + 2]);
          }
          // The x-ORed row y sits at xr + y * (nx + 2), its first nx bytes (the shift above left it there).
          uint8_t* o = ring.data() + (z % 3) * slice;
          for (int64_t y = 0; y < ny; ++y) {
            const uint8_t* mid = xr.data() + y * (nx + 2);
            const uint8_t* lo = y > 0 ? mid - (nx + 2) : nullptr;
            const uint8_t* up = y + 1 < ny ? mid + (nx + 2) : nullptr;
            uint8_t* t = o + y * nx;
            for (int64_t x = 0; x < nx; ++x) t[x] = static_cast<uint8_t>(mid[x] | (lo ? lo[x] : 0) | (up ? up[x] : 0));
          }
        };
        int64_t held[3] = {-1, -1, -1};  // the slice each ring entry holds
        const auto hold = [&](int64_t z) {
          if (z < 0 || z >= nz || held[z % 3] == z) return;
          orSlice(z);
          held[z % 3] = z;
        };
        for (int64_t z = z0; z < z1; ++z) {
          if (!needed(z)) continue;
          hold(z - 1);
          hold(z);
          hold(z + 1);
          const uint8_t* mid = ring.data() + (z % 3) * slice;
          const uint8_t* lo = z > 0 ? ring.data() + ((z + 2) % 3) * slice : nullptr;
          const uint8_t* up = z + 1 < nz ? ring.data() + ((z + 1) % 3) * slice : nullptr;
          uint8_t* o = out.data() + z * slice;
          for (int64_t y = 0; y < ny; ++y)
            for (int64_t x = 0; x < nx; ++x) {
              const int64_t k = y * nx + x, i = z * slice + k;
              const bool beside = mid[k] | (lo ? lo[k] : 0) | (up ? up[k] : 0);
              // A value beyond the edge tests beyond it either way (its neighbourhood's extreme is further).
              if (!beside || beyond(v[i])) {
                o[k] = 0;
                continue;
              }
              float least = v[i];
              for (int64_t dz = std::max<int64_t>(z - 1, 0); dz <= std::min(z + 1, nz - 1); ++dz)
                for (int64_t dy = std::max<int64_t>(y - 1, 0); dy <= std::min(y + 1, ny - 1); ++dy)
                  for (int64_t dx = std::max<int64_t>(x - 1, 0); dx <= std::min(x + 1, nx - 1); ++dx) {
                    const float w = v[g.linear(dx, dy, dz)];
                    least = bright ? std::min(least, w) : std::max(least, w);
                  }
              o[k] = bright ? least < bg : least > bg;
            }
        }
      },
      4);
  return out;
}

}  // namespace vs
