// A route's second search in its own lumen, centred by the medial term (issue 21, the flat variant). Main's cost is
// at its floor over the whole lumen, so inside a flat (sinus-like) lumen every target's geodesic is its own straight
// line across the floor and paths that share the trunk fan apart from the root. The medial term (medial_cost.h)
// read to the section's crest gives such a section one cheapest line, but fed to the first search everywhere it
// pulls a thin kissing tube's route into its wider neighbour (session 46 flatcost / flatsearch). Here the first
// search keeps main's cost; each route found is then searched again, root to target, on main's cost plus the term,
// over the voxels of the route's own lumen only: the lumen voxels connected to the route within its own section's
// reach of the route point they are reached from (the longest in-plane ray from that point to the wall: every
// voxel of a convex section lies within it, and a neighbour beyond a contact lies further than the own section).
#pragma once

#include <functional>
#include <limits>
#include <vector>

#include "cost/cost3d.h"
#include "volume/volume.h"

namespace vs {

struct RecentreOptions {
  double weight = 0.01;  // the medial term at the wall (session 13's value; 10 x the cost floor)
  int rays = 16;         // in-plane directions read for a route point's reach
};

// The image a section's reach reads besides the lumen mask (smoothed null: the mask alone). Two tubes fused at a
// contact make one lumen in the mask, but across the contact the smoothed intensity can dip between the two tubes'
// centres or rise into the brighter one; a flat lumen's section is one plateau. A ray's reach stops at the bottom of
// a dip it rises from by more than dipFloor, above the bottom and the own maximum before it, or above the bottom
// alone where the dip was that deep too (sectionReach in lumen_recentre.cpp).
struct RecentreImage {
  const VolumeF32* smoothed = nullptr;  // the intensities the cost saw
  double sign = 1;                      // -1: a dark lumen (the intensity read as sign x value)
  double dipFloor = 0;                  // a dip shallower than this is noise (the model's valley floor)
  double surround = std::numeric_limits<double>::quiet_NaN();  // the model's background B (sectionShape's level)
};

// The route (root -> target) searched again on cost + medial term, confined to its own lumen (voxels with node cost
// <= lumenCost); the same route when nothing better is found. Both ends are kept. taken (linear voxel index; may be
// nullptr): the voxels of the routes centred before, which cost no term - in a lumen they share they are its centre
// line already, and a line one voxel beside them would part the paths (a fan of near-equal centred lines).
std::vector<Index3> recentreInOwnLumen(const NodeCost3D& cost, double lumenCost, const std::vector<Index3>& route,
                                       const std::function<bool(int64_t)>* taken = nullptr,
                                       const RecentreOptions& options = {}, const RecentreImage& image = {});

// Whether most sections of route[from, to) read one flat lumen by their shape (section_shape.h): elongated (aspect >=
// 1.5), no waist (>= 0.8 in the mask's and the contrast's profiles) and a plateau (>= 0.645 of the section beyond
// 3/4 of its peak contrast). False without the image.
bool sectionsReadFlat(const Geometry& g, const std::vector<Index3>& route, size_t from, size_t to, double halfMm,
                      const RecentreImage& image);

// Whether a route's start (its points within two root radii of the root) reads one flat lumen, its sections read
// over four root radii (a section of aspect up to 4 from any point in it).
bool routeStartReadsFlat(const Geometry& g, const std::vector<Index3>& route, double rootRadiusMm,
                         const RecentreImage& image);

}  // namespace vs
