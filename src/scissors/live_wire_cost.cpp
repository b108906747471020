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

inline double clampedAcos(double x) { return std::acos(std::clamp(x, -1.0, 1.0)); }

// Cost of p -> q where (su, sv) is the step in mm and len its length.
inline double edgeCost(const CostContext& c, size_t p, size_t q, double su, double sv, double len) {
  if (c.o.kind == LiveWireCostKind::Gradient) return len * (255.0 - 0.5 * (c.fG[p] + c.fG[q]));
  const double lu = su / len, lv = sv / len;
  const double dpDot = c.du[p] * lu + c.dv[p] * lv;
  const double sign = dpDot >= 0 ? 1.0 : -1.0;  // L = q - p or p - q (eq. 11)
  const double dp = sign * dpDot;
  const double dq = sign * (c.du[q] * lu + c.dv[q] * lv);
  const double fD = (2.0 / (3.0 * std::numbers::pi)) * (clampedAcos(dp) + clampedAcos(dq));
  const double fZ = c.f->zeroCrossing[q] ? 0.0 : 1.0;
  const double local = c.o.weightZ * fZ + c.o.weightG * c.fG[q] + c.o.weightD * fD;
  return len * std::max(0.0, local);
}

}  // namespace

std::vector<float> liveWireEdgeCosts(const Features2D& f, const LiveWireCostOptions& o,
                                     const std::vector<std::array<int, 2>>& steps) {
  const CostContext c = makeContext(f, o);
  const size_t K = steps.size();
  VS_REQUIRE(K > 0, "live-wire cost: no neighbour steps given");
  std::vector<double> su(K), sv(K), len(K);
  for (size_t k = 0; k < K; ++k) {
    su[k] = steps[k][0] * f.spacingU;
    sv[k] = steps[k][1] * f.spacingV;
    len[k] = std::hypot(su[k], sv[k]);
    VS_REQUIRE(len[k] > 0, "live-wire cost: a neighbour step of length 0");
  }
  const int64_t w = f.width, h = f.height;
  std::vector<float> out(static_cast<size_t>(w * h) * K);
  parallelFor(
      0, h,
      [&](int64_t v0, int64_t v1) {
        for (int64_t v = v0; v < v1; ++v)
          for (int64_t u = 0; u < w; ++u) {
            const size_t p = static_cast<size_t>(u + w * v);
            for (size_t k = 0; k < K; ++k) {
              const int64_t qu = u + steps[k][0], qv = v + steps[k][1];
              float& dst = out[p * K + k];
              if (qu < 0 || qv < 0 || qu >= w || qv >= h) {
                dst = std::numeric_limits<float>::infinity();
                continue;
              }
              dst = static_cast<float>(edgeCost(c, p, static_cast<size_t>(qu + w * qv), su[k], sv[k], len[k]));
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
  const CostContext c = makeContext(f, o);
  const double su = static_cast<double>(qu - pu) * f.spacingU, sv = static_cast<double>(qv - pv) * f.spacingV;
  return edgeCost(c, static_cast<size_t>(f.index(pu, pv)), static_cast<size_t>(f.index(qu, qv)), su, sv,
                  std::hypot(su, sv));
}

}  // namespace vs
