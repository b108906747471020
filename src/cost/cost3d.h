// Per-voxel node costs for 3D path search (thesis 4.2 eq. 19-22, 4.3.2; reading-notes.md).
// Every cost here is a node cost c(u) >= 0 plus an optional per-node sign bit, turned into an
// edge cost by the engine's GridCost (graph/grid_cost.h) or, for explicit graphs with long
// edges (the pruned IsoRegion graph), by NodeCost3D::edgeCost:
//     w(u,v) = ||p(u) - p(v)||_mm * ( nodeWeight * (c(u) + c(v)) / 2 + signWeight * f_z(u,v) )
// with f_z = 0 where the sign bits differ (a Laplacian zero crossing), else 1. All w >= 0.
//
// Kinds (which to use when: docs/notes/tracking.md):
//  * Gradient  (thesis eq. 19-22): c = floor + 1 - min(G, maxG)/maxG, maxG a robust max (percentile
//    of the non-zero |grad|), nodeWeight = w_g = 0.7, signWeight = w_z = 0.3, sign = Laplacian > 0.
//    The floor (default 0.05) keeps every edge >= w_g * floor per mm: without it every voxel whose
//    |G| reaches maxG costs exactly 0 (tens of thousands on a head CT), so between two skin points
//    115 mm apart the cheapest path wandered 882 mm over zero-cost plateaus (docs/notes/surface.md).
//    Cheap on strong edges: paths "climb along surfaces" (vessel *walls*), as in the thesis.
//    Deviation: eq. 22 with "<= 0" would make every flat region (Laplacian 0) a zero crossing;
//    the sign bit is "Laplacian > 0", so a crossing needs a strictly positive side.
//  * Vesselness (Frangi, features/vesselness.h): c = eps + (1 - min(V/maxV, 1))^power; follows
//    tube *centerlines*; polarity Bright (CTA/MRA vessels) or Dark (airways in CT).
//  * Intensity: s = clip((I - lo)/(hi - lo), 0, 1) of the (optionally Gaussian-smoothed) intensity,
//    c = eps + (1 - s)^power for Bright, eps + s^power for Dark (the peers' costs.py formula for
//    bright tubes with lo=0, hi=255, power=4, eps=1e-3). Fast and robust for contrast-filled
//    vessels and air-filled airways.
//  * Given: the voxel values themselves are the node costs (must be finite and >= 0), so the
//    search does exactly scikit-image MCP_Geometric's work (edge = len * (c(u)+c(v))/2).
// Layout: flat vectors, x fastest. Complexity O(N) (+ vesselness). Memory: 4-5 bytes per voxel.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "features/features3d.h"
#include "features/vesselness.h"
#include "graph/grid_cost.h"

namespace vs {

enum class CostKind3D { Gradient, Vesselness, Intensity, Given };
std::string costKindName(CostKind3D k);             // "gradient", "vesselness", "intensity", "given"
CostKind3D costKindFromName(const std::string& s);  // throws InvalidArgument listing the choices

struct Cost3DOptions {
  CostKind3D kind = CostKind3D::Gradient;
  double wg = 0.7;                               // gradient: w_g (eq. 19)
  double wz = 0.3;                               // gradient: w_z (eq. 19); 0 disables the zero-crossing term
  double robustMaxPercentile = 99.5;             // gradient: maxG percentile; vesselness: maxV percentile (of V > 0)
  double gradientFloor = 0.05;                   // gradient: added to every node cost (> 0: length always matters)
  TubePolarity polarity = TubePolarity::Bright;  // vesselness / intensity
  VesselnessOptions vesselness;                  // polarity is overridden by the field above
  double windowLo = std::numeric_limits<double>::quiet_NaN();  // intensity: lo (NaN: 1st percentile)
  double windowHi = std::numeric_limits<double>::quiet_NaN();  // intensity: hi (NaN: 99.9th percentile)
  double smoothMm = 0;                                         // intensity: Gaussian pre-smoothing sigma, mm (0: none)
  double power = 4;                                            // vesselness / intensity exponent
  double epsilon = 1e-3;  // vesselness / intensity floor (> 0 keeps costs positive)
};

struct NodeCost3D {
  CostKind3D kind = CostKind3D::Gradient;
  Geometry geometry;
  std::vector<float> node;    // c(u) >= 0 (+inf allowed for Given: impassable)
  std::vector<uint8_t> sign;  // gradient with wz > 0: 1 where Laplacian > 0; else empty
  float nodeWeight = 1.0f;
  float signWeight = 0.0f;
  std::string description;  // e.g. "gradient (w_g 0.7, w_z 0.3, maxG p99.5 = 412.3)"

  // The engine's cost view (arrays referenced: this object must outlive the search).
  GridCost gridCost() const;
  // Edge cost between any two voxels u, v (linear indices) at physical distance lengthMm.
  double edgeCost(int64_t u, int64_t v, double lengthMm) const {
    const size_t a = static_cast<size_t>(u), b = static_cast<size_t>(v);
    double w = nodeWeight * 0.5 * (static_cast<double>(node[a]) + static_cast<double>(node[b]));
    if (!sign.empty() && signWeight > 0) w += signWeight * ((sign[a] != 0) == (sign[b] != 0) ? 1.0 : 0.0);
    return lengthMm * w;
  }
  // Smallest possible edge cost per mm (A* bound / sanity).
  double minCostPerMm() const;
};

// The vesselness cost's shaping, c = eps + (1 - V / maxV)^power (V / maxV clamped to [0, 1]), as
// computeNodeCost3D does it: one home for a cost computed block by block with the whole volume's
// maxV (the Dask pyramid, issue 25).
std::vector<float> vesselnessCostOf(const std::vector<float>& response, double maxV, double epsilon, double power);

// Computes the node costs. `features` (optional) reuses an already computed Features3D of the
// same volume for the gradient kind. Throws InvalidArgument for bad options (negative weights,
// hi <= lo, power <= 0), DataError for NaN voxels or (Given) negative/NaN costs naming the voxel.
NodeCost3D computeNodeCost3D(const VolumeF32& volume, const Cost3DOptions& options,
                             const Features3D* features = nullptr, Progress& progress = Progress::none());

}  // namespace vs
