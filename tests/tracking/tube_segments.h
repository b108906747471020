// Straight tube pieces (capsules) for the tracking tests' synthetic vessels, and the distance of a
// point to one of them or to a polyline of them (the truth the paths are checked against).
#pragma once

#include <algorithm>
#include <vector>

#include "volume/geometry.h"

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

}  // namespace vs::test_tubes
