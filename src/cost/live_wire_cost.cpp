#include "cost/live_wire_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "util/error.h"
#include "util/parallel.h"

namespace vs {

LiveWireCostKind parseLiveWireCostKind(const std::string& name) {
  if (name == "mb" || name == "mortensen-barrett") return LiveWireCostKind::MortensenBarrett;
  if (name == "gradient" || name == "stalling-hege") return LiveWireCostKind::Gradient;
  throw InvalidArgument("unknown live-wire cost '" + name + "' (expected mb or gradient)");
}

std::string liveWireCostKindName(LiveWireCostKind kind) {
  return kind == LiveWireCostKind::Gradient ? "gradient" : "mb";
}

namespace {

struct Validated {
  float gref = 0;
};

Validated validate(const Features2D& f, const LiveWireCostOptions& o) {
  VS_REQUIRE(std::isfinite(o.weightZ) && std::isfinite(o.weightG) && std::isfinite(o.weightD) && o.weightZ >= 0 &&
                 o.weightG >= 0 && o.weightD >= 0,
             "live-wire cost weights must be finite and >= 0");
  VS_REQUIRE(o.kind == LiveWireCostKind::Gradient || o.weightZ + o.weightG + o.weightD > 0,
             "live-wire cost weights must not all be 0");
  VS_REQUIRE(o.gradientReferenceQuantile > 0 && o.gradientReferenceQuantile <= 1,
             "live-wire gradient reference quantile must be in (0, 1]");
  const auto n = static_cast<size_t>(f.width * f.height);
  VS_REQUIRE(f.width > 0 && f.height > 0 && f.magnitude.size() == n && f.gradU.size() == n && f.gradV.size() == n &&
                 f.zeroCrossing.size() == n,
             "live-wire cost: features are empty or inconsistent");
  Validated v;
  v.gref = o.gradientReferenceQuantile >= 1.0 ? f.maxMagnitude : f.magnitudeQuantile(o.gradientReferenceQuantile);
  return v;
}

constexpr float kPi = std::numbers::pi_v<float>;

// Per-pixel quantities of one image row, padded by one pixel at both ends (index u + 1).
struct RowData {
  std::vector<float> node;    // MB: wZ fZ + wG fG; gradient: Gs (0..255)
  std::vector<float> dot[4];  // D . e_b for the (up to 4) base directions b
  std::vector<float> acs[4];  // acos(|D . e_b|)
  std::vector<float> du, dv;  // unit D (unpadded scratch)
  void resize(size_t n, size_t bases) {
    node.assign(n, 0.0f);
    du.assign(n, 0.0f);
    dv.assign(n, 0.0f);
    for (size_t b = 0; b < bases; ++b) dot[b].assign(n, 0.0f), acs[b].assign(n, 0.0f);
  }
};

// acos(|x|) by Abramowitz & Stegun 4.4.46 (|error| <= 2e-8 rad), |x| clamped to 1; acos(x) for
// x < 0 is pi minus this. Branch-free, so the row loops below vectorise.
inline float acosAbs(float x) {
  const float a = std::min(std::fabs(x), 1.0f);
  const float poly =
      1.5707963050f +
      a * (-0.2145988016f +
           a * (0.0889789874f +
                a * (-0.0501743046f +
                     a * (0.0308918810f + a * (-0.0170881256f + a * (0.0066700901f + a * -0.0012624911f))))));
  return std::sqrt(1.0f - a) * poly;
}

// acs[u] = acosAbs(dot[u]) for a row. std::sqrt keeps compilers from vectorising (errno), so
// with SSE2 the same operations are written with intrinsics (sqrtps is the correctly rounded
// square root, as sqrtss): the results are bit-identical to acosAbs.
void acosAbsRow(float* __restrict acs, const float* __restrict dot, int64_t w) {
  int64_t u = 0;
#if defined(__SSE2__)
  const __m128 one = _mm_set1_ps(1.0f), absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  for (; u + 4 <= w; u += 4) {
    const __m128 a = _mm_min_ps(_mm_and_ps(_mm_loadu_ps(dot + u), absMask), one);
    __m128 poly = _mm_set1_ps(-0.0012624911f);
    poly = _mm_add_ps(_mm_set1_ps(0.0066700901f), _mm_mul_ps(a, poly));
    poly = _mm_add_ps(_mm_set1_ps(-0.0170881256f), _mm_mul_ps(a, poly));
    poly = _mm_add_ps(_mm_set1_ps(0.0308918810f), _mm_mul_ps(a, poly));
    poly = _mm_add_ps(_mm_set1_ps(-0.0501743046f), _mm_mul_ps(a, poly));
    poly = _mm_add_ps(_mm_set1_ps(0.0889789874f), _mm_mul_ps(a, poly));
    poly = _mm_add_ps(_mm_set1_ps(-0.2145988016f), _mm_mul_ps(a, poly));
    poly = _mm_add_ps(_mm_set1_ps(1.5707963050f), _mm_mul_ps(a, poly));
    _mm_storeu_ps(acs + u, _mm_mul_ps(_mm_sqrt_ps(_mm_sub_ps(one, a)), poly));
  }
#endif
  for (; u < w; ++u) acs[u] = acosAbs(dot[u]);
}

// Row kernels: free functions over restrict pointers with branch-free selects, so that the
// compiler vectorises them (the previous per-edge lambda was scalar and branchy).

// Node term of one row: MB wZ fZ + wG fG (eq. 7, 9) or gradient Gs (eq. 12).
void nodeRow(float* __restrict node, const float* __restrict mag, const uint8_t* __restrict zc, int64_t w, bool mb,
             float gref, float wZ, float wG) {
  if (gref > 0) {
    if (mb)
      for (int64_t u = 0; u < w; ++u) {
        const float g = mag[u] < gref ? mag[u] : gref;
        const float rel = g / gref;
        node[u] = wZ * (1.0f - static_cast<float>(zc[u])) + wG * (1.0f - rel);
      }
    else
      for (int64_t u = 0; u < w; ++u) {
        const float g = mag[u] < gref ? mag[u] : gref;
        node[u] = 255.0f * (g / gref);
      }
  } else {  // flat image: rel = 0
    if (mb)
      for (int64_t u = 0; u < w; ++u) node[u] = wZ * (1.0f - static_cast<float>(zc[u])) + wG * 1.0f;
    else
      for (int64_t u = 0; u < w; ++u) node[u] = 0.0f;
  }
}

// D = (Gv, -Gu) / |G| of one row (0 where the gradient vanishes: G == 0 implies Gu == Gv == 0,
// since |G| >= |Gu|, |Gv| before rounding, so dividing by 1 there gives D = 0 without a branch).
void unitDirectionRow(float* __restrict du, float* __restrict dv, const float* __restrict mag,
                      const float* __restrict gU, const float* __restrict gV, int64_t w) {
  for (int64_t u = 0; u < w; ++u) {
    const float g = mag[u];
    const float den = g > 0 ? g : 1.0f;
    du[u] = gV[u] / den;
    dv[u] = -gU[u] / den;
  }
}

// D . e_b and acos(|D . e_b|) of one row.
void directionRow(float* __restrict dot, float* __restrict acs, const float* __restrict du, const float* __restrict dv,
                  int64_t w, float ebu, float ebv) {
  for (int64_t u = 0; u < w; ++u) dot[u] = du[u] * ebu + dv[u] * ebv;
  acosAbsRow(acs, dot, w);
}

// MB edge costs p -> q = p + step for one row (q's row data already shifted by the step):
// fD(p,q) = acos(D(p).L) + acos(D(q).L), L = e if D(p).e >= 0 else -e (eq. 11), so
// acos(D(p).L) = acos(|D(p).e|) and acos(D(q).L) = acos(+-D(q).e) with the sign of D(p).e.
// s = +1 for a base direction, -1 for its opposite (D . e_k = s D . e_b exactly).
void mbEdgeRow(float* __restrict c, const float* __restrict dp, const float* __restrict ap, const float* __restrict dq,
               const float* __restrict aq, const float* __restrict nq, int64_t w, float s, float len, float wD) {
  int64_t u = 0;
#if defined(__SSE2__)
  // The same operations as the scalar loop below (selects as and/andnot/or masks; max(x, 0)
  // is x > 0 ? x : 0), written out because compilers keep the compare-selects scalar.
  const __m128 vs = _mm_set1_ps(s), vlen = _mm_set1_ps(len), vwD = _mm_set1_ps(wD), vpi = _mm_set1_ps(kPi);
  const __m128 zero = _mm_setzero_ps(), signBit = _mm_set1_ps(-0.0f);
  for (; u + 4 <= w; u += 4) {
    const __m128 pe = _mm_mul_ps(vs, _mm_loadu_ps(dp + u)), qe = _mm_mul_ps(vs, _mm_loadu_ps(dq + u));
    const __m128 fwd = _mm_cmpge_ps(pe, zero);
    const __m128 y = _mm_or_ps(_mm_and_ps(fwd, qe), _mm_andnot_ps(fwd, _mm_xor_ps(qe, signBit)));
    const __m128 a = _mm_loadu_ps(aq + u);
    const __m128 pos = _mm_cmpge_ps(y, zero);
    const __m128 termQ = _mm_or_ps(_mm_and_ps(pos, a), _mm_andnot_ps(pos, _mm_sub_ps(vpi, a)));
    const __m128 cost = _mm_add_ps(_mm_loadu_ps(nq + u), _mm_mul_ps(vwD, _mm_add_ps(_mm_loadu_ps(ap + u), termQ)));
    _mm_storeu_ps(c + u, _mm_mul_ps(vlen, _mm_max_ps(cost, zero)));
  }
#endif
  for (; u < w; ++u) {
    const float pe = s * dp[u], qe = s * dq[u];
    const float y = pe >= 0 ? qe : -qe;  // D(q) . L
    const float a = aq[u], complement = kPi - a;
    const float termQ = y >= 0 ? a : complement;
    const float cost = nq[u] + wD * (ap[u] + termQ);
    c[u] = len * (cost > 0.0f ? cost : 0.0f);
  }
}

void gradientEdgeRow(float* __restrict c, const float* __restrict np, const float* __restrict nq, int64_t w,
                     float len) {
  for (int64_t u = 0; u < w; ++u) c[u] = len * (255.0f - 0.5f * (np[u] + nq[u]));
}

// Interleaves K row arrays (stride `stride`) into dst[u * K + k].
template <int K>
void interleave(float* __restrict dst, const float* __restrict rows, int64_t stride, int64_t w) {
  int64_t u = 0;
  for (; u < w; ++u)
    for (int k = 0; k < K; ++k) dst[u * K + k] = rows[k * stride + u];
}
void interleave(float* dst, const float* rows, int64_t stride, int64_t w, size_t K) {
  switch (K) {
    case 8:
      interleave<8>(dst, rows, stride, w);
      return;
    case 4:
      interleave<4>(dst, rows, stride, w);
      return;
    default:
      for (int64_t u = 0; u < w; ++u)
        for (size_t k = 0; k < K; ++k) dst[static_cast<size_t>(u) * K + k] = rows[static_cast<int64_t>(k) * stride + u];
  }
}

}  // namespace

std::vector<float> liveWireEdgeCosts(const Features2D& f, const LiveWireCostOptions& o,
                                     const std::vector<std::array<int, 2>>& steps) {
  const Validated val = validate(f, o);
  const size_t K = steps.size();
  VS_REQUIRE(K > 0, "live-wire cost: no neighbour steps given");
  // Unit step directions in mm. Opposite steps share a base direction b (sign -1): D . e_k is
  // then exactly -(D . e_b), and acos(|D . e|) is the same for both.
  std::vector<float> len(K);
  std::vector<int> base(K, -1);
  std::vector<float> sign(K, 1.0f);
  std::vector<size_t> bases;
  float eu[4] = {}, ev[4] = {};
  for (size_t k = 0; k < K; ++k) {
    const int dx = steps[k][0], dy = steps[k][1];
    VS_REQUIRE(std::abs(dx) <= 1 && std::abs(dy) <= 1 && (dx != 0 || dy != 0),
               "live-wire cost: neighbour steps must be 8-neighbour offsets (each component -1, 0 or 1, not both 0)");
    const double su = dx * f.spacingU, sv = dy * f.spacingV, l = std::hypot(su, sv);
    len[k] = static_cast<float>(l);
    for (size_t b = 0; b < bases.size(); ++b) {
      const size_t kb = bases[b];
      if (steps[kb][0] == -dx && steps[kb][1] == -dy) base[k] = static_cast<int>(b), sign[k] = -1.0f;
      if (steps[kb][0] == dx && steps[kb][1] == dy) base[k] = static_cast<int>(b);
    }
    if (base[k] < 0) {
      base[k] = static_cast<int>(bases.size());
      bases.push_back(k);
      eu[base[k]] = static_cast<float>(su / l);
      ev[base[k]] = static_cast<float>(sv / l);
    }
  }
  const int64_t w = f.width, h = f.height;
  const size_t n = static_cast<size_t>(w * h), B = bases.size();
  const bool mb = o.kind == LiveWireCostKind::MortensenBarrett;
  const float gref = val.gref;
  const float wZ = static_cast<float>(o.weightZ), wG = static_cast<float>(o.weightG);
  const float wD = static_cast<float>(o.weightD * 2.0 / (3.0 * std::numbers::pi));  // eq. 10 with 2/(3 pi)
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> out(n * K);

  // Fills the padded row data of image row v.
  auto fillRow = [&](RowData& r, int64_t v) {
    const size_t i0 = static_cast<size_t>(v * w);
    nodeRow(r.node.data() + 1, f.magnitude.data() + i0, f.zeroCrossing.data() + i0, w, mb, gref, wZ, wG);
    if (!mb) return;
    unitDirectionRow(r.du.data(), r.dv.data(), f.magnitude.data() + i0, f.gradU.data() + i0, f.gradV.data() + i0, w);
    for (size_t b = 0; b < B; ++b)
      directionRow(r.dot[b].data() + 1, r.acs[b].data() + 1, r.du.data(), r.dv.data(), w, eu[b], ev[b]);
  };

  parallelFor(
      0, h,
      [&](int64_t v0, int64_t v1) {
        const size_t padded = static_cast<size_t>(w + 2);
        RowData ring[3];
        for (auto& r : ring) r.resize(padded, mb ? B : 0);
        auto slot = [](int64_t v) { return static_cast<size_t>((v + 3) % 3); };
        if (v0 > 0) fillRow(ring[slot(v0 - 1)], v0 - 1);
        fillRow(ring[slot(v0)], v0);
        std::vector<float> rowCost(padded * K);
        for (int64_t v = v0; v < v1; ++v) {
          if (v + 1 < h) fillRow(ring[slot(v + 1)], v + 1);
          const RowData& P = ring[slot(v)];
          for (size_t k = 0; k < K; ++k) {
            const int dx = steps[k][0], dy = steps[k][1];
            // A missing row (image border) is replaced by row v; those edges become +inf below.
            const int64_t vq = (v + dy < 0 || v + dy >= h) ? v : v + dy;
            const RowData& Q = ring[slot(vq)];
            float* c = rowCost.data() + k * padded;
            const float* nq = Q.node.data() + 1 + dx;
            if (!mb) {
              gradientEdgeRow(c, P.node.data() + 1, nq, w, len[k]);
            } else {
              const size_t b = static_cast<size_t>(base[k]);
              mbEdgeRow(c, P.dot[b].data() + 1, P.acs[b].data() + 1, Q.dot[b].data() + 1 + dx, Q.acs[b].data() + 1 + dx,
                        nq, w, sign[k], len[k], wD);
            }
            if (v + dy < 0 || v + dy >= h) std::fill(c, c + w, inf);
            if (dx < 0) c[0] = inf;
            if (dx > 0) c[w - 1] = inf;
          }
          interleave(out.data() + static_cast<size_t>(v * w) * K, rowCost.data(), static_cast<int64_t>(padded), w, K);
        }
      },
      16);
  return out;
}

double liveWireEdgeCost(const Features2D& f, const LiveWireCostOptions& o, int64_t pu, int64_t pv, int64_t qu,
                        int64_t qv) {
  VS_REQUIRE(f.contains(pu, pv) && f.contains(qu, qv), "liveWireEdgeCost: pixel outside the image");
  VS_REQUIRE(std::max(std::abs(qu - pu), std::abs(qv - pv)) == 1, "liveWireEdgeCost: p and q must be 8-neighbours");
  // The same code path as the bulk computation (O(N); meant for tests and tools, not loops).
  const std::vector<std::array<int, 2>> step = {{static_cast<int>(qu - pu), static_cast<int>(qv - pv)}};
  return liveWireEdgeCosts(f, o, step)[static_cast<size_t>(f.index(pu, pv))];
}

}  // namespace vs
