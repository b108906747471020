#include "volume/geometry.h"

#include <Eigen/LU>
#include <cmath>
#include <cstdio>

#include "util/error.h"

namespace vs {

bool Geometry::containsContinuous(const Vec3& i) const {
  for (int a = 0; a < 3; ++a)
    if (!(i[a] >= 0.0 && i[a] <= static_cast<double>(dims[a] - 1))) return false;
  return true;
}

Vec3 Geometry::indexToWorld(const Vec3& index) const { return origin + direction * spacing.cwiseProduct(index); }

Vec3 Geometry::worldToIndex(const Vec3& world) const {
  return (direction.inverse() * (world - origin)).cwiseQuotient(spacing);
}

double Geometry::stepLength(const Vec3& d) const { return spacing.cwiseProduct(d).norm(); }

void Geometry::validate() const {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1)
      throw InvalidArgument("volume dimension " + std::to_string(a) + " is " + std::to_string(dims[a]) +
                            " (must be >= 1)");
    if (!std::isfinite(spacing[a]) || spacing[a] <= 0.0)
      throw InvalidArgument("voxel spacing must be finite and > 0, got " + std::to_string(spacing[a]));
    if (!std::isfinite(origin[a])) throw InvalidArgument("volume origin is not finite");
  }
  if (!direction.allFinite() || std::abs(direction.determinant()) < 1e-6)
    throw InvalidArgument("direction matrix is not invertible");
}

std::string Geometry::describe() const {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%lldx%lldx%lld, %.4gx%.4gx%.4g mm", static_cast<long long>(dims[0]),
                static_cast<long long>(dims[1]), static_cast<long long>(dims[2]), spacing[0], spacing[1], spacing[2]);
  return buf;
}

Index3 roundIndex(const Vec3& c) {
  return {static_cast<int64_t>(std::lround(c[0])), static_cast<int64_t>(std::lround(c[1])),
          static_cast<int64_t>(std::lround(c[2]))};
}

bool Geometry::nearVolume(const Vec3& world) const {
  const Vec3 i = worldToIndex(world);
  for (int a = 0; a < 3; ++a)
    if (!(i[a] >= -1 && i[a] <= static_cast<double>(dims[static_cast<size_t>(a)]))) return false;
  return true;
}

}  // namespace vs
