#include "cutting/cutting_surface.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "cutting/mesh_livewire.h"
#include "cutting/min_cut.h"
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

// Values on a box of voxels around the search region (the full volume's world mapping).
struct CropField {
  Geometry geometry;  // of the crop (world mapping of the full volume, shifted origin)
  std::vector<float> values;
  // Trilinear; NaN outside the box.
  float sample(const Vec3& worldPoint) const {
    const Vec3 c = geometry.worldToIndex(worldPoint);
    const Index3& d = geometry.dims;
    int64_t i0[3];
    double f[3];
    for (int k = 0; k < 3; ++k) {
      if (!(c[k] >= 0 && c[k] <= double(d[size_t(k)] - 1))) return std::numeric_limits<float>::quiet_NaN();
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

// What the cutting surface sees of the image around the cut.
struct EdgeField {
  CropField gradient;  // G of the smoothed volume x direction consistency, 0 near the object's outer boundary
  float contrast = 1;  // the object's outer boundary contrast: a high percentile of G before erosion
};

EdgeField edgeField(const VolumeF32& volume, double iso, const Index3& lo, const Index3& hi, const Vec3& normal,
                    const CuttingSurfaceOptions& o, Progress& progress) {
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
  const int blurPasses =
      int(std::lround(o.gradientBlurVoxels * o.gradientBlurVoxels / 0.5));  // sigma^2 adds 0.5 per pass
  for (int i = 0; i < blurPasses; ++i) binomialBlur(crop);
  Features3DOptions fo;
  fo.laplacian = false;
  Features3D features = computeFeatures3D(crop, fo, progress);
  // The crop holds the contour, so the object's outer boundary (the strongest edge near the cut)
  // sets the scale, measured at the same blur as the internal edges it is compared with.
  const float contrast = std::max(percentileOf(features.gradientMagnitude, 99.0, true), 1e-12f);
  dilateChessboard(nearOutside, cg.dims, int(std::ceil(o.boundaryErosionVoxels)));
  // Direction consistency (eq. 15-16): the height field can lie along an edge that faces the
  // projection direction; a wall parallel to it is only crossed.
  for (int64_t z = 0; z < cg.dims[2]; ++z)
    for (int64_t y = 0; y < cg.dims[1]; ++y)
      for (int64_t x = 0; x < cg.dims[0]; ++x) {
        const size_t i = size_t(cg.linear(x, y, z));
        if (nearOutside[i] || !(features.gradientMagnitude[i] > 0)) {
          features.gradientMagnitude[i] = 0;
          continue;
        }
        if (o.wd <= 0) continue;
        const Vec3 grad = cg.direction * centralGradient(crop, x, y, z);
        const double n = grad.norm();
        const double facing = n > 0 ? std::abs(grad.dot(normal)) / n : 0.0;
        features.gradientMagnitude[i] *= float(1 - o.wd + o.wd * facing);
      }
  return {{cg, std::move(features.gradientMagnitude)}, contrast};
}

// Where pixel (x, y)'s projection line crosses the plane (depth 0), world mm.
Vec3 lineBase(const CuttingSurface& s, int64_t x, int64_t y) {
  return s.center + (s.u0 + double(x) * s.pixelMm) * s.axisU + (s.v0 + double(y) * s.pixelMm) * s.axisV;
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

// The object's edge near an iso crossing at depth `tIso` on the line through `base`: where the
// values cross half-way between the outside (the lowest value within `window` mm on the side below
// iso) and the inside plateau (the highest within `window` on the other side), the physical
// boundary of a partial-volume ramp. The iso-value only says which voxels are the object; it need
// not be half-way (a head thresholded between air and fat puts the iso crossing a tenth of a voxel
// outside the skin). `tIso` when the half-way level is not crossed within the window.
double halfMaximumDepth(const VolumeF32& volume, const Vec3& base, const Vec3& normal, double tIso, double window,
                        double step) {
  const Geometry& g = volume.geometry();
  auto value = [&](double t) { return sampleTrilinear(volume, g.worldToIndex(base + t * normal)); };
  const double a = value(tIso - step), b = value(tIso + step);
  const double inward = b >= a ? 1.0 : -1.0;  // the object (values >= iso) lies this way along the line
  double outside = 1e300, inside = -1e300;
  for (double d = 0; d <= window; d += step) {
    outside = std::min(outside, value(tIso - inward * d));
    inside = std::max(inside, value(tIso + inward * d));
  }
  const double level = 0.5 * (outside + inside);
  double best = tIso, bestDistance = window;
  double t0 = tIso - window, v0 = value(t0) - level;
  for (double t1 = t0 + step; t1 <= tIso + window; t1 += step) {
    const double v1 = value(t1) - level;
    if ((v0 < 0) != (v1 < 0)) {
      const double t = t0 + step * v0 / (v0 - v1);
      if (std::abs(t - tIso) < bestDistance) bestDistance = std::abs(t - tIso), best = t;
    }
    t0 = t1, v0 = v1;
  }
  return best;
}

// How the pixels not held are filled in from the held ones.
enum class Fill {
  Membrane,   // minimum summed squared gradient: no overshoot, straight between held pixels
  ThinPlate,  // minimum summed squared Laplacian: carries slope and curvature (a quadratic exactly)
};

// The values over the domain's pixels not `held` that minimise the fill's energy with the held
// ones fixed (least squares on the energy's stencils). The thin plate with ring 0 held (the
// contour and the two-pixel rim beyond it) spans the contour, carrying the rim's slope inwards.
std::vector<double> smoothFill(const CuttingSurface& s, const std::vector<double>& depth,
                               const std::vector<uint8_t>& held, Fill fill) {
  const int64_t w = s.width;
  std::vector<int64_t> unknown(s.ring.size(), -1);
  int64_t count = 0;
  for (size_t k = 0; k < s.ring.size(); ++k)
    if (s.ring[k] >= 0 && !held[k]) unknown[k] = count++;
  std::vector<double> filled = depth;
  if (count == 0) return filled;
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<double> rhs;
  // One least-squares row per stencil that lies in the domain and touches an unknown pixel.
  auto addRow = [&](std::initializer_list<std::pair<int64_t, double>> stencil) {
    bool inDomain = true, touchesUnknown = false;
    for (const auto& [k, c] : stencil) {
      inDomain = inDomain && s.ring[size_t(k)] >= 0;
      touchesUnknown = touchesUnknown || unknown[size_t(k)] >= 0;
    }
    if (!inDomain || !touchesUnknown) return;
    const int64_t row = int64_t(rhs.size());
    double known = 0;
    for (const auto& [k, c] : stencil) {
      const int64_t u = unknown[size_t(k)];
      if (u >= 0)
        entries.emplace_back(row, u, c);
      else
        known += c * depth[size_t(k)];
    }
    rhs.push_back(-known);
  };
  for (int64_t y = 1; y + 1 < s.height; ++y)
    for (int64_t x = 1; x + 1 < w; ++x) {
      const int64_t k = y * w + x;
      if (fill == Fill::ThinPlate) {
        addRow({{k, -4.0}, {k - 1, 1.0}, {k + 1, 1.0}, {k - w, 1.0}, {k + w, 1.0}});
      } else {
        addRow({{k, -1.0}, {k + 1, 1.0}});
        addRow({{k, -1.0}, {k + w, 1.0}});
      }
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
  const Vec3 base = lineBase(s, x, y);
  for (double d = 0; d < limit; d += 0.25 * s.pixelMm)
    for (double sign : {-1.0, 1.0})
      if (sampleTrilinear(volume, g.worldToIndex(base + (depth + sign * d) * s.normal)) < iso) return d;
  return limit;
}

// The object's outer surface around the contour as a quadratic height t(u, v) over the plane:
// least squares on its edge (half maximum near each iso crossing) along the projection lines 1-6 pixels outside the
// contour
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
  // A partial-volume ramp spans at most a voxel: its plateaus lie within the largest spacing.
  const double edgeWindow = volume.geometry().spacing.maxCoeff();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d tangent = q[(i + 1) % n] - q[(i + n - 1) % n];
    if (tangent.norm() <= 0) continue;
    const Eigen::Vector2d out =
        (orientation > 0 ? 1.0 : -1.0) * Eigen::Vector2d(tangent.y(), -tangent.x()).normalized();
    for (int j = 1; j <= 6; ++j) {
      const Eigen::Vector2d p = q[i] + double(j) * h * out;
      const double reach = (double(j) + 2) * h;
      const Vec3 base = s.center + p.x() * s.axisU + p.y() * s.axisV;
      const double crossing = outerSurfaceDepth(volume, iso, base, s.normal, t[i], reach, 0.25 * h);
      if (std::abs(crossing - t[i]) >= reach || crossing == t[i]) continue;  // no crossing found
      // The continuation under the part is the physical surface (its edge), not the iso crossing.
      const double d = halfMaximumDepth(volume, base, s.normal, crossing, edgeWindow, 0.1 * h);
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
                                           const std::vector<Eigen::Vector2d>& q, const std::vector<double>& t,
                                           std::vector<double>& standingOut) {
  standingOut.assign(s.ring.size(), 0.0);
  std::vector<uint8_t> ringZero(s.ring.size());
  for (size_t k = 0; k < s.ring.size(); ++k) ringZero[k] = s.ring[k] == 0;
  const std::vector<double> membrane = smoothFill(s, s.depth, ringZero, Fill::ThinPlate);
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
      standingOut[k] = weight;
    }
  // The part term's weight is the part's, not the pixel's: how much of the disc the part stands
  // out over (the mean of the pixels' weights). Per pixel it would leave free the ring near the
  // contour, where a protrusion is thin over the continuation, and the cut would dig a trench there
  // down to the next edge (the skull under a nose).
  double sum = 0;
  int64_t count = 0;
  for (size_t k = 0; k < s.ring.size(); ++k)
    if (s.ring[k] >= 1) sum += standingOut[k], ++count;
  const double disc = count > 0 ? sum / double(count) : 0.0;
  for (size_t k = 0; k < s.ring.size(); ++k) standingOut[k] = s.ring[k] >= 0 ? disc : 0.0;
  return shape;
}

// Eq. 15 summed over the whole disc, minimised exactly rather than ring by ring: each pixel not
// `held` takes an offset from `shape` along its projection line, in steps within +-reach,
// minimising  sum_p -w_g E_p(offset_p) + sum_{p~q} w_pq |offset_p - offset_q| / pixel
//             + sum_p w_p out_p max(0, below_p(offset_p)) / pixel
// with the held pixels at offset 0 (out_p: how far the part stands out of the surrounding surface
// at p, below_p: depth below that surface's continuation, towards the rest of the object). S is the depth difference to
// the 8 neighbours (weights wc / (1 + sqrt 2) and that / sqrt 2 on the diagonals, so a slope costs wc per pixel in any
// direction). A greedy sweep cannot follow an interface that leaves the contour steeply: near the outer boundary G is
// ignored, and by the time the interface shows it lies several pixels deeper than the previous ring, a jump that no
// single pixel's edge pays for. The global optimum weighs the jump against the edge over the whole part. Ishikawa's
// construction (a chain of label nodes per pixel; linear pairwise terms are edges between equal labels) makes it a
// minimum cut, found with Boost's Boykov-Kolmogorov max-flow.
std::vector<double> optimalDepths(const CuttingSurface& s, const std::vector<uint8_t>& held,
                                  const std::vector<double>& shape, const std::vector<double>& standingOut,
                                  double inwards, const EdgeField& field, const CuttingSurfaceOptions& o, double reach,
                                  CuttingSurfaceEnergy& energy, Progress& progress) {
  std::vector<int64_t> pixels;
  std::vector<int64_t> inner(s.ring.size(), -1);
  for (size_t k = 0; k < s.ring.size(); ++k)
    if (s.ring[k] >= 0 && !held[k]) inner[k] = int64_t(pixels.size()), pixels.push_back(int64_t(k));
  std::vector<double> depth = shape;
  energy = {};
  energy.pixels = int64_t(pixels.size());
  if (pixels.empty()) return depth;
  // Offsets in steps of half a pixel, coarser when the graph would exceed ~150k label nodes (the
  // max-flow takes ~0.15 s for 40k on one core; the ridge search below restores the precision).
  const double h = s.pixelMm;
  const double step = std::max(0.5 * h, 2 * reach / (1.5e5 / double(pixels.size())));
  const int64_t half = std::max<int64_t>(1, int64_t(std::ceil(reach / step)));
  const int64_t labels = 2 * half + 1;
  const size_t n = pixels.size();
  auto node = [&](size_t pixel, int64_t label) { return 2 + pixel * size_t(labels - 1) + size_t(label - 1); };
  const double infinite = 1e30;
  const double w4 = o.wc / (1 + std::sqrt(2.0)) * step / h, wDiagonal = w4 / std::sqrt(2.0);
  MinCutNetwork graph(2 + n * size_t(labels - 1));
  graph.reserve(n * size_t(labels) * 5);
  std::vector<double> unary(static_cast<size_t>(labels));
  // Per pixel and label: E (eq. 15's image term) and the part term, kept for the energy report.
  std::vector<float> edges(n * size_t(labels)), parts(n * size_t(labels));
  for (size_t i = 0; i < n; ++i) {
    if (i % 256 == 0) progress.check();
    const int64_t k = pixels[i], x = k % s.width, y = k / s.width;
    const Vec3 base = lineBase(s, x, y);
    double strongest = 0;
    for (int64_t l = 0; l < labels; ++l) {
      const double offset = double(l - half) * step;
      const float G = field.gradient.sample(base + (shape[size_t(k)] + offset) * s.normal);
      const double edge =
          G >= 0 ? std::clamp((double(G) / field.contrast - o.noiseFloor) / (1 - o.noiseFloor), 0.0, 1.0) : 0.0;
      const double part = o.wp * standingOut[size_t(k)] * std::max(0.0, inwards * offset) / h;
      edges[i * size_t(labels) + size_t(l)] = float(edge);
      parts[i * size_t(labels) + size_t(l)] = float(part);
      unary[size_t(l)] = o.wg * (1 - edge) + part;  // -w_g E shifted to be >= 0 (a constant per pixel)
      strongest = std::max(strongest, edge);
    }
    energy.edgeWithinReach += strongest;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const size_t kk = size_t((y + dy) * s.width + x + dx);  // in the grid: it extends beyond the rim
        if (s.ring[kk] < 0) continue;
        const double w = dx != 0 && dy != 0 ? wDiagonal : w4;
        if (inner[kk] < 0) {  // a held pixel (offset 0): its term depends on this pixel only
          for (int64_t l = 0; l < labels; ++l) unary[size_t(l)] += w * double(std::abs(l - half));
        } else if (dy > 0 || (dy == 0 && dx > 0)) {  // each pair once
          for (int64_t l = 1; l < labels; ++l) graph.addEdgePair(node(i, l), node(size_t(inner[kk]), l), w, w);
        }
      }
    // The chain: cutting the edge after its l-th node gives the pixel label l; the infinite
    // reverse edges keep the source side a prefix, so each chain is cut exactly once.
    // A constant per pixel does not move the optimum: the chain's smallest capacity comes off every
    // link, so the max-flow need not saturate each chain's common part first.
    const double lowest = *std::min_element(unary.begin(), unary.end());
    for (double& u : unary) u -= lowest;
    graph.addEdgePair(0, node(i, 1), unary[0], 0);
    for (int64_t l = 1; l + 1 < labels; ++l) graph.addEdgePair(node(i, l), node(i, l + 1), unary[size_t(l)], infinite);
    graph.addEdgePair(node(i, labels - 1), 1, unary[size_t(labels - 1)], 0);
  }
  progress.check();
  graph.solve(0, 1);
  std::vector<double> offset(s.ring.size(), 0.0);  // from the shape; the held pixels at 0
  std::vector<uint8_t> onEdge(s.ring.size(), 0);
  std::vector<int64_t> labelOf(s.ring.size(), half);  // held pixels: offset 0
  for (size_t i = 0; i < n; ++i) {
    int64_t label = 0;  // the number of the chain's nodes on the source side (black)
    while (label + 1 < labels && graph.sourceSide(node(i, label + 1))) ++label;
    labelOf[size_t(pixels[i])] = label;
  }
  // The energy's terms at the optimum.
  int64_t edgePixels = 0;
  double standing = 0;
  for (size_t i = 0; i < n; ++i) {
    const int64_t k = pixels[i], x = k % s.width, y = k / s.width, l = labelOf[size_t(k)];
    const double edge = edges[i * size_t(labels) + size_t(l)];
    energy.image -= o.wg * edge;
    edgePixels += edge > 0;
    energy.part += parts[i * size_t(labels) + size_t(l)];
    standing += standingOut[size_t(k)];
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const size_t kk = size_t((y + dy) * s.width + x + dx);
        if (s.ring[kk] < 0 || (inner[kk] >= 0 && !(dy > 0 || (dy == 0 && dx > 0)))) continue;  // each pair once
        energy.continuity += (dx != 0 && dy != 0 ? wDiagonal : w4) * double(std::abs(l - labelOf[kk]));
      }
  }
  energy.edgeFraction = double(edgePixels) / double(n);
  energy.standingOut = standing / double(n);
  for (size_t i = 0; i < n; ++i) {
    const int64_t label = labelOf[size_t(pixels[i])];
    const int64_t k = pixels[i], x = k % s.width, y = k / s.width;
    const Vec3 base = lineBase(s, x, y);
    double best = shape[size_t(k)] + double(label - half) * step;
    // Where the surface lies on an edge, onto its ridge (the largest G within a pixel or a step):
    // the continuity term pulls it up the edge's smoothed flank towards the shape without contrast.
    // Only where the image term is on: with w_g = 0 the image must not move the surface at all (it
    // did, through this step, on pixels the shape happened to put on an edge).
    if (o.wg <= 0) continue;
    float ridge = field.gradient.sample(base + best * s.normal);
    if (!(ridge / field.contrast > o.noiseFloor)) continue;  // no edge here (or beyond the box)
    onEdge[size_t(k)] = 1;
    const double delta = 0.25 * h;
    const double range = std::max(h, step);
    for (double d = best - range, chosen = best; d <= chosen + range; d += delta) {
      const float G = field.gradient.sample(base + d * s.normal);
      if (G > ridge) ridge = G, best = d;
    }
    // The ridge between the samples: the vertex of the parabola through the largest and its two
    // neighbours.
    const double below = field.gradient.sample(base + (best - delta) * s.normal),
                 above = field.gradient.sample(base + (best + delta) * s.normal);
    const double curvature = below - 2 * double(ridge) + above;
    if (curvature < 0) best += std::clamp(0.5 * (below - above) / curvature, -0.5, 0.5) * delta;
    offset[size_t(k)] = best - shape[size_t(k)];
  }
  // Where the optimum lies on no edge (near the outer boundary, where G is ignored, or a gap in a
  // faint edge) the continuity term is indifferent between the many surfaces of equal total
  // variation: there the surface runs smoothly between the contour and the edges it found (a
  // membrane, which stays between the values it joins; a thin plate can overshoot them).
  for (size_t k = 0; k < s.ring.size(); ++k) onEdge[k] = onEdge[k] || held[k];
  offset = smoothFill(s, offset, onEdge, Fill::Membrane);
  for (int64_t k : pixels) depth[size_t(k)] = shape[size_t(k)] + offset[size_t(k)];
  return depth;
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
  VS_REQUIRE(o.pixelMm >= 0 && o.depthFactor > 0 && o.rimPixels >= 1 && o.gradientBlurVoxels >= 0 &&
                 o.boundaryErosionVoxels >= 0,
             "cutting surface: bad options");
  VS_REQUIRE(o.noiseFloor >= 0 && o.noiseFloor < 1, "cutting surface: the noise floor must be in [0, 1)");
  VS_REQUIRE(o.wp >= 0 && o.wd >= 0 && o.wd <= 1, "cutting surface: w_p must be >= 0 and w_d in [0, 1]");
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
  double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 r = contour[i] - s.center;
    q[i] = {r.dot(s.axisU), r.dot(s.axisV)};
    t[i] = r.dot(s.normal);
    umin = std::min(umin, q[i].x()), umax = std::max(umax, q[i].x());
    vmin = std::min(vmin, q[i].y()), vmax = std::max(vmax, q[i].y());
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
    frontier = std::move(next);
  }
  progress.report(0.1, "cutting surface");

  // Depths are chosen relative to this shape, so without edges the surface takes it.
  std::vector<double> standingOut;
  const std::vector<double> shape = surfaceWithoutContrast(volume, iso, s, q, t, standingOut);
  // Which way along the normal leads into the object at the contour (the image gradient points
  // from outside to inside there): below the continuation of the surrounding surface is that way.
  double facing = 0;
  for (const Vec3& p : contour) {
    const Vec3 grad = interpolatedGradient(volume, p);
    if (grad.norm() > 0) facing += grad.normalized().dot(s.normal);
  }
  const double inwards = facing >= 0 ? 1.0 : -1.0;
  progress.report(0.2, "cutting surface");
  // Search range along the projection lines (+-reach around the shape; a cap can be as deep as
  // the contour is wide), and G on the box of voxels it covers.
  const double reach = o.depthFactor * radius;
  double tLo = 1e300, tHi = -1e300;
  for (size_t k = 0; k < pixels; ++k)
    if (s.ring[k] >= 0) tLo = std::min(tLo, shape[k] - reach), tHi = std::max(tHi, shape[k] + reach);
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
  const EdgeField field = edgeField(volume, iso, ilo, ihi, s.normal, o, progress);
  progress.report(0.4, "cutting surface");
  // Held: the rim beyond the contour, at the contour's depth. Free: every pixel inside it, those on
  // the contour too, so that an interface leaving the contour steeply is followed from the start.
  std::vector<uint8_t> held(pixels);
  for (size_t k = 0; k < pixels; ++k) held[k] = s.ring[k] == 0 && !inside[k];
  s.depth = optimalDepths(s, held, shape, standingOut, inwards, field, o, reach, s.energy, progress);
  // The rim beyond the contour goes onto the object's outer surface (where its projection line
  // meets it near the contour's depth), so the surface closes against the skin even where that
  // curves up beyond the contour (a loop in a hollow): no path runs around the rim's edge.
  for (int64_t y = 0; y < s.height; ++y)
    for (int64_t x = 0; x < s.width; ++x) {
      const size_t k = size_t(y * s.width + x);
      if (s.ring[k] != 0 || inside[k]) continue;
      const Vec3 base = lineBase(s, x, y);
      s.depth[k] = outerSurfaceDepth(volume, iso, base, s.normal, s.depth[k], (o.rimPixels + 1) * h, 0.25 * h);
    }
  progress.report(1.0, "cutting surface");
  return s;
}

}  // namespace vs
