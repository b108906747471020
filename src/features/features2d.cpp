#include "features/features2d.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>
#include <type_traits>

#include "util/error.h"
#include "util/parallel.h"
#include "util/text.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// Normalised Gaussian kernel (float taps, normalised in double as before), radius ceil(3 sigma).
std::vector<float> gaussianKernel(double sigmaPx) {
  const int r = static_cast<int>(std::ceil(3.0 * sigmaPx));
  std::vector<float> k(static_cast<size_t>(2 * r + 1));
  double sum = 0;
  for (int i = -r; i <= r; ++i) {
    const double v = std::exp(-0.5 * i * i / (sigmaPx * sigmaPx));
    k[static_cast<size_t>(i + r)] = static_cast<float>(v);
    sum += v;
  }
  for (auto& v : k) v = static_cast<float>(v / sum);
  return k;
}

// Separable Gaussian blur with replicated borders, sigma in pixels per axis. Both passes are
// row-wise (cache friendly) and parallel over rows; every output is the double sum of
// k[j] * in[clamp(i + j)] over j ascending, as a straightforward convolution would give.
void blur(std::vector<float>& img, int64_t w, int64_t h, double sigmaU, double sigmaV) {
  std::vector<float> tmp(img.size());
  if (sigmaU > 0 && std::ceil(3.0 * sigmaU) > 0) {  // along u: img -> tmp
    const std::vector<float> k = gaussianKernel(sigmaU);
    const int64_t r = static_cast<int64_t>(k.size() / 2);
    parallelFor(
        0, h,
        [&](int64_t v0, int64_t v1) {
          std::vector<float> pad(static_cast<size_t>(w + 2 * r));
          std::vector<double> acc(static_cast<size_t>(w));
          for (int64_t v = v0; v < v1; ++v) {
            const float* src = img.data() + v * w;
            for (int64_t i = 0; i < w + 2 * r; ++i)
              pad[static_cast<size_t>(i)] = src[std::clamp<int64_t>(i - r, 0, w - 1)];
            std::fill(acc.begin(), acc.end(), 0.0);
            for (int64_t j = 0; j <= 2 * r; ++j) {
              const double kj = k[static_cast<size_t>(j)];
              const float* s = pad.data() + j;
              for (int64_t i = 0; i < w; ++i) acc[static_cast<size_t>(i)] += kj * s[i];
            }
            float* dst = tmp.data() + v * w;
            for (int64_t i = 0; i < w; ++i) dst[i] = static_cast<float>(acc[static_cast<size_t>(i)]);
          }
        },
        16);
  } else {
    tmp = img;
  }
  if (sigmaV > 0 && std::ceil(3.0 * sigmaV) > 0) {  // along v: tmp -> img
    const std::vector<float> k = gaussianKernel(sigmaV);
    const int64_t r = static_cast<int64_t>(k.size() / 2);
    parallelFor(
        0, h,
        [&](int64_t v0, int64_t v1) {
          std::vector<double> acc(static_cast<size_t>(w));
          for (int64_t v = v0; v < v1; ++v) {
            std::fill(acc.begin(), acc.end(), 0.0);
            for (int64_t j = -r; j <= r; ++j) {
              const double kj = k[static_cast<size_t>(j + r)];
              const float* s = tmp.data() + std::clamp<int64_t>(v + j, 0, h - 1) * w;
              for (int64_t i = 0; i < w; ++i) acc[static_cast<size_t>(i)] += kj * s[i];
            }
            float* dst = img.data() + v * w;
            for (int64_t i = 0; i < w; ++i) dst[i] = static_cast<float>(acc[static_cast<size_t>(i)]);
          }
        },
        16);
  } else {
    img.swap(tmp);
  }
}

// Gradient, magnitude and Laplacian of image rows (a w x h image with pixel spacing su, sv).
struct RowGradient {
  int64_t w, h;
  double su, sv, su2, sv2;
  // Interior pixels multiply by reciprocals (divisions dominated the pass); exact for
  // power-of-two spacings such as 1 mm, otherwise within one double rounding (invisible after
  // the conversion to float in all but rare ties).
  double inv2u, inv2v, invSu2, invSv2;
  RowGradient(int64_t width, int64_t height, double spacingU, double spacingV)
      : w(width),
        h(height),
        su(spacingU),
        sv(spacingV),
        su2(su * su),
        sv2(sv * sv),
        inv2u(1.0 / (2.0 * su)),
        inv2v(1.0 / (2.0 * sv)),
        invSu2(1.0 / su2),
        invSv2(1.0 / sv2) {}

