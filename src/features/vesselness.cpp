#include "features/vesselness.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>

#include "util/parallel.h"
#include "util/text.h"

namespace vs {

namespace {

inline int64_t clampi(int64_t v, int64_t lo, int64_t hi) { return v < lo ? lo : (v > hi ? hi : v); }

// The largest smoothing scale that means anything: the volume's largest physical size (or
// three voxels for tiny volumes). Beyond it the result is flat, and a huge sigma overflowed
// the kernel radius or ran for minutes.
double maxSigmaMm(const Geometry& g) {
  double e = 3.0 * g.spacing.maxCoeff();
  for (int i = 0; i < 3; ++i) e = std::max(e, static_cast<double>(g.dims[i]) * g.spacing[i]);
  return e;
}

std::vector<float> gaussianKernel(double sigmaVox) {
  if (sigmaVox <= 1e-6) return {1.0f};
  const int r = std::max(1, static_cast<int>(std::ceil(3.0 * sigmaVox)));
  std::vector<float> k(static_cast<size_t>(2 * r + 1));
  double sum = 0;
  for (int i = -r; i <= r; ++i) {
    const double w = std::exp(-0.5 * (i * i) / (sigmaVox * sigmaVox));
    k[static_cast<size_t>(i + r)] = static_cast<float>(w);
    sum += w;
  }
  for (auto& w : k) w = static_cast<float>(w / sum);
  return k;
}

// Convolves along one axis (0, 1, 2) from src into dst, clamped borders. Each output is acc = 0, then acc += k[t] *
// sample for t = -r..r in order, in float; a row of outputs is formed tap by tap across the row (session 45 speedE:
// the same operations on each output in the same order, so the same bits, with no clamping per tap where the
// kernel lies inside the volume and the row's loop free to use the vector unit).
void convolveAxis(const float* src, float* dst, const Index3& dims, int axis, const std::vector<float>& k,
                  Progress& progress) {
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  const int64_t r = static_cast<int64_t>(k.size() / 2);
  const int64_t n = dims[static_cast<size_t>(axis)];
  const int64_t stride = axis == 0 ? 1 : (axis == 1 ? nx : nx * ny);
  parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
    std::vector<float> row(static_cast<size_t>(nx));
    float* acc = row.data();
    for (int64_t z = z0; z < z1; ++z) {
      progress.check();
      for (int64_t y = 0; y < ny; ++y) {
        const int64_t first = nx * (y + ny * z);  // the row's first voxel
        std::fill(row.begin(), row.end(), 0.0f);
        if (axis == 0) {
          // Outputs whose taps all lie in the row: x in [r, nx - 1 - r]; the others clamped, one by one.
          const int64_t lo = std::min(r, nx), hi = std::max(lo, nx - r);
          for (int64_t t = -r; t <= r; ++t) {
            const float kt = k[static_cast<size_t>(t + r)];
            for (int64_t x = lo; x < hi; ++x) acc[x] += kt * src[first + x + t];
          }
          for (int64_t x = 0; x < nx; ++x) {
            if (x >= lo && x < hi) continue;
            for (int64_t t = -r; t <= r; ++t)
              acc[x] += k[static_cast<size_t>(t + r)] * src[first + clampi(x + t, 0, n - 1)];
          }
        } else {
          // Every output of the row reads the same (clamped) line of the axis per tap.
          const int64_t pos = axis == 1 ? y : z, base = first - pos * stride;
          for (int64_t t = -r; t <= r; ++t) {
            const float kt = k[static_cast<size_t>(t + r)];
            const float* s = src + base + clampi(pos + t, 0, n - 1) * stride;
            for (int64_t x = 0; x < nx; ++x) acc[x] += kt * s[x];
          }
        }
        std::copy(row.begin(), row.end(), dst + first);
      }
    }
  });
}

}  // namespace

void symmetricEigenvalues3(double a, double b, double c, double d, double e, double f, double l[3]) {
  const double p1 = d * d + e * e + f * f;
  double e0, e1, e2;
  if (p1 <= 1e-300) {
    e0 = a, e1 = b, e2 = c;
  } else {
    const double q = (a + b + c) / 3.0;
    const double p2 = (a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2.0 * p1;
    const double p = std::sqrt(p2 / 6.0);
    const double b00 = (a - q) / p, b11 = (b - q) / p, b22 = (c - q) / p, b01 = d / p, b02 = e / p, b12 = f / p;
    const double det = b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02);
    const double r = std::clamp(det / 2.0, -1.0, 1.0);
    const double phi = std::acos(r) / 3.0;
    e0 = q + 2.0 * p * std::cos(phi);
    e2 = q + 2.0 * p * std::cos(phi + 2.0943951023931957);
    e1 = 3.0 * q - e0 - e2;
  }
  l[0] = e0, l[1] = e1, l[2] = e2;
  std::sort(l, l + 3, [](double u, double v) { return std::abs(u) < std::abs(v); });
}

