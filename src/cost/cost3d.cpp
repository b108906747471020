#include "cost/cost3d.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>

#include "util/parallel.h"

namespace vs {

std::string costKindName(CostKind3D k) {
  switch (k) {
    case CostKind3D::Gradient:
      return "gradient";
    case CostKind3D::Vesselness:
      return "vesselness";
    case CostKind3D::Intensity:
      return "intensity";
    case CostKind3D::Given:
      return "given";
  }
  return "?";
}

CostKind3D costKindFromName(const std::string& s) {
  if (s == "gradient") return CostKind3D::Gradient;
  if (s == "vesselness") return CostKind3D::Vesselness;
  if (s == "intensity") return CostKind3D::Intensity;
  if (s == "given") return CostKind3D::Given;
  throw InvalidArgument("unknown cost '" + s + "' (choose gradient, vesselness, intensity or given)");
}

GridCost NodeCost3D::gridCost() const {
  if (!sign.empty() && signWeight > 0)
    return GridCost::scissors(std::span<const float>(node), std::span<const uint8_t>(sign), nodeWeight, signWeight);
  GridCost g = GridCost::nodes(std::span<const float>(node));
  g.nodeWeight = nodeWeight;
  return g;
}

double NodeCost3D::minCostPerMm() const {
  float m = std::numeric_limits<float>::infinity();
  for (float c : node) m = std::min(m, c);
  return std::isfinite(m) ? nodeWeight * m : 0.0;
}

namespace {
std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

// x^p with multiplications for the small whole powers (the default 4 among them): std::pow was most of
// the intensity cost's time on a 1024^3 Dask pyramid, and q*q*q*q agrees with it to the float result.
double wholePower(double x, int p) {
  double r = 1.0, b = x;
  for (; p > 0; p >>= 1, b *= b)
    if (p & 1) r *= b;
  return r;
}

// c = eps + (1 - s)^p over s in [0,1] (the shape of the peers' costs.py).
void shapeCost(std::vector<float>& out, const std::vector<float>& s, double eps, double power) {
  const bool whole = power >= 1 && power <= 16 && power == std::floor(power);
  const int wholeP = whole ? static_cast<int>(power) : 0;
  parallelFor(
      0, static_cast<int64_t>(s.size()),
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          const double v = std::clamp(static_cast<double>(s[static_cast<size_t>(i)]), 0.0, 1.0);
          const double q = 1.0 - v;
          out[static_cast<size_t>(i)] = static_cast<float>(eps + (whole ? wholePower(q, wholeP) : std::pow(q, power)));
        }
      },
      1 << 16);
}
}  // namespace

std::vector<float> vesselnessCostOf(const std::vector<float>& response, double maxV, double epsilon, double power) {
  VS_REQUIRE(maxV > 0 && std::isfinite(maxV), "vesselness cost: maxV must be > 0");
  VS_REQUIRE(power > 0 && epsilon >= 0, "cost power must be > 0 and epsilon >= 0");
  std::vector<float> s(response.size()), out(response.size());
  for (size_t i = 0; i < response.size(); ++i) s[i] = static_cast<float>(response[i] / maxV);
  shapeCost(out, s, epsilon, power);
  return out;
}

