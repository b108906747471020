// Kissing vessels (issue 21, session 18 kiss8): the centre of a thin point's own tube where its
// cross-section is fused with a touching neighbour's. Two touching tubes are one region above the
// half-way level, so the refinement's rays from one run through the contact into the other and the
// chords pull the point towards the pair's middle (kiss4's "pulled" class, the largest of the kissing
// misses). In the section the two tubes still show as two lobes of the region: each has its own
// intensity plateau with a valley between them (the partial-volume dip at the contact, smoothed), or
// a waist in the region's outline.
//
// `ownLobe` samples the plane normal to `tangent` at `c` (half size halfMm, step half the smallest
// spacing), takes the 4-connected component of samples beyond `level` (the lumen's side) that holds
// the sample nearest `anchor` projected into the plane (the point's own path voxel: it lies in the
// own tube, where the refined point may already have been pulled out of it) and divides it into
// lobes by the valleys of a lumen-ness that is the intensity's excess over the level times the
// distance to the region's edge (a watershed: every sample climbs by steepest ascent to a peak; two
// peaks' basins are one lobe unless the highest saddle between them lies below both peaks by more
// than `valleyShare` x the lower peak). Where the component holds more than one lobe, the own lobe
// (the anchor's) gives the centre (its samples' centroid) and the radius (its area as a circle's);
// else nothing (split false: one tube, the rays' result stands). O((halfMm / step)^2) samples.
// Thread-safe with one scratch per thread.
#pragma once

#include <cstdint>
#include <vector>

#include "volume/sample.h"

namespace vs {

struct LobeScratch {
  std::vector<float> value, height;
  std::vector<int32_t> label, stack, parent;
  std::vector<uint8_t> inside, heightKnown;  // heightKnown: height formed (ownLobe forms it where first read)
  std::vector<float> dist2, tmp, peak;
  std::vector<int32_t> idx;
  struct Edge {
    float saddle;
    int32_t a, b;
  };
  std::vector<Edge> edges;
};

struct LobeResult {
  bool split = false;    // the component holds more than one lobe
  Vec3 centre{0, 0, 0};  // mm (index x spacing), the own lobe's centroid
  double radiusMm = 0;   // the own lobe's area as a circle's radius
  int lobes = 0;         // lobes of the component
  // Also with one lobe: the own lobe's peak of lumen-ness (its deepest sample, refined by a parabola along each axis;
  // mm) and its width, 4 x its samples' spread along its long axis (a disc's diameter; mm). 0 where it has no samples.
  Vec3 peak{0, 0, 0};
  double widthMm = 0;
};

// `c`, `anchor` in mm (index x spacing); `bright`: the lumen lies above `level`.
LobeResult ownLobe(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                   const Vec3& anchor, double level, bool bright, double halfMm, double valleyShare,
                   LobeScratch& scratch);

// A path voxel beside a fork's junction (two children's discrete paths run side by side through their
// parent and part late) can lie in the sibling's lobe, so the anchor's lobe is not the point's own (blind
// 10828 and 10809): true where both ends[0..1] (the point's parent and child, mm) lie in a lobe of the section at
// `c` other than the one centred at `ownCentre` (its centroid more than half a sample step away). `count`: how many
// points `ends` holds (1: a touching path's voxel, session 37 touch37).
bool neighboursInOtherLobe(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                           const Vec3* ends, double level, bool bright, double halfMm, double valleyShare,
                           const Vec3& ownCentre, LobeScratch& scratch, size_t count = 2);

// The own lobe read as another traced path's tube (issue 21, session 44 forkG): the lobe the anchor (the point's own
// path voxel, inside its own tube) falls in has its centre nearer the voxel of a path touching the point (`touching`,
// touchingPaths; null: none) than the anchor. The own lobe's centre lies on the own tube's axis, within the own radius
// of the anchor; nearer the other path's voxel it is that tube's, or the union's where the other tube crosses the
// section's plane - a stripe across the section, not a disc, which the valleys split off with a part of the own disc
// (scan thin forced 7321: b1's hairpin return limb crossing b2's start, the "own" lobe's centre 3.1 mm from b2's voxel
// and 5.3 mm from the anchor). The rays' step stands there, as where the section holds one lobe. Both voxels are whole
// cells' samples: the lobe counts as the other's only where it is nearer that voxel by more than `cellMm`, half a
// cell's diagonal (fitTwoTubes' allowance for a path voxel; on 2.2 mm slices the anchor may sit a half slice off its
// lumen's middle - the sweep's 11709 and 11301 lost their points without it).
inline bool lobeNearerTouching(const Vec3& lobeCentre, const Vec3& anchor, const Vec3* touching, double cellMm) {
  return touching && (lobeCentre - *touching).norm() + cellMm < (lobeCentre - anchor).norm();
}

// The one child of a point on a plain chain (neither its parent nor its child a branch point: a fork's b
// lies in both children's lobes, so it says nothing of which is the point's); 0 elsewhere.
size_t plainChainChild(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children, size_t k);

// Per tree point (parents before their children, parent -1 for the root) its distance along the
// tree (mm, positions q) to the nearest branch point (a point with two or more children); +inf in
// a tree without one. O(points).
std::vector<double> alongTreeFromForks(const std::vector<int32_t>& parent, const std::vector<Vec3>& q);

}  // namespace vs
