#include "cutting/cutting_surface.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "cutting/mesh_livewire.h"
#include "features/features3d.h"
#include "util/error.h"
#include "volume/sample.h"

namespace vs {
namespace {

// One separable binomial [1 2 1]/4 pass per axis (clamped border): about a Gaussian of sigma 0.7
// voxel per pass, enough to keep noise gradients well below a real boundary's.
void binomialBlur(VolumeF32& v) {
  const Index3 d = v.dims();
  std::vector<float> line;
  for (int axis = 0; axis < 3; ++axis) {
    const int64_t n = d[size_t(axis)];
    if (n < 3) continue;
    const int64_t stride = axis == 0 ? 1 : (axis == 1 ? d[0] : d[0] * d[1]);
    line.resize(size_t(n));
    const int64_t o1 = axis == 0 ? d[1] : d[0], o2 = axis == 2 ? d[1] : d[2];
    for (int64_t b = 0; b < o2; ++b)
      for (int64_t a = 0; a < o1; ++a) {
        int64_t base;
        if (axis == 0)
          base = d[0] * (a + d[1] * b);
        else if (axis == 1)
          base = a + d[0] * d[1] * b;
        else
          base = a + d[0] * b;
        float* p = v.data() + base;
        for (int64_t i = 0; i < n; ++i) line[size_t(i)] = p[i * stride];
        for (int64_t i = 0; i < n; ++i) {
          const float l = line[size_t(std::max<int64_t>(i - 1, 0))], r = line[size_t(std::min(i + 1, n - 1))];
          p[i * stride] = 0.25f * l + 0.5f * line[size_t(i)] + 0.25f * r;
        }
      }
  }
}

// Sets `mask` to 1 within `radius` voxels (chessboard) of a voxel already set: separable max filter.
void dilateChessboard(std::vector<uint8_t>& mask, const Index3& d, int radius) {
  std::vector<uint8_t> line;
  for (int axis = 0; axis < 3; ++axis) {
    const int64_t n = d[size_t(axis)];
    const int64_t stride = axis == 0 ? 1 : (axis == 1 ? d[0] : d[0] * d[1]);
    const int64_t o1 = axis == 0 ? d[1] : d[0], o2 = axis == 2 ? d[1] : d[2];
    line.resize(size_t(n));
    for (int64_t b = 0; b < o2; ++b)
      for (int64_t a = 0; a < o1; ++a) {
        int64_t base;
        if (axis == 0)
          base = d[0] * (a + d[1] * b);
        else if (axis == 1)
          base = a + d[0] * d[1] * b;
        else
          base = a + d[0] * b;
        uint8_t* p = mask.data() + base;
        for (int64_t i = 0; i < n; ++i) line[size_t(i)] = p[i * stride];
        for (int64_t i = 0; i < n; ++i) {
          uint8_t m = 0;
          for (int64_t j = std::max<int64_t>(0, i - radius); j <= std::min(n - 1, i + radius) && !m; ++j)
            m = line[size_t(j)];
          p[i * stride] = m;
        }
      }
  }
}

// G on a box of the volume around the search region, ignoring the object's outer boundary.
struct GradientField {
  Geometry geometry;  // of the crop (world mapping of the full volume, shifted origin)
  std::vector<float> values;
  float contrast = 1;       // the object's outer boundary contrast: a high percentile of G before erosion
  double seamFraction = 1;  // of the contour points, those on a seam an interior edge starts from
  float sample(const Vec3& worldPoint) const {
    const Vec3 c = geometry.worldToIndex(worldPoint);
    const Index3& d = geometry.dims;
    int64_t i0[3];
    double f[3];
    for (int k = 0; k < 3; ++k) {
      if (!(c[k] >= 0 && c[k] <= double(d[size_t(k)] - 1))) return -1;  // outside the box: no candidate
      i0[k] = std::min<int64_t>(int64_t(c[k]), std::max<int64_t>(d[size_t(k)] - 2, 0));
      f[k] = c[k] - double(i0[k]);
    }
    double s = 0;
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
          if (w == 0) continue;
          s += w * values[size_t(geometry.linear(std::min(i0[0] + dx, d[0] - 1), std::min(i0[1] + dy, d[1] - 1),
                                                 std::min(i0[2] + dz, d[2] - 1)))];
        }
    return float(s);
  }
};

// The fraction of the contour points that lie on a seam: where an interior edge meets the outer
// surface, so that G stays high from the surface point inwards (along the image gradient) to
// `depthMm`, past the band near the outer boundary where G is ignored. Under a contour around a
// nose (the same tissue on both sides) G drops to noise below the skin before any deeper edge (the
// skull): that edge is not joined to the contour and the cutting surface must not dive onto it.
double seamFraction(const VolumeF32& volume, const GradientField& unblurred, const std::vector<Vec3>& contourMm,
                    double depthMm, double threshold) {
  const double step = 0.25 * volume.geometry().spacing.minCoeff();
  int64_t onSeam = 0;
  for (const Vec3& p : contourMm) {
    const Vec3 gradient = interpolatedGradient(volume, p);
    if (gradient.norm() <= 0) continue;
    const Vec3 inwards = gradient.normalized();
    double weakest = 1e300;
    for (double s = 0; s <= depthMm; s += step) weakest = std::min(weakest, double(unblurred.sample(p + s * inwards)));
    onSeam += weakest >= threshold * unblurred.contrast;
  }
  return double(onSeam) / double(contourMm.size());
}

GradientField gradientField(const VolumeF32& volume, double iso, const Index3& lo, const Index3& hi,
                            const std::vector<Vec3>& contourMm, const CuttingSurfaceOptions& o, Progress& progress) {
  const Geometry& g = volume.geometry();
  Geometry cg = g;
  for (int k = 0; k < 3; ++k) cg.dims[size_t(k)] = hi[size_t(k)] - lo[size_t(k)] + 1;
  cg.origin = g.indexToWorld(Vec3(double(lo[0]), double(lo[1]), double(lo[2])));
  VolumeF32 crop(cg);
  std::vector<uint8_t> nearOutside(size_t(cg.voxelCount()), 0);
  for (int64_t z = 0; z < cg.dims[2]; ++z)
    for (int64_t y = 0; y < cg.dims[1]; ++y)
      for (int64_t x = 0; x < cg.dims[0]; ++x) {
        const float v = volume(x + lo[0], y + lo[1], z + lo[2]);
        crop(x, y, z) = v;
        nearOutside[size_t(cg.linear(x, y, z))] = v < iso;
      }
  progress.check();
  Features3DOptions fo;
  fo.laplacian = false;
  // The seam test looks at the unblurred G: blurring would bridge the gap under a thin layer.
  GradientField unblurred{cg, computeFeatures3D(crop, fo, progress).gradientMagnitude, 1};
  unblurred.contrast = std::max(percentileOf(unblurred.values, 99.0, true), 1e-12f);
  const double seamDepthMm = (std::ceil(o.boundaryErosionVoxels) + 1) * g.spacing.maxCoeff();
  const double seam = seamFraction(volume, unblurred, contourMm, seamDepthMm, o.seamThreshold);
  const int blurPasses =
      int(std::lround(o.gradientBlurVoxels * o.gradientBlurVoxels / 0.5));  // sigma^2 adds 0.5 per pass
  for (int i = 0; i < blurPasses; ++i) binomialBlur(crop);
  Features3D features = computeFeatures3D(crop, fo, progress);
  // The crop holds the contour, so the object's outer boundary (the strongest edge near the cut)
  // sets the scale, measured at the same blur as the internal edges it is compared with.
  const float contrast = std::max(percentileOf(features.gradientMagnitude, 99.0, true), 1e-12f);
  dilateChessboard(nearOutside, cg.dims, int(std::ceil(o.boundaryErosionVoxels)));
  for (size_t i = 0; i < nearOutside.size(); ++i)
    if (nearOutside[i]) features.gradientMagnitude[i] = 0;
  return {cg, std::move(features.gradientMagnitude), contrast, seam};
}

// Depth (mm along `normal` from `base`) of the iso crossing nearest `nearT` within `reach` mm on
// the line through `base`: where the object's outer surface meets the line; `nearT` when none.
double outerSurfaceDepth(const VolumeF32& volume, double iso, const Vec3& base, const Vec3& normal, double nearT,
                         double reach, double step) {
  const Geometry& g = volume.geometry();
  auto above = [&](double t) { return sampleTrilinear(volume, g.worldToIndex(base + t * normal)) - iso; };
  double best = nearT, bestDistance = reach;
  double t0 = nearT - reach, v0 = above(t0);
  for (double t1 = t0 + step; t1 <= nearT + reach; t1 += step) {
    const double v1 = above(t1);
    if ((v0 < 0) != (v1 < 0)) {
      const double t = t0 + step * v0 / (v0 - v1);
      if (std::abs(t - nearT) < bestDistance) bestDistance = std::abs(t - nearT), best = t;
    }
    t0 = t1, v0 = v1;
  }
  return best;
}

// The depths over the inner pixels (ring >= 1) that minimise the summed squared Laplacian with
// ring 0 (the contour and the two-pixel rim beyond it) held at `depth`: a thin-plate fill that
// carries the rim's slope and curvature across the disc (a quadratic is reproduced exactly).
std::vector<double> thinPlateFill(const CuttingSurface& s, const std::vector<double>& depth) {
  const int64_t w = s.width;
  std::vector<int64_t> unknown(s.ring.size(), -1);
  int64_t count = 0;
  for (size_t k = 0; k < s.ring.size(); ++k)
    if (s.ring[k] >= 1) unknown[k] = count++;
  std::vector<double> filled = depth;
  if (count == 0) return filled;
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<double> rhs;
  for (int64_t y = 1; y + 1 < s.height; ++y)
    for (int64_t x = 1; x + 1 < w; ++x) {
      const int64_t stencil[5] = {y * w + x, y * w + x - 1, y * w + x + 1, (y - 1) * w + x, (y + 1) * w + x};
      bool inDomain = true, touchesUnknown = false;
      for (int64_t k : stencil) {
        inDomain = inDomain && s.ring[size_t(k)] >= 0;
        touchesUnknown = touchesUnknown || unknown[size_t(k)] >= 0;
      }
      if (!inDomain || !touchesUnknown) continue;
      const int64_t row = int64_t(rhs.size());
      double known = 0;
      for (int j = 0; j < 5; ++j) {
        const double c = j == 0 ? -4.0 : 1.0;
        const int64_t u = unknown[size_t(stencil[j])];
        if (u >= 0)
          entries.emplace_back(row, u, c);
        else
          known += c * depth[size_t(stencil[j])];
      }
      rhs.push_back(-known);
    }
  Eigen::SparseMatrix<double> A(int64_t(rhs.size()), count);
  A.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(Eigen::SparseMatrix<double>(A.transpose() * A));
  if (solver.info() != Eigen::Success) throw DataError("cutting surface: the contour's disc could not be spanned");
  const Eigen::VectorXd b = A.transpose() * Eigen::Map<const Eigen::VectorXd>(rhs.data(), int64_t(rhs.size()));
  const Eigen::VectorXd solution = solver.solve(b);
  for (size_t k = 0; k < s.ring.size(); ++k)
    if (unknown[k] >= 0) filled[k] = solution[unknown[k]];
  return filled;
}

// Distance (mm) from the point at `depth` on a pixel's projection line to the nearest point
// outside the object along that line, up to `limit`.
double distanceToOutside(const VolumeF32& volume, double iso, const CuttingSurface& s, int64_t x, int64_t y,
                         double depth, double limit) {
  const Geometry& g = volume.geometry();
  const Vec3 base = s.center + (s.u0 + double(x) * s.pixelMm) * s.axisU + (s.v0 + double(y) * s.pixelMm) * s.axisV;
  for (double d = 0; d < limit; d += 0.25 * s.pixelMm)
    for (double sign : {-1.0, 1.0})
      if (sampleTrilinear(volume, g.worldToIndex(base + (depth + sign * d) * s.normal)) < iso) return d;
  return limit;
}

// The object's outer surface around the contour as a quadratic height t(u, v) over the plane:
// least squares on its iso crossings along the projection lines 1-6 pixels outside the contour
// (`q`, `t`: the projected contour and its depths). False when too few crossings are found (the
// surface falls away steeply beyond the contour).
bool fitOuterSurface(const VolumeF32& volume, double iso, const CuttingSurface& s,
                     const std::vector<Eigen::Vector2d>& q, const std::vector<double>& t,
                     Eigen::Matrix<double, 6, 1>& c) {
  const size_t n = q.size();
  double orientation = 0;
  for (size_t i = 0; i < n; ++i) orientation += q[i].x() * q[(i + 1) % n].y() - q[(i + 1) % n].x() * q[i].y();
  std::vector<Eigen::Matrix<double, 6, 1>> rows;
  std::vector<double> depths;
  const double h = s.pixelMm;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d tangent = q[(i + 1) % n] - q[(i + n - 1) % n];
    if (tangent.norm() <= 0) continue;
    const Eigen::Vector2d out =
        (orientation > 0 ? 1.0 : -1.0) * Eigen::Vector2d(tangent.y(), -tangent.x()).normalized();
    for (int j = 1; j <= 6; ++j) {
      const Eigen::Vector2d p = q[i] + double(j) * h * out;
      const double reach = (double(j) + 2) * h;
      const double d =
          outerSurfaceDepth(volume, iso, s.center + p.x() * s.axisU + p.y() * s.axisV, s.normal, t[i], reach, 0.25 * h);
      if (std::abs(d - t[i]) >= reach || d == t[i]) continue;  // no crossing found
      Eigen::Matrix<double, 6, 1> row;
      row << 1, p.x(), p.y(), p.x() * p.x(), p.x() * p.y(), p.y() * p.y();
      rows.push_back(row);
      depths.push_back(d);
    }
  }
  // A quadratic from a thin annulus extrapolates wildly: the surface must be found across at
  // least half of the annulus' width on average (on a steep sphere beyond the contour it is not).
  if (rows.size() < 3 * n || rows.size() < 12) return false;
  Eigen::MatrixXd A(int64_t(rows.size()), 6);
  for (size_t r = 0; r < rows.size(); ++r) A.row(int64_t(r)) = rows[r].transpose();
  c = A.colPivHouseholderQr().solve(Eigen::Map<const Eigen::VectorXd>(depths.data(), int64_t(depths.size())));
  return true;
}

