// Live-wire edge costs on the 8-connected pixel grid of one slice (thesis 2.3, eq. 7-12,
// with the corrections of reading-notes.md).
//
// Mortensen-Barrett (eq. 7): for the directed edge p -> q,
//   cost(p,q) = len(p,q) * [ wZ fZ(q) + wG fG(q) + wD fD(p,q) ]
//   fZ(q)   = 0 on a Laplacian zero crossing, else 1                     (eq. 7)
//   fG(q)   = 1 - min(G(q), Gref) / Gref                                  (eq. 9)
//   fD(p,q) = 2/(3 pi) * ( acos(D(p).L) + acos(D(q).L) )                  (eq. 10-11)
//     D(x) = unit(Gv(x), -Gu(x)) (perpendicular to the gradient; 0 where the gradient is 0),
//     L = unit(q - p) if D(p).(q - p) >= 0 else unit(p - q), taken in mm (anisotropic spacing).
//   The 2/(3 pi) factor keeps fD in [0, 1] (the sum of the arccos terms reaches 3 pi / 2).
// Stalling-Hege (eq. 12), gradient magnitudes scaled to 0..255 (Gs = 255 * min(G, Gref) / Gref):
//   cost(p,q) = len(p,q) * ( 255 - (Gs(p) + Gs(q)) / 2 )
// len(p,q) is the physical step length in mm (1 pixel step = spacing; diagonals longer), so
// costs are proportional to edge length and diagonal paths are not favoured (eq. 9 note);
// a path cost is "cost per mm" integrated along the path.
// Gref is a quantile of G (default 1.0 = the maximum, as in eq. 9; lower values are a robust
// maximum so one bright outlier does not flatten the costs).
// Flat image (G == 0 everywhere): fG = 1, Gs = 0, fD = 2/3, no zero crossings - uniform costs
// per mm, no division by zero, every target reachable.
// All costs are finite and >= 0. Complexity O(N * K), rows in parallel (parallelFor): per row,
// the node term and, per pair of opposite steps, D . e and acos(|D . e|) are computed once per
// pixel (a 3-row ring buffer per thread, no per-pixel allocation), then every direction is one
// vectorised pass (SSE2 where available) and the K values are interleaved into the output.
// Results equal the per-edge formulas up to float rounding (<= 1 ulp; tests compare with a
// double-precision evaluation edge by edge).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "features/features2d.h"

namespace vs {

enum class LiveWireCostKind {
  MortensenBarrett,  // eq. 7-11 ("mb")
  Gradient,          // eq. 12, Stalling & Hege ("gradient")
};

// "mb" / "gradient" (also "mortensen-barrett", "stalling-hege"); throws InvalidArgument otherwise.
LiveWireCostKind parseLiveWireCostKind(const std::string& name);
std::string liveWireCostKindName(LiveWireCostKind kind);

struct LiveWireCostOptions {
  LiveWireCostKind kind = LiveWireCostKind::MortensenBarrett;
  double weightZ = 0.43;                   // wZ, Laplacian zero crossing
  double weightG = 0.43;                   // wG, gradient magnitude
  double weightD = 0.14;                   // wD, gradient direction (smoothness)
  double gradientReferenceQuantile = 1.0;  // Gref = this quantile of G (1 = max G, eq. 9)
};

// Cost of every directed edge: out[i * K + k] for pixel i = u + width * v to its neighbour
// (u + steps[k][0], v + steps[k][1]); K = steps.size(). Edges leaving the image get +inf.
// Steps must be 8-neighbour offsets (components -1, 0, 1, not both 0), as the grid graph's.
// Throws InvalidArgument for other steps, no steps, negative/non-finite weights, all weights 0, or a quantile
// outside (0, 1].
std::vector<float> liveWireEdgeCosts(const Features2D& features, const LiveWireCostOptions& options,
                                     const std::vector<std::array<int, 2>>& steps);

// The single edge p -> q (8-neighbours) by the same formulas (reference / tests).
double liveWireEdgeCost(const Features2D& features, const LiveWireCostOptions& options, int64_t pu, int64_t pv,
                        int64_t qu, int64_t qv);

}  // namespace vs