  // Gradient, magnitude and Laplacian of one row v from the image rows up (v-1), row, dn (v+1)
  // (replicated at the border). Same double arithmetic as the per-pixel definition; the interior
  // of a row is a branch-free loop. Returns the row's largest magnitude.
  float operator()(int64_t v, const float* up, const float* row, const float* dn, float* gU, float* gV, float* mag,
                   float* lap) const {
    const int64_t vm = v > 0 ? v - 1 : v, vp = v + 1 < h ? v + 1 : v;
    // d/dv: central difference, one-sided at the first/last row, 0 for a single row.
    const double dvDen = vp > vm ? static_cast<double>(vp - vm) * sv : 0.0;
    auto pixel = [&](int64_t u) {  // general form (row ends)
      const int64_t um = u > 0 ? u - 1 : u, uq = u + 1 < w ? u + 1 : u;
      const double c = row[u];
      const double iu0 = row[um], iu1 = row[uq], iv0 = up[u], iv1 = dn[u];
      const double gu = uq > um ? (iu1 - iu0) / (static_cast<double>(uq - um) * su) : 0.0;
      const double gv = vp > vm ? (iv1 - iv0) / dvDen : 0.0;
      gU[u] = static_cast<float>(gu);
      gV[u] = static_cast<float>(gv);
      mag[u] = static_cast<float>(std::sqrt(gu * gu + gv * gv));
      lap[u] = static_cast<float>((iu0 - 2 * c + iu1) / su2 + (iv0 - 2 * c + iv1) / sv2);
    };
    pixel(0);
    if (w > 1) pixel(w - 1);
    if (vp > vm && vp - vm == 2) {
      int64_t u = 1;
#if defined(__SSE2__)
      // Two pixels per step in double, the same operations in the same order as the scalar
      // loop below (sqrtpd is correctly rounded like sqrt), so results are bit-identical;
      // written out because std::sqrt's errno keeps compilers from vectorising.
      const __m128d r2u = _mm_set1_pd(inv2u), r2v = _mm_set1_pd(inv2v), two = _mm_set1_pd(2.0);
      const __m128d rsu2 = _mm_set1_pd(invSu2), rsv2 = _mm_set1_pd(invSv2);
      auto load2 = [](const float* p) {
        return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
      };
      auto store2 = [](float* p, __m128d x) {
        _mm_storel_epi64(reinterpret_cast<__m128i*>(p), _mm_castps_si128(_mm_cvtpd_ps(x)));
      };
      for (; u + 3 <= w; u += 2) {
        const __m128d c = load2(row + u), iu0 = load2(row + u - 1), iu1 = load2(row + u + 1);
        const __m128d iv0 = load2(up + u), iv1 = load2(dn + u);
        const __m128d gu = _mm_mul_pd(_mm_sub_pd(iu1, iu0), r2u);
        const __m128d gv = _mm_mul_pd(_mm_sub_pd(iv1, iv0), r2v);
        store2(gU + u, gu);
        store2(gV + u, gv);
        store2(mag + u, _mm_sqrt_pd(_mm_add_pd(_mm_mul_pd(gu, gu), _mm_mul_pd(gv, gv))));
        const __m128d c2 = _mm_mul_pd(two, c);
        const __m128d lu = _mm_mul_pd(_mm_add_pd(_mm_sub_pd(iu0, c2), iu1), rsu2);
        const __m128d lv = _mm_mul_pd(_mm_add_pd(_mm_sub_pd(iv0, c2), iv1), rsv2);
        store2(lap + u, _mm_add_pd(lu, lv));
      }
#endif
      for (; u + 1 < w; ++u) {
        const double c = row[u];
        const double iu0 = row[u - 1], iu1 = row[u + 1], iv0 = up[u], iv1 = dn[u];
        const double gu = (iu1 - iu0) * inv2u;
        const double gv = (iv1 - iv0) * inv2v;
        gU[u] = static_cast<float>(gu);
        gV[u] = static_cast<float>(gv);
        mag[u] = static_cast<float>(std::sqrt(gu * gu + gv * gv));
        lap[u] = static_cast<float>((iu0 - 2 * c + iu1) * invSu2 + (iv0 - 2 * c + iv1) * invSv2);
      }
    } else {
      for (int64_t u = 1; u + 1 < w; ++u) pixel(u);
    }
    float rowMax = 0;
    for (int64_t u = 0; u < w; ++u) rowMax = mag[u] > rowMax ? mag[u] : rowMax;
    return rowMax;
  }
};

