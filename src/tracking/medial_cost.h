// The medial term of the auto cost (issue 21: paths in wide lumens run centred). Inside a lumen
// whose intensities are flat the lumen model's cost is flat too, so the minimum-cost path is the
// shortest chord, which hugs the wall of a wide lumen or the inner side of a bend. Centreline
// tools such as VMTK minimise the integral of 1 / R, R the distance to the wall; here a term that
// falls with the distance to the wall relative to the local lumen radius is added to the cost:
//   c += weight * (1 - D / R_loc)   (D = 0, so the full weight, outside the lumen),
// where the lumen is the cost's own (voxels with s >= lumenLevel, i.e. c <= eps + (1 -
// lumenLevel)^power), D is the exact Euclidean distance (mm, anisotropic spacing) from a lumen
// voxel to the nearest voxel centre outside it (outside the volume counts as outside), and R_loc
// is the lumen's local radius: D at the ridge (medial axis) reached by steepest ascent of D from
// the voxel, following a neighbour only while D rises by at least ridgeSlope per mm (across a
// tube D rises by ~1 per mm towards the axis; along the axis it changes by the taper only, so the
// ascent stops there and every branch keeps its own radius). A voxel on the medial axis costs
// what it cost, a voxel at the wall up to `weight` more, whatever the lumen's width: the path
// keeps to the axis of a vessel of 1 or of 25 voxels radius alike.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cost/cost3d.h"
#include "volume/geometry.h"

namespace vs {

struct MedialOptions {
  // Added at the wall (0: no medial term, the default; the cost floor eps is 1e-3). 0.01 centres
  // the raw path in a wide bent lumen (test) but moved the kissing CI seed 9604 past its bound
  // (mean 1.93 -> 2.06 voxel) and the kissing tuning seeds 501-560 (mean 1.08 -> 1.30 voxel) for
  // little gain on the wide ones, whose lumen the cost mostly does not mark (session 13 wide2).
  double weight = 0;
  double lumenLevel = 0.05;  // a voxel with s >= lumenLevel is lumen (0.5: noise holes in a wide lumen, thin
                             // seeds 1-40 97.86 % within 1 voxel against 98.18 %; session 13 wide2)
  double ridgeSlope = 0.5;   // steepest ascent of D follows a neighbour while D rises >= this per mm
};

// Exact Euclidean distance (mm) from every voxel with inside != 0 to the nearest voxel centre with
// inside == 0 or outside the volume (0 for those outside); separable lower envelopes of parabolas
// (Felzenszwalb-Huttenlocher), linear in the voxel count, any spacing.
std::vector<float> distanceToOutside(const Geometry& g, const std::vector<uint8_t>& inside);

// R_loc (see above) for every voxel with distance > 0 (0 elsewhere).
std::vector<float> localLumenRadius(const Geometry& g, const std::vector<float>& distance, double ridgeSlope);

// Adds the medial term to `cost.node` (lumen: node <= lumenCost); returns the term's text for the
// cost's description ("" when weight is 0).
std::string addMedialTerm(NodeCost3D& cost, double lumenCost, const MedialOptions& options);

}  // namespace vs
