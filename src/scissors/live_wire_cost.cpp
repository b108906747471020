#include "scissors/live_wire_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "util/error.h"
#include "util/parallel.h"

namespace vs {

LiveWireCostKind parseLiveWireCostKind(const std::string& name) {
  if (name == "mb" || name == "mortensen-barrett") return LiveWireCostKind::MortensenBarrett;
  if (name == "gradient" || name == "stalling-hege") return LiveWireCostKind::Gradient;
  throw UsageError("unknown live-wire cost '" + name + "' (expected mb or gradient)");
}

std::string liveWireCostKindName(LiveWireCostKind kind) {
  return kind == LiveWireCostKind::Gradient ? "gradient" : "mb";
}

namespace {

struct CostContext {
  const Features2D* f = nullptr;
  LiveWireCostOptions o;
  std::vector<float> fG;             // MB: 1 - G/Gref; gradient: Gs = 255 * G/Gref
  std::vector<float> du, dv;         // unit D = (Gv, -Gu)/|G| (0 where G == 0)
};

CostContext makeContext(const Features2D& f, const LiveWireCostOptions& o) {
  VS_REQUIRE(std::isfinite(o.weightZ) && std::isfinite(o.weightG) && std::isfinite(o.weightD) && o.weightZ >= 0 &&
                 o.weightG >= 0 && o.weightD >= 0,
             "live-wire cost weights must be finite and >= 0");
  VS_REQUIRE(o.kind == LiveWireCostKind::Gradient || o.weightZ + o.weightG + o.weightD > 0,
             "live-wire cost weights must not all be 0");
  VS_REQUIRE(o.gradientReferenceQuantile > 0 && o.gradientReferenceQuantile <= 1,
             "live-wire gradient reference quantile must be in (0, 1]");
  VS_REQUIRE(f.width > 0 && f.height > 0 && f.magnitude.size() == static_cast<size_t>(f.width * f.height),
             "live-wire cost: features are empty or inconsistent");
  CostContext c;
  c.f = &f;
  c.o = o;
  const float gref = o.gradientReferenceQuantile >= 1.0 ? f.maxMagnitude : f.magnitudeQuantile(o.gradientReferenceQuantile);
  const size_t n = f.magnitude.size();
  c.fG.resize(n);
  c.du.resize(n);
  c.dv.resize(n);
  const bool mb = o.kind == LiveWireCostKind::MortensenBarrett;
  for (size_t i = 0; i < n; ++i) {
    const float g = f.magnitude[i];
    const float rel = gref > 0 ? std::min(g, gref) / gref : 0.0f;  // flat image: 0
    c.fG[i] = mb ? 1.0f - rel : 255.0f * rel;
    if (g > 0) {
      c.du[i] = f.gradV[i] / g;
      c.dv[i] = -f.gradU[i] / g;
    } else {
      c.du[i] = c.dv[i] = 0.0f;
    }
  }
  return c;
}

// arccos by Abramowitz & Stegun 4.4.46 (|error| <= 2e-8 rad), clamped to [-1, 1]: ~5x faster
// than std::acos and far more precise than the costs need.
inline float fastAcos(float x) {
  const float a = std::min(std::fabs(x), 1.0f);
  const float poly =
      1.5707963050f +
      a * (-0.2145988016f +
           a * (0.0889789874f + a * (-0.0501743046f + a * (0.0308918810f + a * (-0.0170881256f + a * (0.0066700901f + a * -0.0012624911f))))));
  const float r = std::sqrt(1.0f - a) * poly;
  return x >= 0 ? r : std::numbers::pi_v<float> - r;
}

}  // namespace

std::vector<float> liveWireEdgeCosts(const Features2D& f, const LiveWireCostOptions& o,
                                     const std::vector<std::array<int, 2>>& steps) {
  const CostContext c = makeContext(f, o);
  const size_t K = steps.size();
  VS_REQUIRE(K > 0, "live-wire cost: no neighbour steps given");
  // Unit step directions in mm; opposite steps share one arccos table (acos(-x) = pi - acos(x)).
  std::vector<float> eu(K), ev(K), len(K);
  std::vector<int> base(K, -1);
  std::vector<float> sign(K, 1.0f);
  std::vector<size_t> bases;
  for (size_t k = 0; k < K; ++k) {
    const double su = steps[k][0] * f.spacingU, sv = steps[k][1] * f.spacingV, l = std::hypot(su, sv);
    VS_REQUIRE(l > 0, "live-wire cost: a neighbour step of length 0");
    eu[k] = static_cast<float>(su / l);
    ev[k] = static_cast<float>(sv / l);
    len[k] = static_cast<float>(l);
    for (size_t b = 0; b < bases.size(); ++b) {
      const size_t kb = bases[b];
      if (steps[kb][0] == -steps[k][0] && steps[kb][1] == -steps[k][1]) base[k] = static_cast<int>(b), sign[k] = -1.0f;
      if (steps[kb][0] == steps[k][0] && steps[kb][1] == steps[k][1]) base[k] = static_cast<int>(b);
    }
    if (base[k] < 0) {
      base[k] = static_cast<int>(bases.size());
      bases.push_back(k);
    }
  }
  const int64_t w = f.width, h = f.height;
  const size_t n = static_cast<size_t>(w * h), B = bases.size();
  const bool mb = o.kind == LiveWireCostKind::MortensenBarrett;
  std::vector<float> out(n * K);
  std::vector<float> acosTable(mb ? n * B : 0);  // acos(D(p) . e_base), per pixel and base direction
  const float wZ = static_cast<float>(o.weightZ), wG = static_cast<float>(o.weightG);
  const float wD = static_cast<float>(o.weightD * 2.0 / (3.0 * std::numbers::pi));  // eq. 10 with 2/(3 pi)
  const float pi = std::numbers::pi_v<float>;
  parallelFor(
      0, h,
      [&](int64_t v0, int64_t v1) {
        if (mb)
          for (size_t p = static_cast<size_t>(v0 * w); p < static_cast<size_t>(v1 * w); ++p)
            for (size_t b = 0; b < B; ++b)
              acosTable[p * B + b] = fastAcos(c.du[p] * eu[bases[b]] + c.dv[p] * ev[bases[b]]);
      },
      16);
  // Per-pixel node term wZ fZ(q) + wG fG(q) (MB) or Gs(q) (gradient).
  std::vector<float> nodeTerm(n);
  for (size_t q = 0; q < n; ++q)
    nodeTerm[q] = mb ? wZ * (f.zeroCrossing[q] ? 0.0f : 1.0f) + wG * c.fG[q] : c.fG[q];
  std::vector<int64_t> offs(K);
  for (size_t k = 0; k < K; ++k) offs[k] = steps[k][0] + w * steps[k][1];
  auto edge = [&](size_t p, size_t q, size_t k) -> float {
    if (!mb) return len[k] * (255.0f - 0.5f * (nodeTerm[p] + nodeTerm[q]));
    // e = q - p (unit, mm); a(x) = acos(D(x) . e) from the base direction's table.
    const size_t b = static_cast<size_t>(base[k]);
    const float tp = acosTable[p * B + b], tq = acosTable[q * B + b];
    const float ap = sign[k] > 0 ? tp : pi - tp;
    const float aq = sign[k] > 0 ? tq : pi - tq;
    const bool forward = c.du[p] * eu[k] + c.dv[p] * ev[k] >= 0;  // eq. 11: L = q - p, else p - q
    const float termP = std::min(ap, pi - ap);                      // acos(|D(p) . e|) = acos(D(p) . L)
    const float termQ = forward ? aq : pi - aq;                      // acos(D(q) . L)
    return len[k] * std::max(0.0f, nodeTerm[q] + wD * (termP + termQ));
  };
  parallelFor(
      0, h,
      [&](int64_t v0, int64_t v1) {
        for (int64_t v = v0; v < v1; ++v) {
          const bool borderRow = v == 0 || v == h - 1;
          for (int64_t u = 0; u < w; ++u) {
            const size_t p = static_cast<size_t>(u + w * v);
            float* dst = out.data() + p * K;
            if (!borderRow && u > 0 && u < w - 1) {  // interior: every neighbour exists
              for (size_t k = 0; k < K; ++k) dst[k] = edge(p, static_cast<size_t>(static_cast<int64_t>(p) + offs[k]), k);
              continue;
            }
            for (size_t k = 0; k < K; ++k) {
              const int64_t qu = u + steps[k][0], qv = v + steps[k][1];
              dst[k] = (qu < 0 || qv < 0 || qu >= w || qv >= h) ? std::numeric_limits<float>::infinity()
                                                                 : edge(p, static_cast<size_t>(qu + w * qv), k);
            }
          }
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