// The shape the cutting surface takes where the image has no contrast inside. Where the part
// stands out of the object's surface around the contour (a nose on a face), that surface's
// continuation under it (its quadratic fit; the ring sweep joins it to the contour): the cut
// keeps the face's own curvature. Where nothing stands out of the continuation (a cap of a plain sphere, whose
// continuation is the sphere itself), a membrane spanning the contour (the thin-plate fill of the
// contour's own depths).
std::vector<double> surfaceWithoutContrast(const VolumeF32& volume, double iso, const CuttingSurface& s,
                                           const std::vector<Eigen::Vector2d>& q, const std::vector<double>& t) {
  const std::vector<double> membrane = thinPlateFill(s, s.depth);
  Eigen::Matrix<double, 6, 1> c;
  if (!fitOuterSurface(volume, iso, s, q, t, c)) return membrane;
  const double h = s.pixelMm;
  auto quadric = [&](int64_t x, int64_t y) {
    const double u = s.u0 + double(x) * h, v = s.v0 + double(y) * h;
    return c[0] + c[1] * u + c[2] * v + c[3] * u * u + c[4] * u * v + c[5] * v * v;
  };
  std::vector<double> shape = membrane;
  for (int64_t y = 0; y < s.height; ++y)
    for (int64_t x = 0; x < s.width; ++x) {
      const size_t k = size_t(y * s.width + x);
      if (s.ring[k] < 1) continue;
      const double continuation = quadric(x, y);
      // Standing out: the continuation lies > 2 pixels deep inside the object (full weight from 5);
      // under a plain scalp it stays within the fit's error of the skin.
      const double inside = distanceToOutside(volume, iso, s, x, y, continuation, 5 * h);
      const double weight = std::clamp((inside - 2 * h) / (3 * h), 0.0, 1.0);
      shape[k] = membrane[k] + weight * (continuation - membrane[k]);
    }
  return shape;
}

}  // namespace