VolumeF32 gaussianSmooth3D(const VolumeF32& vol, double sigmaMm, Progress& progress) {
  VS_REQUIRE(!vol.empty(), "gaussianSmooth3D: empty volume");
  VS_REQUIRE(sigmaMm >= 0 && std::isfinite(sigmaMm), "gaussianSmooth3D: sigma must be >= 0 mm");
  VS_REQUIRE(sigmaMm <= maxSigmaMm(vol.geometry()), "smoothing sigma " + numberText(sigmaMm) +
                                                        " mm is larger than the volume (" +
                                                        numberText(maxSigmaMm(vol.geometry())) + " mm)");
  const Geometry& g = vol.geometry();
  VolumeF32 a = vol, b(g);
  for (int axis = 0; axis < 3; ++axis) {
    if (g.dims[static_cast<size_t>(axis)] == 1) continue;
    const auto k = gaussianKernel(sigmaMm / g.spacing[axis]);
    if (k.size() == 1) continue;
    convolveAxis(a.data(), b.data(), g.dims, axis, k, progress);
    std::swap(a, b);
  }
  return a;
}

std::vector<double> vesselnessScales(const Geometry& g, const VesselnessOptions& opt) {
  std::vector<double> scales = opt.scalesMm;
  const double minSp = g.spacing.minCoeff();
  if (scales.empty()) scales = {1.0 * minSp, 2.0 * minSp, 3.0 * minSp};
  for (double s : scales)
    VS_REQUIRE(s > 0 && std::isfinite(s), "computeVesselness: scales must be > 0 mm, got " + std::to_string(s));
  for (double s : scales)
    VS_REQUIRE(s <= maxSigmaMm(g), "vesselness scale " + numberText(s) + " mm is larger than the volume (" +
                                       numberText(maxSigmaMm(g)) + " mm)");
  return scales;
}

int vesselnessHaloVoxels(const Geometry& g, const VesselnessOptions& opt) {
  size_t widest = 1;
  for (double s : vesselnessScales(g, opt))
    for (int axis = 0; axis < 3; ++axis) widest = std::max(widest, gaussianKernel(s / g.spacing[axis]).size());
  return static_cast<int>(widest / 2) + 1;
}

namespace {

// The scale-normalised Hessian of the smoothed volume L at (x, y, z): xx, yy, zz, xy, xz, yz.
struct HessianAt {
  const float* l;
  int64_t nx, ny, nz;
  double sx, sy, sz, norm;
  void operator()(int64_t x, int64_t y, int64_t z, double h[6]) const {
    const int64_t xm = clampi(x - 1, 0, nx - 1), xp = clampi(x + 1, 0, nx - 1);
    const int64_t ym = clampi(y - 1, 0, ny - 1), yp = clampi(y + 1, 0, ny - 1);
    const int64_t zm = clampi(z - 1, 0, nz - 1), zp = clampi(z + 1, 0, nz - 1);
    auto at = [&](int64_t X, int64_t Y, int64_t Z) { return static_cast<double>(l[X + nx * (Y + ny * Z)]); };
    const double c0 = at(x, y, z);
    h[0] = (at(xp, y, z) - 2 * c0 + at(xm, y, z)) / (sx * sx) * norm;
    h[1] = (at(x, yp, z) - 2 * c0 + at(x, ym, z)) / (sy * sy) * norm;
    h[2] = (at(x, y, zp) - 2 * c0 + at(x, y, zm)) / (sz * sz) * norm;
    h[3] = (at(xp, yp, z) - at(xp, ym, z) - at(xm, yp, z) + at(xm, ym, z)) / (4 * sx * sy) * norm;
    h[4] = (at(xp, y, zp) - at(xp, y, zm) - at(xm, y, zp) + at(xm, y, zm)) / (4 * sx * sz) * norm;
    h[5] = (at(x, yp, zp) - at(x, yp, zm) - at(x, ym, zp) + at(x, ym, zm)) / (4 * sy * sz) * norm;
  }
};

HessianAt hessianOf(const VolumeF32& L, double sigma) {
  const Geometry& g = L.geometry();
  return {L.data(), g.dims[0], g.dims[1], g.dims[2], g.spacing[0], g.spacing[1], g.spacing[2], sigma * sigma};
}

// Half the largest Frobenius norm of the Hessian over the box [lo, hi) (Frangi's rule for c).
double structureScale(const HessianAt& hessian, const Index3& lo, const Index3& hi) {
  std::vector<double> partial(static_cast<size_t>(hi[2] - lo[2]), 0.0);
  parallelFor(lo[2], hi[2], [&](int64_t z0, int64_t z1) {
    for (int64_t z = z0; z < z1; ++z) {
      double m = 0;
      double h[6];
      for (int64_t y = lo[1]; y < hi[1]; ++y)
        for (int64_t x = lo[0]; x < hi[0]; ++x) {
          hessian(x, y, z, h);
          m = std::max(m, h[0] * h[0] + h[1] * h[1] + h[2] * h[2] + 2 * (h[3] * h[3] + h[4] * h[4] + h[5] * h[5]));
        }
      partial[static_cast<size_t>(z - lo[2])] = m;
    }
  });
  return partial.empty() ? 0.0 : 0.5 * std::sqrt(*std::max_element(partial.begin(), partial.end()));
}

}  // namespace