// Zero crossings of one row from the Laplacian rows up, row, dn (zeros for a missing row).
// Pixel i is marked when a 4-neighbour j has a Laplacian of opposite sign and |L(i)| <= |L(j)|
// (so of such a pair the one closer to zero is marked, both on a tie), or when L(i) == 0 and it
// has both a positive and a negative 4-neighbour. A missing neighbour (border) counts as 0,
// which neither pairs nor counts as positive/negative.
void zeroCrossingRow(int64_t w, const float* up, const float* row, const float* dn, uint8_t* zc) {
  auto mark = [](float a, float l, float r, float t, float b) -> uint8_t {
    const float fa = std::fabs(a);
    auto pairs = [&](float x) {
      return static_cast<int>(((a > 0) & (x < 0)) | ((a < 0) & (x > 0))) & static_cast<int>(fa <= std::fabs(x));
    };
    const int pos =
        static_cast<int>(l > 0) | static_cast<int>(r > 0) | static_cast<int>(t > 0) | static_cast<int>(b > 0);
    const int neg =
        static_cast<int>(l < 0) | static_cast<int>(r < 0) | static_cast<int>(t < 0) | static_cast<int>(b < 0);
    return static_cast<uint8_t>(pairs(l) | pairs(r) | pairs(t) | pairs(b) | (static_cast<int>(a == 0) & pos & neg));
  };
  zc[0] = mark(row[0], 0.0f, w > 1 ? row[1] : 0.0f, up[0], dn[0]);
  if (w > 1) zc[w - 1] = mark(row[w - 1], row[w - 2], 0.0f, up[w - 1], dn[w - 1]);
  int64_t u = 1;
#if defined(__SSE2__)
  // Four pixels per step with compare masks: the same decisions as mark().
  const __m128 zero = _mm_setzero_ps(), absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  for (; u + 5 <= w; u += 4) {
    const __m128 a = _mm_loadu_ps(row + u), fa = _mm_and_ps(a, absMask);
    const __m128 aPos = _mm_cmpgt_ps(a, zero), aNeg = _mm_cmplt_ps(a, zero);
    __m128 any = _mm_setzero_ps(), pos = _mm_setzero_ps(), neg = _mm_setzero_ps();
    for (const float* nb : {row + u - 1, row + u + 1, up + u, dn + u}) {
      const __m128 x = _mm_loadu_ps(nb);
      const __m128 xPos = _mm_cmpgt_ps(x, zero), xNeg = _mm_cmplt_ps(x, zero);
      const __m128 opposite = _mm_or_ps(_mm_and_ps(aPos, xNeg), _mm_and_ps(aNeg, xPos));
      any = _mm_or_ps(any, _mm_and_ps(opposite, _mm_cmple_ps(fa, _mm_and_ps(x, absMask))));
      pos = _mm_or_ps(pos, xPos);
      neg = _mm_or_ps(neg, xNeg);
    }
    any = _mm_or_ps(any, _mm_and_ps(_mm_cmpeq_ps(a, zero), _mm_and_ps(pos, neg)));
    // all-ones lanes -> 1, others 0; pack the four 32-bit lanes to bytes
    const __m128i bits = _mm_and_si128(_mm_castps_si128(any), _mm_set1_epi32(1));
    const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(bits, bits), _mm_setzero_si128());
    const int packed = _mm_cvtsi128_si32(bytes);
    std::memcpy(zc + u, &packed, 4);
  }