NodeCost3D computeNodeCost3D(const VolumeF32& vol, const Cost3DOptions& opt, const Features3D* features,
                             Progress& progress) {
  VS_REQUIRE(!vol.empty(), "computeNodeCost3D: empty volume");
  VS_REQUIRE(opt.wg >= 0 && opt.wz >= 0 && std::isfinite(opt.wg) && std::isfinite(opt.wz),
             "cost weights w_g and w_z must be finite and >= 0");
  VS_REQUIRE(opt.power > 0 && opt.epsilon >= 0, "cost power must be > 0 and epsilon >= 0");
  NodeCost3D nc;
  nc.kind = opt.kind;
  nc.geometry = vol.geometry();
  const size_t N = static_cast<size_t>(vol.size());
  nc.node.assign(N, 0.0f);

  switch (opt.kind) {
    case CostKind3D::Given: {
      const float* v = vol.data();
      for (size_t i = 0; i < N; ++i) {
        if (std::isnan(v[i]) || v[i] < 0) {
          const Index3 p = vol.geometry().unlinear(static_cast<int64_t>(i));
          throw DataError("--cost given: voxel (" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," +
                          std::to_string(p[2]) + ") holds " + std::to_string(v[i]) +
                          "; node costs must be >= 0 (inf = impassable)");
        }
        nc.node[i] = v[i];
      }
      nc.description = "given node costs (edge = len * (c(u)+c(v))/2, scikit-image MCP_Geometric)";
      break;
    }
    case CostKind3D::Gradient: {
      Features3D local;
      const Features3D* f = features;
      if (!f || f->gradientMagnitude.size() != N || (opt.wz > 0 && !f->hasLaplacian())) {
        Features3DOptions fo;
        fo.laplacian = opt.wz > 0;
        fo.robustMaxPercentile = opt.robustMaxPercentile;
        local = computeFeatures3D(vol, fo, progress);
        f = &local;
      }
      const double maxG = f->robustMaxGradient;
      VS_REQUIRE(std::isfinite(opt.gradientFloor) && opt.gradientFloor >= 0,
                 "gradient cost floor must be finite and >= 0");
      for (size_t i = 0; i < N; ++i)
        nc.node[i] = static_cast<float>(opt.gradientFloor + 1.0 -
                                        std::min(static_cast<double>(f->gradientMagnitude[i]), maxG) / maxG);
      nc.nodeWeight = static_cast<float>(opt.wg);
      if (opt.wz > 0) {
        nc.sign.resize(N);
        for (size_t i = 0; i < N; ++i) nc.sign[i] = f->laplacian[i] > 0.0f ? 1 : 0;
        nc.signWeight = static_cast<float>(opt.wz);
      }
      nc.description = fmt("gradient (w_g %.3g, w_z %.3g, maxG = p%.4g of |grad| = %.4g", opt.wg, opt.wz,
                           opt.robustMaxPercentile, maxG) +
                       fmt(", floor %.3g)", opt.gradientFloor);
      break;
    }
    case CostKind3D::Vesselness: {
      VesselnessOptions vo = opt.vesselness;
      vo.polarity = opt.polarity;
      const std::vector<float> v = computeVesselness(vol, vo, progress);
      const double maxV = std::max(1e-12, static_cast<double>(percentileOf(v, opt.robustMaxPercentile, true)));
      nc.node = vesselnessCostOf(v, maxV, opt.epsilon, opt.power);
      nc.description = std::string("vesselness (") + (opt.polarity == TubePolarity::Bright ? "bright" : "dark") +
                       fmt(", maxV = p%.4g = %.4g, c = %.3g + (1 - V/maxV)^%.3g)", opt.robustMaxPercentile, maxV,
                           opt.epsilon, opt.power);
      break;
    }
    case CostKind3D::Intensity: {
      const VolumeF32 sm = opt.smoothMm > 0 ? gaussianSmooth3D(vol, opt.smoothMm, progress) : VolumeF32();
      const VolumeF32& src = opt.smoothMm > 0 ? sm : vol;
      requireFinite(AnyVolume(vol), "intensity cost input");
      double lo = opt.windowLo, hi = opt.windowHi;
      if (std::isnan(lo)) lo = percentileOf(src.voxels(), 1.0);
      if (std::isnan(hi)) hi = percentileOf(src.voxels(), 99.9);
      VS_REQUIRE(hi > lo,
                 "intensity cost: window hi (" + std::to_string(hi) + ") must exceed lo (" + std::to_string(lo) + ")");
      std::vector<float> s(N);
      const bool bright = opt.polarity == TubePolarity::Bright;
      for (size_t i = 0; i < N; ++i) {
        const double t = std::clamp((static_cast<double>(src.voxels()[i]) - lo) / (hi - lo), 0.0, 1.0);
        s[i] = static_cast<float>(bright ? t : 1.0 - t);
      }
      shapeCost(nc.node, s, opt.epsilon, opt.power);
      nc.description =
          std::string("intensity (") + (bright ? "bright" : "dark") +
          fmt(", window %.6g..%.6g, smooth %.3g mm, c = eps + (1-s)^%.3g)", lo, hi, opt.smoothMm, opt.power);
      break;
    }
  }
  progress.report(1.0, "cost");
  return nc;
}

}  // namespace vs
