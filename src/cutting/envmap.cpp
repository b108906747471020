#include "cutting/envmap.h"

#include <cmath>
#include <sstream>

#include "util/error.h"
#include "volume/ray_crossings.h"
#include "volume/sample.h"

namespace vs {

TriMesh envMapMesh(const VolumeF32& volume, const EnvMapOptions& o) {
  VS_REQUIRE(o.latitudes >= 4 && o.longitudes >= 8, "environment map: need >= 4 latitudes and >= 8 longitudes");
  const Geometry& g = volume.geometry();
  Vec3 center = Vec3::Zero();
  if (o.centerMm) {
    center = *o.centerMm;
  } else {
    Vec3 sum = Vec3::Zero();
    int64_t count = 0;
    for (int64_t z = 0; z < g.dims[2]; ++z)
      for (int64_t y = 0; y < g.dims[1]; ++y)
        for (int64_t x = 0; x < g.dims[0]; ++x)
          if (volume(x, y, z) >= o.iso) sum += Vec3(double(x), double(y), double(z)), ++count;
    if (count == 0) throw DataError("iso-value " + std::to_string(o.iso) + " gives no object voxel");
    center = g.indexToWorld(sum / double(count));
  }
  auto value = [&](const Vec3& p) { return sampleTrilinear(volume, g.worldToIndex(p)) - o.iso; };
  auto describe = [&](const Vec3& p) {
    const Vec3 i = g.worldToIndex(p);
    std::ostringstream s;
    s.precision(1);
    s << std::fixed << i.x() << "," << i.y() << "," << i.z();
    return s.str();
  };
  if (value(center) < 0)
    throw DataError("environment map: the centre (voxel " + describe(center) +
                    ") lies outside the object; the object is not star-shaped from it (use --mesh iso)");

  // Each ray is sampled at a quarter of the smallest spacing until it leaves the volume.
  const double step = 0.25 * g.spacing.minCoeff();
  const Vec3 extent = g.spacing.cwiseProduct(Vec3(double(g.dims[0]), double(g.dims[1]), double(g.dims[2])));
  const double longest = extent.norm() * 2;
  int64_t hidden = 0;
  std::optional<Vec3> firstHidden;
  auto castRay = [&](const Vec3& dir) {
    // The exit is the first crossing; a second one means the ray meets the object again.
    const RayIsoCrossings ray = rayIsoCrossings(volume, o.iso, center, dir, step, longest, 2);
    if (ray.crossings.size() > 1) {
      ++hidden;
      if (!firstHidden) firstHidden = center + ray.crossings[1].t * dir;
    }
    // Without a crossing the object reaches the volume's border.
    return Vec3(center + (ray.crossings.empty() ? ray.end : ray.crossings[0].t) * dir);
  };
  TriMesh mesh;
  const int rows = o.latitudes, cols = o.longitudes;
  mesh.positions.push_back(castRay(Vec3(0, 0, 1)));
  for (int r = 1; r < rows; ++r) {
    const double theta = M_PI * r / rows;
    for (int c = 0; c < cols; ++c) {
      const double phi = 2 * M_PI * c / cols;
      mesh.positions.push_back(
          castRay(Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta))));
    }
  }
  mesh.positions.push_back(castRay(Vec3(0, 0, -1)));
  if (hidden > 0) {
    std::ostringstream msg;
    msg << "environment map: the object is not star-shaped from the centre (voxel " << describe(center)
        << "): " << hidden << " of " << mesh.positions.size() << " rays leave it and meet it again (first at voxel "
        << describe(*firstHidden) << "); use --mesh iso";
    throw DataError(msg.str());
  }
  // Row r (1..rows-1), column c -> vertex 1 + (r-1)*cols + c; poles 0 and last. Counter-clockwise
  // seen from outside: increasing phi then increasing theta.
  const int32_t south = int32_t(mesh.positions.size() - 1);
  auto at = [&](int r, int c) { return int32_t(1 + (r - 1) * cols + (c % cols)); };
  for (int c = 0; c < cols; ++c) {
    mesh.triangles.push_back({0, at(1, c), at(1, c + 1)});
    for (int r = 1; r + 1 < rows; ++r) {
      mesh.triangles.push_back({at(r, c), at(r + 1, c), at(r + 1, c + 1)});
      mesh.triangles.push_back({at(r, c), at(r + 1, c + 1), at(r, c + 1)});
    }
    mesh.triangles.push_back({at(rows - 1, c), south, at(rows - 1, c + 1)});
  }
  return mesh;
}

}  // namespace vs
