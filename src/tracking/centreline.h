// Sub-voxel centrelines: moves the voxel points of a tree of extracted paths to the lumen centre
// and gives each point a radius (issue 12).
//
// Per iteration, every point except the root is
//   1. centred in the plane normal to the tree at that point (tangent from its tree neighbours):
//      `rays` rays in that plane each stop where the intensity (trilinear) crosses the local
//      half-way level between the value at the point and the median value at maxRadiusMm (the
//      surroundings, whichever the polarity); the point moves to the mean of the crossings
//      (rays without a crossing are left out; with fewer than half the rays crossing the point
//      stays), by at most maxStepMm (or maxStepRadii x half its median chord, if larger). In a
//      lumen wider than maxRadiusMm the cast grows (doubled, up to the volume's diagonal) while
//      the surroundings at twice the length are much further from the point's value (growContrast)
//      or (growOnEscapes) fewer than half the chords find both walls; there a chord more than twice the median
//      chord long is left out where the rule for rays (twice the median) leaves too few;
//   2. smoothed along the tree: p <- (1 - w) p + w * mean(tree neighbours). Branch points are
//      ordinary tree nodes with three or more neighbours, so every branch stays joined to them.
// After the last round a final centring step (a point's step against its tree neighbours' steps
// averaged with theirs by w: no zig-zag between neighbours centred apart); the radius of a point is
// the median ray length of that step (half the smallest spacing at least). The root keeps its
// position (it is where the user clicked) but gets a radius.
// Coordinates: continuous 0-based voxel index (x,y,z); distances in mm (anisotropy honoured).
// Rays march in steps of the smallest spacing, halved once at the crossing; each stops at its
// first crossing. Complexity O(points * (iterations + 1) * rays * (radius / spacing + 2)),
// points in parallel (util/parallel.h). Thread-safe (pure function).
#pragma once

#include <cstdint>
#include <vector>

#include "util/progress.h"
#include "volume/sample.h"
#include "volume/volume.h"

