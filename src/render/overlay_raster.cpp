#include "render/overlay_raster.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace vs {

void rasteriseOverlays(const CameraFrame& cf, const std::vector<MeshOverlay>& meshes,
                       const std::vector<LineOverlay>& lineSets, OverlayBuffer& ob) {
  const int W = cf.width(), H = cf.height();
  auto plot = [&](int x, int y, float z, const std::array<float, 3>& c, float shade) {
    const size_t i = static_cast<size_t>(y) * W + x;
    if (z < ob.depth[i] && z > 0) {
      ob.depth[i] = z;
      ob.color[i] = {c[0] * shade, c[1] * shade, c[2] * shade};
    }
  };
  const bool persp = cf.camera().perspective;
  for (const auto& mo : meshes) {
    const auto& m = mo.mesh;
    const bool vn = m.normals.size() == m.positions.size();
    for (const auto& tri : m.triangles) {
      double sx[3], sy_[3], sz_[3];
      bool ok = true;
      for (int k = 0; k < 3; ++k)
        ok = ok && cf.project(m.positions[static_cast<size_t>(tri[k])], sx[k], sy_[k], sz_[k]);
      if (!ok) continue;
      const Vec3& p0 = m.positions[static_cast<size_t>(tri[0])];
      Vec3 fn = (m.positions[static_cast<size_t>(tri[1])] - p0).cross(m.positions[static_cast<size_t>(tri[2])] - p0);
      if (fn.norm() > 0) fn.normalize();
      const double area = (sx[1] - sx[0]) * (sy_[2] - sy_[0]) - (sx[2] - sx[0]) * (sy_[1] - sy_[0]);
      if (std::abs(area) < 1e-12) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({sx[0], sx[1], sx[2]}))));
      const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({sy_[0], sy_[1], sy_[2]}))));
      const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({sy_[0], sy_[1], sy_[2]}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const double px = x + 0.5, py = y + 0.5;
          double w0 = ((sx[1] - px) * (sy_[2] - py) - (sx[2] - px) * (sy_[1] - py)) / area;
          double w1 = ((sx[2] - px) * (sy_[0] - py) - (sx[0] - px) * (sy_[2] - py)) / area;
          double w2 = 1.0 - w0 - w1;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          double z;
          if (persp) {
            const double iz = w0 / sz_[0] + w1 / sz_[1] + w2 / sz_[2];
            const double b0 = w0 / sz_[0] / iz, b1 = w1 / sz_[1] / iz, b2 = w2 / sz_[2] / iz;
            z = 1.0 / iz;
            w0 = b0, w1 = b1, w2 = b2;
          } else {
            z = w0 * sz_[0] + w1 * sz_[1] + w2 * sz_[2];
          }
          Vec3 n = fn;
          if (vn) {
            n = w0 * m.normals[static_cast<size_t>(tri[0])] + w1 * m.normals[static_cast<size_t>(tri[1])] +
                w2 * m.normals[static_cast<size_t>(tri[2])];
            if (n.norm() > 0) n.normalize();
          }
          const float shade = static_cast<float>(0.25 + 0.75 * std::abs(n.dot(cf.forward())));
          plot(x, y, static_cast<float>(z), mo.color, shade);
        }
    }
  }
  for (const auto& lo : lineSets) {
    for (const auto& pl : lo.lines) {
      const size_t n = pl.points.size();
      const size_t segs = n < 2 ? n : (pl.closed ? n : n - 1);
      for (size_t s = 0; s < segs; ++s) {
        const size_t ia = s, ib = n < 2 ? s : (s + 1) % n;
        double ax, ay, az, bx_, by_, bz_;
        if (!cf.project(pl.points[ia], ax, ay, az) || !cf.project(pl.points[ib], bx_, by_, bz_)) continue;
        auto radiusPx = [&](size_t i, double z) {
          double r = lo.radius > 0 ? lo.radius : (pl.radii.size() == n ? pl.radii[i] : 0.0);
          const double px = r > 0 ? r / cf.pixelSizeAt(z) : 1.5;
          return std::max(px, 1.0);
        };
        const double ra = radiusPx(ia, az), rb = radiusPx(ib, bz_);
        const double rmax = std::max(ra, rb);
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min(ax, bx_) - rmax)));
        const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max(ax, bx_) + rmax)));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min(ay, by_) - rmax)));
        const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max(ay, by_) + rmax)));
        const double dx = bx_ - ax, dy = by_ - ay, len2 = dx * dx + dy * dy;
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            double t = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
            t = std::clamp(t, 0.0, 1.0);
            const double qx = ax + t * dx - px, qy = ay + t * dy - py;
            const double d = std::sqrt(qx * qx + qy * qy);
            const double r = ra + t * (rb - ra);
            if (d > r) continue;
            double z = persp ? 1.0 / ((1 - t) / az + t / bz_) : (1 - t) * az + t * bz_;
            const double bulge = std::sqrt(std::max(0.0, r * r - d * d));
            z -= bulge * cf.pixelSizeAt(z);  // front surface of the tube
            plot(x, y, static_cast<float>(z), lo.color, static_cast<float>(0.4 + 0.6 * bulge / r));
          }
      }
    }
  }
}

}  // namespace vs
