// Straight tube pieces (capsules) for the tracking tests' synthetic vessels, and the distance of a
// point to one of them or to a polyline of them (the truth the paths are checked against).
#pragma once

#include <algorithm>
#include <vector>

#include "phantom/phantom.h"
#include "volume/geometry.h"
#include "volume/volume.h"

namespace vs::test_tubes {

struct Segment {
  Vec3 a, b;
  double r;
};

inline double distanceToSegment(const Segment& s, const Vec3& p) {
  const Vec3 d = s.b - s.a;
  const double t = std::clamp((p - s.a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (p - (s.a + t * d)).norm();
}

inline double distanceToPolyline(const std::vector<Segment>& line, const Vec3& p) {
  double best = 1e300;
  for (const Segment& s : line) best = std::min(best, distanceToSegment(s, p));
  return best;
}

// Tubes (capsules) of `in` on `out`, with partial volume (4^3 samples per voxel near a wall) and Gaussian noise.
inline VolumeF32 drawTubes(const Index3& dims, const std::vector<Segment>& tubes, float in, float out, double noise,
                           uint64_t seed) {
  Geometry g;
  g.dims = dims;
  VolumeF32 v(g);
  PhantomRng rng(seed);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) {
        const Vec3 c(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z));
        double nearest = 1e300;
        for (const Segment& s : tubes) nearest = std::min(nearest, distanceToSegment(s, c) - s.r);
        double fill = 0;
        if (nearest < -1) {
          fill = 1;
        } else if (nearest < 1) {
          int hits = 0;
          for (int k = 0; k < 64; ++k) {
            const Vec3 q = c + Vec3((k % 4 - 1.5) / 4, (k / 4 % 4 - 1.5) / 4, (k / 16 - 1.5) / 4);
            for (const Segment& s : tubes)
              if (distanceToSegment(s, q) <= s.r) {
                ++hits;
                break;
              }
          }
          fill = hits / 64.0;
        }
        v(x, y, z) = static_cast<float>(out + fill * (in - out) + rng.normal(0, noise));
      }
  return v;
}

}  // namespace vs::test_tubes