namespace vs {

struct CentrelineOptions {
  int iterations = 4;       // centre + smooth rounds (0: no refinement, radii only)
  int rays = 16;            // rays per normal plane
  double maxRadiusMm = 15;  // first ray length; the surroundings are sampled here
  // Wide lumens (issue 21): a point's ray length is doubled, up to the volume's diagonal, while
  // the median value at twice the length is more than growContrast x as far from the point's
  // value as the median at the current length (the far ends were still inside the lumen); in a
  // thin vessel the far ends lie in the background and the length stays maxRadiusMm. 0: never grow,
  // the default: with 1.5 the README chest CTA airway tree got radii of 19-22 mm at its carina and
  // main bronchi (10.7 mm at most without; the rays grow through the junction into the other
  // bronchus), seen as blobs in its render; family wide lumens' radius error 4.5 -> 2.3 voxels with
  // it (docs/notes/tracking.md, session 13 lead).
  double growContrast = 0;
  // ... and also while fewer than half its chords find both walls (a point near the wall of a
  // wide lumen; session 12 wide1). Off by default: near a junction of the chest CTA's bronchi the
  // rays escape into the other branch the same way, and a point moved to within 0.75 mm of the
  // wall even with the step capped at its radius from before the growth (docs/notes/tracking.md,
  // session 13 wide2).
  bool growOnEscapes = false;
  // Wide lumens by their cross-section (issue 21, session 14): a point whose median value at twice
  // the first ray length is more than sectionContrast x as far from its value as the median at the
  // first length (its rays end inside the lumen), or fewer than half of whose chords find both
  // walls, is centred at the largest circle inscribed in its lobe of the plane normal to the path
  // (half size 2 maxRadiusMm, a local half-way level from the section's own plateau and
  // background) and takes that lobe's radius (cross_section.h). 0: never.
  double sectionContrast = 1.5;
  // ... where the section's inscribed radius exceeds wideRadii x maxRadiusMm (narrower lumens are
  // resolved by the rays) and, beyond 2 maxRadiusMm from the root along the tree, its radius is at
  // most the largest radius within that distance of the root + 1 voxel (trees narrow away from the
  // root; a faint bronchus in the lung gives the lung's section).
  double wideRadii = 0.5;
  // Wide trunks and their daughters (session 15 wide5): after the rounds, every point centred by
  // its wide section moves onto the trunk's axis (the centroid of the lumen within 1.5 section
  // radii, iterated: no direction needed), and where a chain leaves the wide lumen for a daughter
  // its own points past the trunk's axis point nearest the daughter's axis go onto the segment
  // from there to the daughter's first point; all of them are frozen (wide_trunk.h).
  bool wideTrunk = true;
  double smoothWeight = 0.5;  // w of the smoothing step, in [0,1)
  double maxStepMm = 1.5;     // largest move of one point per centring step
  // ... or this fraction of half the point's median chord when larger (a point far off the axis
  // of a wide lumen reaches it in a few rounds), but once a point's cast has grown not more than
  // its median radius before the growth (when at least half its rays crossed then).
  double maxStepRadii = 0.5;
  // A point whose last centring step and whose drift since are both under settleVoxels (x the
  // smallest spacing) has settled and is not cast again (0: every point in every round).
  double settleVoxels = 0.05;
  // The first coarseRounds rounds march every second ray (when `rays` is a multiple of 4): the
  // points move by up to a voxel there; the later rounds and the radii use every ray.
  int coarseRounds = 2;
  // Points per thread of a round (util/parallel.h). A point costs ~1-3 us per round, starting a
  // thread 0.8-3 ms on the 2-core VM this was measured on (~0.05 ms on bare metal): a second
  // thread pays only for large trees (a 10-path tree of a 256^3 phantom has ~800 points).
  int64_t pointsPerThread = 2048;
  // Side branches: where a child continues its parent (a trunk), the points of each side branch
  // whose cross-section (a disc of the branch's own radius) is fused with the trunk are placed on
  // the segment from the branch point to the branch's first round section instead of being
  // centred and smoothed there; the trunk is left alone (centreline.cpp: placeJunctions). On the
  // vessel family's tuning seeds 1-40 it raised the share within 1 voxel a little (97.91 ->
  // 98.02 %, docs/notes/tracking.md, session 12); on the aorta MRA it keeps renal paths out of
  // the aorta's lumen without pulling the aorta's axis towards the ostia. Where a branch point's two
  // children have axes that meet near it, both children's fused points are placed instead on the
  // segments from that junction to their first round sections (session 13: 98.02 -> 98.19 %, 24 ->
  // 27 of 37 seeds >= 98 %); where the two children's chains run together from the branch point
  // through the fused section, their points beyond the junction go onto each child's axis
  // (placeParted, session 14: 98.18 -> 98.67 % on the 37 seeds that ran on main, 24 -> 28 >= 98 %).
  bool junctions = true;
  // Forks whose discrete branch point lies past the junction (the children's paths share the
  // parent's points beyond it, a fused section both paths run through): with junctions on, the
  // tree is re-branched there before the junction zones are placed: the shared points between the
  // junction J (where the children's axes meet, as placeFork's) and the branch point are copied for
  // each further child, so each child leaves J on its own points (session 14). The output tree
  // then has more points than the input (RefinedCentreline::parent, source).
  bool splitForks = true;
  // Touching lumens (kissing vessels, session 14 kiss4): a ray whose value falls by saddleContrast
  // x |value at the point - half-way level| below the most lumen-like value on it and rises again
  // by as much, before it crosses the level, ends at its least lumen-like sample (the neck between
  // two touching tubes), so the point is centred in its own tube (centreline.cpp: SaddleStop).
  // 0 (off) by default: at 0.2 the family's kissing variant goes 79.99 -> 82.87 % within 1 voxel
  // and thin seeds 1-40 98.18 -> 98.46 %, but on the README chest CTA airway example one refined
  // point (of 284) at a bronchial junction moves from 0.84 to 0.69 mm of the wall (the criterion
  // is none within 0.75 mm): the airway's level lies near the soft tissue, so thin bronchial walls
  // that stay below it are saddles too (docs/notes/tracking.md, session 14 kiss4).
  double saddleContrast = 0;
  // Touching lumens by their section (session 18 kiss8): a point some of whose rays escape (longer
  // than twice the median or no crossing) and whose section holds two lobes (own_lobe.h:
  // basins of the lumen-ness apart where the valley between them is deeper than lobeValley x the
  // lower peak) moves to the centroid of its own lobe, the one holding its path voxel (the raw path
  // lies in its own tube where the rays' chords pulled the point across the contact: kiss4's
  // "pulled" class), where that lobe is one the rays resolve (radius <= wideRadii x maxRadiusMm).
  // 0: off. Family tuning seeds (docs/notes/tracking.md, session 18 kiss8): kissing 84.35 -> 88.48 %
  // within 1 voxel, thin 1-40 98.98 -> 99.19 % (33 -> 36 seeds >= 98 %).
  double lobeValley = 0.1;
  // ... and a point none of whose rays escaped but whose longest ray is more than lobeLongRay x
  // their median (a contact thinner than the escape rule sees: session 22's blind kissing seed 10607,
  // tubes 0.03 voxel apart, the wider tube's rays reached 1.65-1.8 medians into the narrower one and
  // its points sat 1.1 voxels off towards it), where it lies farther along the tree than
  // lobeForkRadii x its median ray from every branch point (a fork's fused section is two lobes too;
  // its points are the junctions'). 0: only escapes (docs/notes/tracking.md, session 23 kiss16).
  double lobeLongRay = 1.7;
  double lobeForkRadii = 4;
  // ... and a point whose lumen another traced path's touches, away from forks alike (a neck that stops every ray
  // short of the other tube: neither trigger above sees it; the family's 524), where that path's voxel lies in the
  // other of the section's two lobes (centreline_junctions.h: touchingPaths; docs/notes/tracking.md, session 37
  // touch37). false: the rays' triggers only.
  bool lobeTouching = true;
  // Forks where the children's chains part (session 25 fork3): where two sibling paths' voxels stay
  // neighbours from the search tree's fork on over at least togetherForkMm along the earlier one (they differ
  // by a voxel through their common parent), they are one chain there and the fork lies where they part
  // (centreline_junctions.h: mergeTogetherChains). Shorter runs are how discrete paths part at any fork: with
  // every run merged, 163 -> 156 of 184 tuning lines met; from 10 mm 163 -> 164 (docs/notes/tracking.md,
  // session 25 fork3). 0: the search tree's forks as they are.
  double togetherForkMm = 10;
  // A thinner tube fused with a touching wider one into one blob no slice or pixel resolves (session 26 kiss21):
  // a point whose last cast's radius is over fusedBumpRadii x that of a point up and of a point down its plain
  // chain (those two within fusedBumpReachRadii x its radius along the path), or that another traced path's point
  // lies within the smaller of their radii of, though their path voxels lie farther apart and their fork more than
  // lobeForkRadii x the larger radius along the tree (drawn together with no bump: its unfused ends the chain's first
  // points not so drawn; session 32 kiss36), has its cross-section's intensities
  // fitted as one blurred disc and as two (the own at its chain's radius, the other free); where two explain the
  // section better by more than twoTubeBic (the Bayesian information criterion's difference) on at least
  // twoTubeRun consecutive points of the chain (or two or more spanning twoTubeRun - 1 of the finest spacing, across
  // thick slices) whose two centres move smoothly, and the other tube is seen going on beside the own one past both
  // ends of that stretch, keeping its calibre (the run's median other radius and the two ends' within 2x: a bulge, an
  // ostium or a tangle has no such tube), each goes to its own disc's centre, and so do the stretch's decisive points
  // between the run and its unfused ends and those ends themselves (centreline_junctions.h: fitTwoTubes;
  // docs/notes/tracking.md, sessions 29 kiss25, 30 kiss29, 31 kiss35 and 34 kiss38). 0: off.
  double fusedBumpRadii = 1.5;
  double fusedBumpReachRadii = 12;
  double twoTubeBic = 10;
  int twoTubeRun = 3;
};

struct CentrelineTree {
  std::vector<Vec3> points;     // continuous voxel index
  std::vector<int32_t> parent;  // -1 for the root (point 0)
};

struct RefinedCentreline {
  std::vector<Vec3> points;     // continuous voxel index: the input's points in its order first,
                                // then any copies made where a fork was re-branched (splitForks)
  std::vector<double> radiiMm;  // per point
  std::vector<int32_t> parent;  // the refined tree: per point its parent (-1: the root)
  std::vector<int32_t> source;  // per point the input point it is (or is a copy of)
  // per point: 1 placed on a wide trunk's axis or a daughter's way out of it, inside the lumen of its
  // section's level by construction (VesselTracker::confineToLumen leaves it); 2 kept on the axis where
  // its rays centred it, deep in its lumen (confineToLumen moves it at most half the finest spacing)
  std::vector<uint8_t> wideTrunk;
  int polarity = 0;  // the lumen at the root against its surroundings: 1 brighter, -1 darker, 0 neither
};

// The refined points of one root-to-end chain of the input tree (its input point indices in order,
// e.g. VesselTracker::pathTreePoints): the chain walked up the refined tree from its last point,
// which takes the copies where a fork was re-branched. The input chain itself when that walk does
// not give a chain of the same length.
std::vector<int32_t> refinedChain(const RefinedCentreline& refined, const std::vector<int32_t>& inputChain);

// Per refined point the input point whose path voxel is its own (of `inputCount` input points): its
// source, unless that source was copied for a sibling (splitForks' re-branched forks, a wide trunk's
// daughters): the discrete routes' shared stretch past the junction, whose voxels lie in one child's
// lumen at most; then the source of the first point down its own chain that is no copy's (session 31,
// thin28: 10503's pull into the sibling). Its source where the chain forks or ends first.
std::vector<int32_t> ownPathVoxels(const RefinedCentreline& refined, size_t inputCount);

// `intensity`: the (smoothed) intensities of the lumen. Throws InvalidArgument on inconsistent
// sizes or points outside the volume, Cancelled through progress.
RefinedCentreline refineCentreline(const VolumeF32& intensity, const CentrelineTree& tree,
                                   const CentrelineOptions& options = {}, Progress& progress = Progress::none());

// The intensities refineCentreline centres paths in, for node costs computed from `volume`:
// `volume` Gaussian-smoothed by smoothMm (0: as is). With costsGiven (the voxels are the costs
// themselves) the paths are centred in the cost valleys, and impassable (non-finite) voxels take
// the 99.9th percentile first, since inf would poison the interpolation.
VolumeF32 refinementIntensity(const VolumeF32& volume, double smoothMm, bool costsGiven,
                              Progress& progress = Progress::none());

}  // namespace vs
