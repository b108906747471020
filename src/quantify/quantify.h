// Vessel and airway quantification along centrelines (issue 24): lumen cross-sections measured
// in the image, per-segment / per-path / per-branch-point measures and the tree's topology.
//
// Input: a volume and a tree of centreline points in world mm (vs::Tree: what `trace` writes to
// SWC / JSON, refined positions and radii). The tree is split into segments (root or branch
// point -> branch point or tip); every segment is resampled every `stepMm` of arc length and at
// each sample a cross-section is measured (plus one section next to each branch point on each of
// its segments, BranchPointMeasure):
//   * plane orthogonal to the local tangent (chord of the centreline over +-max(1 mm, r));
//   * `rays` rays from the centre in that plane, sampled trilinearly (volume/sample.h) every
//     `sampleStepVoxels` x the smallest spacing, world mm mapped through the volume's geometry
//     (spacing and direction honoured);
//   * lumen level L = median of the samples within half the lumen radius of the centre, wall
//     level W = median of the samples in the ring [1.5 r + 1 voxel, 2 r + 2 voxels] around it;
//     each ray stops at its first crossing of the half-maximum (L + W) / 2, linearly
//     interpolated (sub-voxel); r is re-estimated from the crossings and the step repeated
//     (up to 3 times) and the centre moved once to the boundary's centroid;
//   * the boundary polygon gives the area (shoelace), the equivalent diameter 2 sqrt(A / pi)
//     and the minimum / maximum Feret (caliper) diameters with their world directions.
// The lumen's polarity (bright vessel in CTA/MRA, dark airway in CT) is chosen per tree from the
// median contrast of all sections unless given.
// Flags (a flagged section keeps its position but no numbers, NaN): LeavesVolume (a ray or the
// wall ring leaves the volume), MeetsBranch (another segment's lumen crosses the section's plane
// within the section's outer radius: the branch-point rule, also for touching neighbours),
// NoBoundary (more than a quarter of the rays find no crossing: no lumen here).
// Thread-safe (pure functions); sections in parallel (util/parallel.h).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

enum class LumenPolarity { Auto, Bright, Dark };
std::string lumenPolarityName(LumenPolarity p);                // "auto", "bright", "dark"
LumenPolarity lumenPolarityFromName(const std::string& name);  // throws InvalidArgument

struct QuantifyOptions {
  double stepMm = 0.5;             // arc length between cross-sections
  int rays = 48;                   // rays per cross-section (>= 8)
  double sampleStepVoxels = 0.25;  // ray sampling step, x the smallest spacing
  double maxRadiusMm = 25;         // longest ray (lumen radius + wall ring)
  LumenPolarity polarity = LumenPolarity::Auto;
  // Stenosis reference (per segment): a line d_ref(s) fitted to the sections not narrower than
  // healthyFraction x the line (iterated), i.e. the healthy lumen proximal and distal to the
  // narrowing interpolated across it; at least two healthy sections on each side of the
  // minimum, else no stenosis is reported (NaN: a taper to the end is not a stenosis). stenosis = 1 - d_min /
  // d_ref(s_min), d_min the smallest measured equivalent diameter of the segment.
  double healthyFraction = 0.9;
  // Noise guard (both must hold, else no stenosis is reported, NaN): the narrowed run - the
  // contiguous sections around the minimum below healthyFraction x d_ref - spans at least
  // stenosisMinLengthVoxels x the largest spacing (a narrowing shorter than the image resolves
  // is a noise blob), and the narrowing d_ref - d_min is at least stenosisSignificance x the
  // scatter of the healthy sections about the line (1.4826 x their median absolute residual).
  double stenosisMinLengthVoxels = 2.0;
  double stenosisSignificance = 3.0;
  // Focal only: a narrowed run longer than stenosisMaxLengthDiameters x d_ref is a taper or diffuse
  // disease (ACC/AHA type C: > 20 mm in a ~3 mm coronary), not reported as a stenosis either.
  double stenosisMaxLengthDiameters = 7.0;
  // Branch directions: the chord of a segment between arc a1 = directionStartRadii x r and
  // a1 + max(directionMinLengthMm, directionLengthRadii x r) from the branch point (r: the parent's
  // lumen radius there), clamped to the segment.
  double directionStartRadii = 2.0, directionLengthRadii = 3.0, directionMinLengthMm = 3.0;
  int64_t sectionsPerThread = 256;
};

enum CrossSectionFlag : uint32_t {
  kSectionLeavesVolume = 1u,
  kSectionMeetsBranch = 2u,
  kSectionNoBoundary = 4u,
};
// "leaves_volume|meets_branch|no_boundary" (empty for a measured section).
std::string crossSectionFlagsText(uint32_t flags);

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct CrossSection {
  int segment = -1;
  double arcMm = 0;        // along its segment, from the segment's first point
  Vec3 centreMm{0, 0, 0};  // world mm (moved to the boundary's centroid when measured)
  Vec3 tangent{0, 0, 1};   // world unit vector
  double areaMm2 = kNaN, equivalentDiameterMm = kNaN, minDiameterMm = kNaN, maxDiameterMm = kNaN;
  Vec3 minDirection{0, 0, 0}, maxDirection{0, 0, 0};  // world unit vectors of the Feret diameters
  double outerRadiusMm = 0;                           // largest boundary distance from the centre (or the hint radius)
  double lumenLevel = kNaN, wallLevel = kNaN;
  uint32_t flags = 0;
  std::vector<Vec3> boundaryMm;  // the lumen boundary (one point per ray, world mm); empty when flagged
  int branchPoint = -1;          // a branch point's neighbour section: its index in branchPoints
  bool measured() const { return flags == 0; }
};