#endif
  for (; u + 1 < w; ++u) zc[u] = mark(row[u], row[u - 1], row[u + 1], up[u], dn[u]);
}

}  // namespace

template <class T>
Features2D computeFeatures2D(const SliceView<T>& slice, const Features2DOptions& options, const std::string& what) {
  VS_REQUIRE(slice.base != nullptr && slice.width > 0 && slice.height > 0, "computeFeatures2D: empty slice view");
  VS_REQUIRE(std::isfinite(options.smoothSigmaMm) && options.smoothSigmaMm >= 0,
             "computeFeatures2D: smoothing sigma must be a finite number >= 0 mm");
  VS_REQUIRE(slice.spacingU > 0 && slice.spacingV > 0, "computeFeatures2D: pixel spacing must be > 0");
  // A sigma wider than the slice only flattens it, and a huge one overflowed the kernel size.
  const double sliceExtentMm =
      std::max({static_cast<double>(slice.width) * slice.spacingU, static_cast<double>(slice.height) * slice.spacingV,
                3.0 * slice.spacingU, 3.0 * slice.spacingV});
  VS_REQUIRE(options.smoothSigmaMm <= sliceExtentMm, "smoothing sigma " + numberText(options.smoothSigmaMm) +
                                                         " mm is larger than the slice (" + numberText(sliceExtentMm) +
                                                         " mm)");

  Features2D f;
  const int64_t w = slice.width, h = slice.height, n = w * h;
  f.width = w;
  f.height = h;
  f.spacingU = slice.spacingU;
  f.spacingV = slice.spacingV;
  f.smoothed.resize(static_cast<size_t>(n));
  f.gradU.resize(static_cast<size_t>(n));
  f.gradV.resize(static_cast<size_t>(n));
  f.magnitude.resize(static_cast<size_t>(n));
  f.laplacian.resize(static_cast<size_t>(n));
  f.zeroCrossing.resize(static_cast<size_t>(n));

  // Pass 1 (rows in parallel): copy to float and count non-finite pixels (only float input can
  // have them). Converts rows [r0, r1) of the slice into dst (row stride w).
  std::mutex merge;
  int64_t bad = 0, firstBad = -1;
  auto convertRows = [&](int64_t r0, int64_t r1, float* dst, bool count) {
    int64_t myBad = 0, myFirst = -1;
    for (int64_t v = r0; v < r1; ++v, dst += w) {
      const T* src = slice.base + v * slice.strideV;
      const int64_t su = slice.strideU;
      if (su == 1)
        for (int64_t u = 0; u < w; ++u) dst[u] = static_cast<float>(src[u]);
      else
        for (int64_t u = 0; u < w; ++u) dst[u] = static_cast<float>(src[u * su]);
      if constexpr (std::is_floating_point_v<T>) {
        if (!count) continue;
        int64_t rowBad = 0;
        for (int64_t u = 0; u < w; ++u) rowBad += std::isfinite(dst[u]) ? 0 : 1;
        if (rowBad > 0) {
          for (int64_t u = 0; u < w && myFirst < 0; ++u)
            if (!std::isfinite(dst[u])) myFirst = u + w * v;
          myBad += rowBad;
        }
      }
    }
    if (myBad > 0) {
      std::lock_guard<std::mutex> lock(merge);
      bad += myBad;
      if (firstBad < 0 || myFirst < firstBad) firstBad = myFirst;
    }
  };
  auto throwIfBad = [&] {
    if (bad == 0) return;
    std::ostringstream os;
    os << (what.empty() ? describeSlice(slice.axis, slice.index) : what) << " contains " << bad << " non-finite pixel"
       << (bad > 1 ? "s" : "") << " (NaN or inf), first at u=" << firstBad % w << ", v=" << firstBad / w
       << "; the live-wire cost is undefined there";
    throw DataError(os.str());
  };
  const bool smooth = options.smoothSigmaMm > 0;
  if (smooth) {  // the blur needs the whole image first
    parallelFor(
        0, h, [&](int64_t v0, int64_t v1) { convertRows(v0, v1, f.smoothed.data() + v0 * w, true); }, 32);
    throwIfBad();
    blur(f.smoothed, w, h, options.smoothSigmaMm / slice.spacingU, options.smoothSigmaMm / slice.spacingV);
  }

  const RowGradient gradientRow(w, h, slice.spacingU, slice.spacingV);
  const std::vector<float> zeros(static_cast<size_t>(w), 0.0f);  // the Laplacian beyond the border

  // One parallel region for the rest: each chunk of rows [v0, v1) also computes the image rows
  // v0-2, v0-1, v1, v1+1 and the Laplacian rows v0-1 and v1 privately (halo), so it needs no
  // other chunk's results and no second pass over the image.
  float gmax = 0;
  parallelFor(
      0, h,
      [&](int64_t v0, int64_t v1) {
        const int64_t top = std::max<int64_t>(0, v0 - 2), bottom = std::min(h, v1 + 2);
        std::vector<float> haloI, haloL(static_cast<size_t>(2 * w)), scratch(static_cast<size_t>(3 * w));
        if (!smooth) {
          convertRows(v0, v1, f.smoothed.data() + v0 * w, true);
          haloI.resize(static_cast<size_t>(4 * w));
          if (top < v0) convertRows(top, v0, haloI.data() + (2 - (v0 - top)) * w, false);  // rows v0-2, v0-1 -> 0, 1
          if (bottom > v1) convertRows(v1, bottom, haloI.data() + 2 * w, false);           // rows v1, v1+1 -> 2, 3
        }
        auto imageRow = [&](int64_t r) -> const float* {
          r = std::clamp<int64_t>(r, 0, h - 1);
          if (smooth || (r >= v0 && r < v1)) return f.smoothed.data() + r * w;
          return r < v0 ? haloI.data() + (2 - (v0 - r)) * w : haloI.data() + (2 + (r - v1)) * w;
        };
        float myMax = 0;
        for (int64_t v = v0; v < v1; ++v) {
          const size_t o = static_cast<size_t>(v * w);
          myMax = std::max(myMax, gradientRow(v, imageRow(v - 1), imageRow(v), imageRow(v + 1), f.gradU.data() + o,
                                              f.gradV.data() + o, f.magnitude.data() + o, f.laplacian.data() + o));
        }
        float* gs = scratch.data();
        if (v0 > 0)
          gradientRow(v0 - 1, imageRow(v0 - 2), imageRow(v0 - 1), imageRow(v0), gs, gs + w, gs + 2 * w, haloL.data());
        if (v1 < h)
          gradientRow(v1, imageRow(v1 - 1), imageRow(v1), imageRow(v1 + 1), gs, gs + w, gs + 2 * w, haloL.data() + w);
        auto lapRow = [&](int64_t r) -> const float* {
          if (r < 0 || r >= h) return zeros.data();
          if (r < v0) return haloL.data();
          if (r >= v1) return haloL.data() + w;
          return f.laplacian.data() + r * w;
        };
        for (int64_t v = v0; v < v1; ++v)
          zeroCrossingRow(w, lapRow(v - 1), lapRow(v), lapRow(v + 1), f.zeroCrossing.data() + v * w);
        std::lock_guard<std::mutex> lock(merge);
        gmax = std::max(gmax, myMax);
      },
      32);
  throwIfBad();
  f.maxMagnitude = gmax;
  return f;
}

Features2D computeFeatures2D(const AnyVolume& image2d, const Features2DOptions& options) {
  return std::visit(
      [&](const auto& vol) -> Features2D {
        VS_REQUIRE(vol.dims()[2] == 1,
                   "computeFeatures2D: expected a 2D image (dims.z == 1), got " + vol.geometry().describe());
        return computeFeatures2D(sliceView(vol, 2, 0), options, "image");
      },
      image2d);
}

template Features2D computeFeatures2D(const SliceView<uint8_t>&, const Features2DOptions&, const std::string&);
template Features2D computeFeatures2D(const SliceView<int16_t>&, const Features2DOptions&, const std::string&);
template Features2D computeFeatures2D(const SliceView<uint16_t>&, const Features2DOptions&, const std::string&);
template Features2D computeFeatures2D(const SliceView<float>&, const Features2DOptions&, const std::string&);

}  // namespace vs
