// The lumen model's upper edge (auto_cost.h; docs/notes/tracking.md session 15 bone1): values far beyond the
// lumen (bright: bone, calcium, metal) and the partial-volume shell around them are not lumen.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
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
// Both neighbourhood readings are separable (an OR and a minimum): each slice is filtered along x, then y, into a ring
// of three slices per thread, then along z - a few branch-free passes per voxel (session 47 speed2: the per-voxel
// 27-neighbour loop was most of this). The least lumen-beyond value is a minimum of keys: the value (dark: negated,
// so "least" is a minimum either way), NaN as +inf (it was skipped: never the least); a NaN voxel is in no shell.
std::vector<uint8_t> upperShell(const VolumeF32& sm, const LumenEstimate& e) {
  const bool bright = e.polarity == TubePolarity::Bright;
  const float hi = static_cast<float>(e.upperHi), bg = static_cast<float>(bright ? e.windowLo : e.windowHi);
  const float bgKey = bright ? bg : -bg, none = std::numeric_limits<float>::infinity();
  const Geometry& g = sm.geometry();
  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2], slice = nx * ny;
  std::vector<uint8_t> out(static_cast<size_t>(g.voxelCount()));
  const float* v = sm.data();
  auto beyond = [bright, hi](float w) { return bright ? w > hi : w < hi; };
  auto key = [bright, none](float w) { return std::isnan(w) ? none : bright ? w : -w; };
  auto least = [](float a, float b) { return b < a ? b : a; };
  parallelFor(
      0, nz,
      [&](int64_t z0, int64_t z1) {
        // One row padded by a neutral column each side; the slice filtered along x; rings of three slices filtered
        // along x and y (slice z at z % 3).
        std::vector<uint8_t> padB(static_cast<size_t>(nx + 2), 0), xB(static_cast<size_t>(slice)),
            ringB(static_cast<size_t>(3 * slice));
        std::vector<float> padK(static_cast<size_t>(nx + 2), none), xK(static_cast<size_t>(slice)),
            ringK(static_cast<size_t>(3 * slice));
        auto filterSlice = [&](int64_t z) {
          const float* s = v + z * slice;
          for (int64_t y = 0; y < ny; ++y) {
            const float* r = s + y * nx;
            for (int64_t x = 0; x < nx; ++x) {
              padB[static_cast<size_t>(x + 1)] = beyond(r[x]);
              padK[static_cast<size_t>(x + 1)] = key(r[x]);
            }
            uint8_t* tb = xB.data() + y * nx;
            float* tk = xK.data() + y * nx;
            for (int64_t x = 0; x < nx; ++x) {
              const size_t p = static_cast<size_t>(x);
              tb[x] = static_cast<uint8_t>(padB[p] | padB[p + 1] | padB[p + 2]);
              tk[x] = least(least(padK[p], padK[p + 1]), padK[p + 2]);
            }
          }
          uint8_t* ob = ringB.data() + (z % 3) * slice;
          float* ok = ringK.data() + (z % 3) * slice;
          for (int64_t y = 0; y < ny; ++y) {
            // A missing row is the row itself (OR and minimum take it twice: the face cuts the neighbourhood).
            const int64_t lo = (y > 0 ? y - 1 : y) * nx, mid = y * nx, up = (y + 1 < ny ? y + 1 : y) * nx;
            for (int64_t x = 0; x < nx; ++x) {
              ob[mid + x] = static_cast<uint8_t>(xB[static_cast<size_t>(lo + x)] | xB[static_cast<size_t>(mid + x)] |
                                                 xB[static_cast<size_t>(up + x)]);
              ok[mid + x] = least(least(xK[static_cast<size_t>(lo + x)], xK[static_cast<size_t>(mid + x)]),
                                  xK[static_cast<size_t>(up + x)]);
            }
          }
        };
        if (z0 > 0) filterSlice(z0 - 1);
        filterSlice(z0);
        for (int64_t z = z0; z < z1; ++z) {
          if (z + 1 < nz) filterSlice(z + 1);
          const int64_t mid = (z % 3) * slice, lo = z > 0 ? ((z + 2) % 3) * slice : mid,
                        up = z + 1 < nz ? ((z + 1) % 3) * slice : mid;
          const uint8_t *bLo = ringB.data() + lo, *bMid = ringB.data() + mid, *bUp = ringB.data() + up;
          const float *kLo = ringK.data() + lo, *kMid = ringK.data() + mid, *kUp = ringK.data() + up;
          const float* own = v + z * slice;
          uint8_t* o = out.data() + z * slice;
          for (int64_t k = 0; k < slice; ++k) {
            const bool beside = (bLo[k] | bMid[k] | bUp[k]) != 0;
            // A value beyond the edge tests beyond it either way (its neighbourhood's extreme is further).
            const bool background = least(least(kLo[k], kMid[k]), kUp[k]) < bgKey;
            o[k] = static_cast<uint8_t>(beside & !beyond(own[k]) & !std::isnan(own[k]) & background);
          }
        }
      },
      4);
  return out;
}

}  // namespace vs
