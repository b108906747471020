#include "volume/ray_crossings.h"

#include "util/error.h"
#include "volume/sample.h"

namespace vs {

RayIsoCrossings rayIsoCrossings(const VolumeF32& volume, double iso, const Vec3& origin, const Vec3& direction,
                                double step, double maxLength, size_t maxCrossings) {
  VS_REQUIRE(step > 0, "ray walk: the step must be positive");
  const Geometry& g = volume.geometry();
  auto value = [&](const Vec3& p) { return sampleTrilinear(volume, g.worldToIndex(p)) - iso; };
  RayIsoCrossings r;
  double v = value(origin), t = step;
  r.startsAbove = v >= 0;
  for (; t < maxLength; t += step) {
    const Vec3 p = origin + t * direction;
    const Vec3 i = g.worldToIndex(p);
    bool outsideVolume = false;
    for (int k = 0; k < 3; ++k) outsideVolume = outsideVolume || i[k] < -0.5 || i[k] > double(g.dims[size_t(k)]) - 0.5;
    if (outsideVolume) break;
    const double w = sampleTrilinear(volume, i) - iso;
    if ((w >= 0) != (v >= 0)) {
      r.crossings.push_back({t - step * w / (w - v), w >= 0});
      if (r.crossings.size() >= maxCrossings) break;
    }
    v = w;
  }
  r.end = t;
  return r;
}

}  // namespace vs