struct SegmentMeasure {
  std::vector<int32_t> nodes;  // tree nodes, first = root or branch point, last = branch point or tip
  std::vector<int> sections;   // indices into TreeMeasurement::sections, by arc
  int parent = -1;             // parent segment (-1: starts at a root)
  std::vector<int> children;
  int generation = 0;  // root segment 0, +1 per branch point
  int strahler = 1;    // Strahler order: tips 1; max of the children, +1 when two share the max
  double lengthMm = 0, chordMm = 0;
  double distanceMetric = kNaN;    // length / chord (1: straight)
  double sumOfAnglesRadPerCm = 0;  // Bullitt's SOAM on the centreline resampled every 1 mm
  int measuredSections = 0;
  double meanDiameterMm = kNaN, minDiameterMm = kNaN, minArcMm = kNaN;  // equivalent diameters
  double referenceDiameterMm = kNaN, stenosis = kNaN;                   // see QuantifyOptions
  double stenosisLengthMm = kNaN;  // the narrowed run's length (also when the noise guard refused it)
  double branchAngleDeg = kNaN;    // direction change from the parent's end direction (0: straight on)
};

struct PathMeasure {  // root -> tip
  std::vector<int> segments;
  int tipNode = -1;
  double lengthMm = 0, chordMm = 0, distanceMetric = kNaN, sumOfAnglesRadPerCm = 0;
  double meanDiameterMm = kNaN, minDiameterMm = kNaN, minArcMm = kNaN;  // arc from the root
  double stenosis = kNaN, stenosisArcMm = kNaN;  // the largest of its segments' (position from the root)
  // The profile: the path's sections in order (a branch point's section once), arc from the root.
  std::vector<int> sections;
  std::vector<double> arcMm;
};

struct BranchPointMeasure {
  int32_t node = -1;
  Vec3 positionMm{0, 0, 0};
  int parentSegment = -1;  // -1 at a root with several children
  std::vector<int> childSegments;
  std::vector<double> childAnglesDeg;  // per child: angle between the parent's and the child's directions
  std::vector<double> pairAnglesDeg;   // per pair of children (i < j, row order): angle between them
  // Neighbour sections (indices into TreeMeasurement::sections, -1: none): on each of its
  // segments, the measured section nearest the branch point that no other branch meets (searched
  // every step/8 between the regular stations, added to the segment's sections). Their diameters
  // are the parent's and the children's lumen next to the junction.
  int parentSection = -1;
  std::vector<int> childSections;  // per child segment
};

struct TreeMeasurement {
  Tree tree;               // the tree measured: the input after mergeCoincidentBranches (node indices refer to it)
  int mergedBranches = 0;  // coincident branches merged
  LumenPolarity polarity = LumenPolarity::Bright;  // the one used
  std::vector<CrossSection> sections;
  std::vector<SegmentMeasure> segments;
  std::vector<PathMeasure> paths;
  std::vector<BranchPointMeasure> branchPoints;
  int measuredSections() const;
};

// Throws DataError when the tree does not belong to the volume: a point outside it by more than
// one voxel (different geometry, wrong file), or no point inside it; InvalidArgument for a bad
// tree or options; Cancelled through progress.
TreeMeasurement measureTree(const VolumeF32& volume, const Tree& tree, const QuantifyOptions& options = {},
                            Progress& progress = Progress::none());

// Two sibling branches that leave a branch point inside the same lumen (a search through a wide,
// flat-cost lumen such as the trachea splits at once and the refinement centres both paths) are
// one branch until they separate: the shorter one's nodes within half the other's radius of it
// are dropped and the rest is hung on its nearest node, so the branch point moves to where the
// lumens part. Repeated until no pair coincides over two or more nodes; `merged` counts the
// merges. Trees without radii are returned unchanged.
Tree mergeCoincidentBranches(const Tree& tree, int* merged = nullptr);

// Checks only the tree against the volume (the first part of measureTree).
void checkTreeInVolume(const Geometry& geometry, const Tree& tree, const std::string& treeName = "tree");

// The measured tree (m.tree) with each node's radius from the measured cross-sections of its
// segment (half the equivalent diameter of the nearest measured section by arc); nodes of a
// segment without one keep their radius. flaggedAsNaN (for colouring by diameter, where a flagged
// section must not borrow its neighbour's number): the nearest section of any kind decides, a
// flagged one gives NaN, and nodes of a segment without sections get NaN.
Tree treeWithMeasuredRadii(const TreeMeasurement& m, bool flaggedAsNaN = false);

}  // namespace vs