TriMesh CuttingSurface::mesh() const {
  TriMesh m;
  std::vector<int32_t> vertexOf(ring.size(), -1);
  for (int64_t y = 0; y < height; ++y)
    for (int64_t x = 0; x < width; ++x)
      if (inDomain(x, y)) {
        vertexOf[size_t(y * width + x)] = int32_t(m.positions.size());
        m.positions.push_back(point(x, y));
      }
  for (int64_t y = 0; y + 1 < height; ++y)
    for (int64_t x = 0; x + 1 < width; ++x) {
      const int32_t a = vertexOf[size_t(y * width + x)], b = vertexOf[size_t(y * width + x + 1)],
                    c = vertexOf[size_t((y + 1) * width + x + 1)], d = vertexOf[size_t((y + 1) * width + x)];
      const int n = (a >= 0) + (b >= 0) + (c >= 0) + (d >= 0);
      if (n == 4) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else if (n == 3) {
        std::array<int32_t, 3> t{};
        int k = 0;
        for (int32_t v : {a, b, c, d})
          if (v >= 0) t[size_t(k++)] = v;
        m.triangles.push_back(t);
      }
    }
  return m;
}

CuttingSurface buildCuttingSurface(const VolumeF32& volume, double iso, const std::vector<Vec3>& contour,
                                   const CuttingSurfaceOptions& o, Progress& progress) {
  VS_REQUIRE(contour.size() >= 3, "cutting surface: the contour needs at least 3 points");
  VS_REQUIRE(o.wg >= 0 && o.wc > 0, "cutting surface: w_g must be >= 0 and w_c > 0");
  VS_REQUIRE(o.pixelMm >= 0 && o.depthFactor >= 0 && o.rimPixels >= 1 && o.refinePasses >= 0 &&
                 o.gradientBlurVoxels >= 0 && o.boundaryErosionVoxels >= 0,
             "cutting surface: bad options");
  VS_REQUIRE(o.noiseFloor >= 0 && o.noiseFloor < 1, "cutting surface: the noise floor must be in [0, 1)");
  VS_REQUIRE(o.seamThreshold >= 0, "cutting surface: the seam threshold must be >= 0");
  const Geometry& g = volume.geometry();
  CuttingSurface s;
  const size_t n = contour.size();
  for (const Vec3& p : contour) s.center += p;
  s.center /= double(n);
  // The vector area: its direction is the normal of the plane of largest projected area, its
  // length that area (the projected area on a plane of unit normal m is A.m).
  Vec3 area = Vec3::Zero();
  double radius = 0;
  for (size_t i = 0; i < n; ++i) {
    area += 0.5 * (contour[i] - s.center).cross(contour[(i + 1) % n] - s.center);
    radius = std::max(radius, (contour[i] - s.center).norm());
  }
  const double h = o.pixelMm > 0 ? o.pixelMm : g.spacing.minCoeff();
  if (area.norm() < 2 * h * h) throw DataError("the contour encloses no area: it runs back and forth along one line");
  s.projectedAreaMm2 = area.norm();
  s.normal = area.normalized();
  s.axisU = s.normal.unitOrthogonal();
  s.axisV = s.normal.cross(s.axisU);
  s.pixelMm = h;

  std::vector<Eigen::Vector2d> q(n);
  std::vector<double> t(n);
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300, tmin = 1e300, tmax = -1e300;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 r = contour[i] - s.center;
    q[i] = {r.dot(s.axisU), r.dot(s.axisV)};
    t[i] = r.dot(s.normal);
    umin = std::min(umin, q[i].x()), umax = std::max(umax, q[i].x());
    vmin = std::min(vmin, q[i].y()), vmax = std::max(vmax, q[i].y());
    tmin = std::min(tmin, t[i]), tmax = std::max(tmax, t[i]);
  }
  const double margin = (o.rimPixels + 1) * h;
  s.u0 = umin - margin;
  s.v0 = vmin - margin;
  s.width = int64_t(std::ceil((umax - umin + 2 * margin) / h)) + 1;
  s.height = int64_t(std::ceil((vmax - vmin + 2 * margin) / h)) + 1;
  VS_REQUIRE(s.width * s.height < (int64_t(1) << 26), "cutting surface: the contour is too large for the grid");
  const size_t pixels = size_t(s.width * s.height);
  s.ring.assign(pixels, -1);
  s.depth.assign(pixels, std::numeric_limits<double>::quiet_NaN());

  // Ring 0: pixels on the projected contour and the rim beyond it take the depth of the nearest
  // contour point; inside pixels get their hop distance from ring 0 (eq. 14, Figure 15).
  std::vector<uint8_t> inside(pixels, 0);
  std::vector<int64_t> frontier;
  for (int64_t y = 0; y < s.height; ++y) {
    progress.check();
    for (int64_t x = 0; x < s.width; ++x) {
      const Eigen::Vector2d p(s.u0 + double(x) * h, s.v0 + double(y) * h);
      bool in = false;
      double best = 1e300, bestT = 0;
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector2d& a = q[i];
        const Eigen::Vector2d& b = q[(i + 1) % n];
        if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()))
          in = !in;
        const Eigen::Vector2d ab = b - a;
        const double len2 = ab.squaredNorm();
        const double f = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        const double d2 = (a + f * ab - p).squaredNorm();
        if (d2 < best) best = d2, bestT = t[i] + f * (t[(i + 1) % n] - t[i]);
      }
      const size_t k = size_t(y * s.width + x);
      const double dist = std::sqrt(best);
      inside[k] = in;
      if ((in && dist <= 0.75 * h) || (!in && dist <= o.rimPixels * h)) {
        s.ring[k] = 0;
        s.depth[k] = bestT;
        if (in) frontier.push_back(int64_t(k));
      }
    }
  }
  std::vector<std::vector<int64_t>> rings;
  while (!frontier.empty()) {
    std::vector<int64_t> next;
    for (int64_t k : frontier) {
      const int64_t x = k % s.width, y = k / s.width;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int64_t xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= s.width || yy >= s.height) continue;
          const size_t kk = size_t(yy * s.width + xx);
          if (inside[kk] && s.ring[kk] < 0) {
            s.ring[kk] = s.ring[size_t(k)] + 1;
            next.push_back(int64_t(kk));
          }
        }
    }
    if (!next.empty()) rings.push_back(next);
    frontier = std::move(next);
  }

  // Search range along the projection lines, and G on the box of voxels it covers.
  const double reach = o.depthFactor * radius;
  const double tLo = tmin - reach, tHi = tmax + reach;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (double tt : {tLo, tHi})
    for (double uu : {s.u0, s.u0 + double(s.width) * h})
      for (double vv : {s.v0, s.v0 + double(s.height) * h}) {
        const Vec3 c = g.worldToIndex(s.center + uu * s.axisU + vv * s.axisV + tt * s.normal);
        lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
      }
  Index3 ilo, ihi;
  for (int k = 0; k < 3; ++k) {
    ilo[size_t(k)] = std::clamp<int64_t>(int64_t(std::floor(lo[k])) - 3, 0, g.dims[size_t(k)] - 1);
    ihi[size_t(k)] = std::clamp<int64_t>(int64_t(std::ceil(hi[k])) + 3, 0, g.dims[size_t(k)] - 1);
  }
  const GradientField field = gradientField(volume, iso, ilo, ihi, contour, o, progress);
  s.seamFraction = field.seamFraction;
  // Interior edges count only where the contour traces a seam they start from: none when under a
  // fifth of its points lie on one (a contour around a nose), fully from half of them on.
  const double wg = o.wg * std::clamp((field.seamFraction - 0.2) / 0.3, 0.0, 1.0);

  // Continuity is measured after subtracting this shape, so without edges the surface takes it.
  const std::vector<double> shape = surfaceWithoutContrast(volume, iso, s, q, t);
  const double step = 0.25 * h;
  // The eq. 15 choice for one pixel given its neighbourhood A: the previous ring's decided pixels
  // within eps = 1.5 pixels (eq. 16) in the thesis's sweep, all decided 8-neighbours when refining.
  auto bestDepthAt = [&](int64_t k, bool allNeighbours) {
    const int64_t x = k % s.width, y = k / s.width;
    const int32_t previous = s.ring[size_t(k)] - 1;
    double inPlane2[8], depthOf[8];
    int count = 0;
    double mean = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int64_t xx = x + dx, yy = y + dy;
        if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= s.width || yy >= s.height) continue;
        const size_t kk = size_t(yy * s.width + xx);
        if (allNeighbours ? s.ring[kk] < 0 : s.ring[kk] != previous) continue;
        inPlane2[count] = double(dx * dx + dy * dy);
        depthOf[count] = s.depth[kk] - shape[kk];
        mean += depthOf[count];
        ++count;
      }
    mean = mean / count + shape[size_t(k)];  // count >= 1: a ring-k pixel was reached from a ring k-1 neighbour
    // S (eq. 18) as the RMS distance to A, in pixels (the thesis's sqrt(sum)/|A| would make the
    // surface stiffer where fewer neighbours are known), on depths relative to the shape without contrast.
    auto continuity = [&](double depth) {
      double sum = 0;
      for (int i = 0; i < count; ++i) {
        const double dt = (depthOf[i] - (depth - shape[size_t(k)])) / h;
        sum += inPlane2[i] + dt * dt;
      }
      return std::sqrt(sum / count);
    };
    // Beyond this distance from the mean depth the continuity cost alone exceeds any gain from G.
    const double window = h * (wg / o.wc + continuity(mean) + 1);
    const Vec3 base = s.center + (s.u0 + double(x) * h) * s.axisU + (s.v0 + double(y) * h) * s.axisV;
    double bestCost = o.wc * continuity(mean), bestDepth = mean;
    const double from = std::max(tLo, mean - window), to = std::min(tHi, mean + window);
    for (double d = from; d <= to; d += step) {
      const float G = field.sample(base + d * s.normal);
      if (G < 0) continue;
      const double edge = std::clamp((double(G) / field.contrast - o.noiseFloor) / (1 - o.noiseFloor), 0.0, 1.0);
      const double cost = -wg * edge + o.wc * continuity(d);
      if (cost < bestCost) bestCost = cost, bestDepth = d;
    }
    return bestDepth;
  };
  const int passes = int(rings.size()) + o.refinePasses;
  for (size_t r = 0; r < rings.size(); ++r) {
    progress.report(double(r) / double(passes), "cutting surface");
    std::vector<double> chosen(rings[r].size());
    for (size_t j = 0; j < rings[r].size(); ++j) chosen[j] = bestDepthAt(rings[r][j], false);
    // The ring is decided from the previous one only (the thesis's set G grows ring by ring).
    for (size_t j = 0; j < rings[r].size(); ++j) s.depth[size_t(rings[r][j])] = chosen[j];
  }
  // The sweep decides each pixel of a ring independently, so a pixel can stay behind while its
  // ring follows an edge; a few passes over every inner pixel with all its neighbours (iterated
  // conditional modes on the same cost) pull such stragglers onto the surface the others found.
  std::vector<double> next = s.depth;
  for (int pass = 0; pass < o.refinePasses; ++pass) {
    progress.report(double(rings.size() + size_t(pass)) / double(passes), "cutting surface");
    for (const auto& ring : rings)
      for (int64_t k : ring) next[size_t(k)] = bestDepthAt(k, true);
    s.depth = next;
  }
  // The rim beyond the contour goes onto the object's outer surface (where its projection line
  // meets it near the contour's depth), so the surface closes against the skin even where that
  // curves up beyond the contour (a loop in a hollow): no path runs around the rim's edge.
  for (int64_t y = 0; y < s.height; ++y)
    for (int64_t x = 0; x < s.width; ++x) {
      const size_t k = size_t(y * s.width + x);
      if (s.ring[k] != 0 || inside[k]) continue;
      const Vec3 base = s.center + (s.u0 + double(x) * h) * s.axisU + (s.v0 + double(y) * h) * s.axisV;
      s.depth[k] = outerSurfaceDepth(volume, iso, base, s.normal, s.depth[k], (o.rimPixels + 1) * h, 0.25 * h);
    }
  progress.report(1.0, "cutting surface");
  return s;
}

}  // namespace vs