std::vector<double> vesselnessStructureScale(const VolumeF32& vol, const VesselnessOptions& opt, const Index3& lo,
                                             const Index3& hiIn) {
  VS_REQUIRE(!vol.empty(), "vesselnessStructureScale: empty volume");
  requireFinite(AnyVolume(vol), "vesselness input");
  const Geometry& g = vol.geometry();
  const Index3 hi = hiIn == Index3{0, 0, 0} ? g.dims : hiIn;
  for (int a = 0; a < 3; ++a)
    VS_REQUIRE(0 <= lo[a] && lo[a] < hi[a] && hi[a] <= g.dims[a], "vesselnessStructureScale: box outside the volume");
  std::vector<double> c;
  for (double sigma : vesselnessScales(g, opt)) {
    const VolumeF32 L = gaussianSmooth3D(vol, sigma);
    c.push_back(structureScale(hessianOf(L, sigma), lo, hi));
  }
  return c;
}

std::vector<float> computeVesselness(const VolumeF32& vol, const VesselnessOptions& opt, Progress& progress) {
  VS_REQUIRE(!vol.empty(), "computeVesselness: empty volume");
  requireFinite(AnyVolume(vol), "computeVesselness input");
  const Geometry& g = vol.geometry();
  const std::vector<double> scales = vesselnessScales(g, opt);
  VS_REQUIRE(opt.alpha > 0 && opt.beta > 0 && opt.c >= 0, "computeVesselness: alpha, beta must be > 0 and c >= 0");
  VS_REQUIRE(opt.cPerScale.empty() || opt.cPerScale.size() == scales.size(),
             "computeVesselness: cPerScale needs one value per scale");
  for (double c : opt.cPerScale)
    VS_REQUIRE(c >= 0 && std::isfinite(c), "computeVesselness: cPerScale values must be finite and >= 0");

  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const int64_t N = g.voxelCount();
  std::vector<float> out(static_cast<size_t>(N), 0.0f);
  const bool bright = opt.polarity == TubePolarity::Bright;

  for (size_t si = 0; si < scales.size(); ++si) {
    const double sigma = scales[si];
    progress.report(static_cast<double>(si) / static_cast<double>(scales.size()), "vesselness");
    const VolumeF32 L = gaussianSmooth3D(vol, sigma, progress);
    const HessianAt hessian = hessianOf(L, sigma);
    double c = opt.cPerScale.empty() ? opt.c : opt.cPerScale[si];
    if (opt.cPerScale.empty() && c <= 0) c = structureScale(hessian, {0, 0, 0}, g.dims);
    if (!(c > 0)) continue;  // flat at this scale: no response
    const double a2 = 2 * opt.alpha * opt.alpha, b2 = 2 * opt.beta * opt.beta, c2 = 2 * c * c;
    parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
      double h[6], ev[3];
      for (int64_t z = z0; z < z1; ++z) {
        progress.check();
        for (int64_t y = 0; y < ny; ++y)
          for (int64_t x = 0; x < nx; ++x) {
            hessian(x, y, z, h);
            symmetricEigenvalues3(h[0], h[1], h[2], h[3], h[4], h[5], ev);
            const double l1 = ev[0], l2 = ev[1], l3 = ev[2];
            if (bright ? (l2 >= 0 || l3 >= 0) : (l2 <= 0 || l3 <= 0)) continue;
            const double ra2 = (l2 * l2) / (l3 * l3);
            const double rb2 = (l1 * l1) / std::abs(l2 * l3);
            const double s2 = l1 * l1 + l2 * l2 + l3 * l3;
            const double v = (1 - std::exp(-ra2 / a2)) * std::exp(-rb2 / b2) * (1 - std::exp(-s2 / c2));
            float& o = out[static_cast<size_t>(x + nx * (y + ny * z))];
            o = std::max(o, static_cast<float>(v));
          }
      }
    });
  }
  progress.report(1.0, "vesselness");
  return out;
}

}  // namespace vs
