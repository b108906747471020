#include "features/features2d.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "util/error.h"

namespace vs {

std::string describeSlice(int axis, int64_t index) {
  std::string s = "slice ";
  s += (axis >= 0 && axis <= 2) ? "xyz"[axis] : '?';
  return s + "=" + std::to_string(index);
}

float Features2D::magnitudeQuantile(double q) const {
  if (magnitude.empty()) return 0.0f;
  q = std::clamp(q, 0.0, 1.0);
  std::vector<float> m(magnitude);
  const auto k = static_cast<size_t>(std::llround(q * static_cast<double>(m.size() - 1)));
  std::nth_element(m.begin(), m.begin() + static_cast<std::ptrdiff_t>(k), m.end());
  return m[k];
}

namespace {

// Separable Gaussian blur along one axis with replicated borders, sigma in pixels.
void blurAxis(std::vector<float>& img, int64_t w, int64_t h, double sigmaPx, bool alongU) {
  if (sigmaPx <= 0) return;
  const int r = static_cast<int>(std::ceil(3.0 * sigmaPx));
  if (r <= 0) return;
  std::vector<float> k(static_cast<size_t>(2 * r + 1));
  double sum = 0;
  for (int i = -r; i <= r; ++i) {
    const double v = std::exp(-0.5 * i * i / (sigmaPx * sigmaPx));
    k[static_cast<size_t>(i + r)] = static_cast<float>(v);
    sum += v;
  }
  for (auto& v : k) v = static_cast<float>(v / sum);
  const int64_t n = alongU ? w : h, lines = alongU ? h : w;
  std::vector<float> line(static_cast<size_t>(n));
  for (int64_t l = 0; l < lines; ++l) {
    auto at = [&](int64_t i) -> float& { return alongU ? img[static_cast<size_t>(i + w * l)] : img[static_cast<size_t>(l + w * i)]; };
    for (int64_t i = 0; i < n; ++i) line[static_cast<size_t>(i)] = at(i);
    for (int64_t i = 0; i < n; ++i) {
      double acc = 0;
      for (int j = -r; j <= r; ++j) {
        const int64_t s = std::clamp<int64_t>(i + j, 0, n - 1);
        acc += static_cast<double>(k[static_cast<size_t>(j + r)]) * line[static_cast<size_t>(s)];
      }
      at(i) = static_cast<float>(acc);
    }
  }
}

}  // namespace

template <class T>
Features2D computeFeatures2D(const SliceView<T>& slice, const Features2DOptions& options, const std::string& what) {
  VS_REQUIRE(slice.base != nullptr && slice.width > 0 && slice.height > 0, "computeFeatures2D: empty slice view");
  VS_REQUIRE(std::isfinite(options.smoothSigmaMm) && options.smoothSigmaMm >= 0,
             "computeFeatures2D: smoothing sigma must be a finite number >= 0 mm");
  VS_REQUIRE(slice.spacingU > 0 && slice.spacingV > 0, "computeFeatures2D: pixel spacing must be > 0");
  const std::string name = what.empty() ? describeSlice(slice.axis, slice.index) : what;

  Features2D f;
  const int64_t w = slice.width, h = slice.height, n = w * h;
  f.width = w;
  f.height = h;
  f.spacingU = slice.spacingU;
  f.spacingV = slice.spacingV;
  f.smoothed.resize(static_cast<size_t>(n));
  int64_t bad = 0, firstBad = -1;
  for (int64_t v = 0; v < h; ++v)
    for (int64_t u = 0; u < w; ++u) {
      const float x = static_cast<float>(slice(u, v));
      if (!std::isfinite(x)) {
        if (firstBad < 0) firstBad = u + w * v;
        ++bad;
      }
      f.smoothed[static_cast<size_t>(u + w * v)] = x;
    }
  if (bad > 0) {
    std::ostringstream os;
    os << name << " contains " << bad << " non-finite pixel" << (bad > 1 ? "s" : "") << " (NaN or inf), first at u="
       << firstBad % w << ", v=" << firstBad / w << "; the live-wire cost is undefined there";
    throw DataError(os.str());
  }
  if (options.smoothSigmaMm > 0) {
    blurAxis(f.smoothed, w, h, options.smoothSigmaMm / slice.spacingU, true);
    blurAxis(f.smoothed, w, h, options.smoothSigmaMm / slice.spacingV, false);
  }

  const auto& I = f.smoothed;
  f.gradU.assign(static_cast<size_t>(n), 0.0f);
  f.gradV.assign(static_cast<size_t>(n), 0.0f);
  f.magnitude.assign(static_cast<size_t>(n), 0.0f);
  f.laplacian.assign(static_cast<size_t>(n), 0.0f);
  f.zeroCrossing.assign(static_cast<size_t>(n), 0);
  const double su = slice.spacingU, sv = slice.spacingV;
  float gmax = 0;
  for (int64_t v = 0; v < h; ++v) {
    for (int64_t u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(u + w * v);
      const int64_t um = u > 0 ? u - 1 : u, up = u + 1 < w ? u + 1 : u;
      const int64_t vm = v > 0 ? v - 1 : v, vp = v + 1 < h ? v + 1 : v;
      const double c = I[i];
      const double iu0 = I[static_cast<size_t>(um + w * v)], iu1 = I[static_cast<size_t>(up + w * v)];
      const double iv0 = I[static_cast<size_t>(u + w * vm)], iv1 = I[static_cast<size_t>(u + w * vp)];
      const double gu = up > um ? (iu1 - iu0) / (static_cast<double>(up - um) * su) : 0.0;
      const double gv = vp > vm ? (iv1 - iv0) / (static_cast<double>(vp - vm) * sv) : 0.0;
      f.gradU[i] = static_cast<float>(gu);
      f.gradV[i] = static_cast<float>(gv);
      const float m = static_cast<float>(std::sqrt(gu * gu + gv * gv));
      f.magnitude[i] = m;
      gmax = std::max(gmax, m);
      // Replicated border: the missing neighbour equals the centre.
      const double lu = (iu0 - 2 * c + iu1) / (su * su);
      const double lv = (iv0 - 2 * c + iv1) / (sv * sv);
      f.laplacian[i] = static_cast<float>(lu + lv);
    }
  }
  f.maxMagnitude = gmax;

  // Zero crossings: of two 4-neighbours with Laplacians of opposite sign, the one closer
  // to zero is marked (both on a tie); a pixel with Laplacian exactly 0 is marked when it
  // has both a positive and a negative 4-neighbour.
  const auto& L = f.laplacian;
  for (int64_t v = 0; v < h; ++v) {
    for (int64_t u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(u + w * v);
      const float a = L[i];
      auto pairWith = [&](size_t j) {
        const float b = L[j];
        if ((a > 0 && b < 0) || (a < 0 && b > 0)) {
          const float fa = std::fabs(a), fb = std::fabs(b);
          if (fa <= fb) f.zeroCrossing[i] = 1;
          if (fb <= fa) f.zeroCrossing[j] = 1;
        }
      };
      if (u + 1 < w) pairWith(i + 1);
      if (v + 1 < h) pairWith(i + static_cast<size_t>(w));
      if (a == 0) {
        bool pos = false, neg = false;
        auto see = [&](int64_t uu, int64_t vv) {
          if (uu < 0 || vv < 0 || uu >= w || vv >= h) return;
          const float b = L[static_cast<size_t>(uu + w * vv)];
          pos |= b > 0;
          neg |= b < 0;
        };
        see(u - 1, v), see(u + 1, v), see(u, v - 1), see(u, v + 1);
        if (pos && neg) f.zeroCrossing[i] = 1;
      }
    }
  }
  return f;
}

Features2D computeFeatures2D(const AnyVolume& image2d, const Features2DOptions& options) {
  return std::visit(
      [&](const auto& vol) -> Features2D {
        VS_REQUIRE(vol.dims()[2] == 1, "computeFeatures2D: expected a 2D image (dims.z == 1), got " +
                                           vol.geometry().describe());
        return computeFeatures2D(sliceView(vol, 2, 0), options, "image");
      },
      image2d);
}

template Features2D computeFeatures2D(const SliceView<uint8_t>&, const Features2DOptions&, const std::string&);
template Features2D computeFeatures2D(const SliceView<int16_t>&, const Features2DOptions&, const std::string&);
template Features2D computeFeatures2D(const SliceView<uint16_t>&, const Features2DOptions&, const std::string&);
template Features2D computeFeatures2D(const SliceView<float>&, const Features2DOptions&, const std::string&);

}  // namespace vs
