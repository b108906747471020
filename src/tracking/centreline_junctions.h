// Junctions and forks of refineCentreline (internal to src/tracking; centreline_junctions.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "tracking/centreline.h"
#include "volume/geometry.h"
#include "volume/sample.h"

namespace vs::centreline_detail {

// refineCentreline's preconditions (centreline_input.cpp; throws InvalidArgument naming the first that fails).
void validateRefineInput(const VolumeF32& vol, const CentrelineTree& tree, const CentrelineOptions& o);

// The refinement's last centring step per point (`step`, mm) smoothed along the tree into `out` (centreline_input.cpp):
// where it points against the mean of its tree neighbours' that take a step (the root and placed, frozen points do
// not), (1 - weight) x its own + weight x that mean; elsewhere, at ends and frozen points its own.
void smoothSteps(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                 const std::vector<uint8_t>& frozen, double weight, const std::vector<Vec3>& step,
                 std::vector<Vec3>& out);

// Each branch point that the fork placements left free (not frozen) moved once by the bias of the rounds' smoothing
// at it (centreline_input.cpp): the smoothing's target is the mean of all its tree neighbours, which at a fork weighs
// the children 2 : 1 and draws the point into the crotch, past the junction (the family's 511: 1.06 voxels off one
// child's axis, within a voxel of the other's); a chain point's target lies mid-way between its parent and its
// children's mean. The step is the difference of the two targets, so a point at the rounds' rest (smoothing against
// centring) goes where it would rest with the chain point's target (its centring step unchanged). Done in the rounds
// instead, the changed dynamics at every fork cost five thin seeds (docs/notes/tracking.md, session 29 thin23).
void balanceFreeForks(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                      const std::vector<uint8_t>& frozen, std::vector<Vec3>& q);

// The refinement's final centring step smoothed (smoothSteps) and taken (centreline_input.cpp): `q` holds the points
// after the unsmoothed step and receives rested + the smoothed one; returns those stepped positions.
std::vector<Vec3> smoothFinalStep(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                                  const std::vector<uint8_t>& frozen, double weight, const std::vector<Vec3>& rested,
                                  std::vector<Vec3>& q);

// Per point whether it lies within reachMm of the root along the tree (the root's lumen; centreline_input.cpp).
std::vector<uint8_t> nearRootPoints(const CentrelineTree& tree, const std::vector<Vec3>& q, double reachMm);

// The refinement's result (centreline_input.cpp): the points `q` (mm) in continuous voxel index, the radii (sized as
// q in `out`) at least half the smallest spacing, the tree (`parent`, `source`: moved into `out`).
void finishRefined(const std::vector<Vec3>& q, const Vec3& spacing, std::vector<int32_t>& parent,
                   std::vector<int32_t>& source, RefinedCentreline& out);

struct JunctionInput {
  const std::vector<int32_t>& parent;
  const std::vector<std::vector<int32_t>>& children;
  const std::vector<double>& radius;  // per point: its last cast's median ray (mm)
  // per point: its input (discrete path) voxel's position (mm; placeParted's notPastParting); empty: not known
  std::function<Vec3(size_t)> raw = {};
  double coarseMm = 0;  // the volume's coarsest spacing (mm; 0: not known - the smallest is used)
  // lobeCentre(k, dir, outerMm, innerMm, maxMm, centre): placeParted's lobe of point k's section along its widest chord
  // dir, from the wall at outerMm to the one at innerMm (signed, from q[k]): lobeCentreFromWalls; empty: not known
  std::function<bool(size_t, const Vec3&, double, double, double, Vec3&)> lobeCentre = {};
};

// Per point, the rounds' last centring step (each round's centring and smoothing, from its position before the round
// to after it) and whether it pointed against the one before (a negative dot product; session 36 kiss36): the
// iteration swings about its rest instead of settling there (final_step.cpp). begin() before a round, end()
// after; copy(k) appends a copy of point k's state (a point copied by splitForks / placeWide).
struct RoundSteps {
  std::vector<Vec3> before, last;
  std::vector<uint8_t> reversed;
  void begin(const std::vector<Vec3>& q);
  void end(const std::vector<Vec3>& q);
  void copy(size_t k);
};

// The final centring's step taken back (session 36 kiss36; final_step.cpp) where the rounds were swinging (their
// last two steps reversed), the final step goes on the way the last round went, towards another traced path whose
// lumen touches the point's, and no later placement moved the point (q still `stepped`). A swinging point's rest lies
// between its last two positions; a step on past the last one, away from the one before, leaves that bracket - one
// more swing, unsmoothed along the tree unlike the rounds'. Towards a touching tube it is the chords through the
// fused blob that swing the point (a kissing contact: the family's 11108 / 521). Another traced path: a point of
// another branch more than lobeForkRadii x the larger radius along the tree from it (drawnTogether's fork exclusion),
// whose path voxel (`in.raw`) lies within the sum of the two radii of the point's rest and nearer its stepped
// position. The point keeps the rounds' position (`rested`), where its radius was measured. Returns the count held.
size_t holdReversedSteps(const JunctionInput& in, const CentrelineOptions& o, const RoundSteps& rounds,
                         const std::vector<Vec3>& rested, const std::vector<Vec3>& stepped, std::vector<Vec3>& q);

// Per point of a radius bump on its plain chain (CentrelineOptions::fusedBumpRadii), or drawn inside another traced
// path's point's radius far from their fork with no bump, or touched by another traced path (touchingPaths) where its
// last own-lobe look found one lobe (`oneLobe`, centreline.cpp's ownLobeOffset: the fused contact the rounds cannot
// split; null: none), its cross-section normal to
// the chain, sampled trilinearly, fitted as one partial-volume-blurred disc and as two (the own
// disc at the chain's radius); points of runs of o.twoTubeRun consecutive decisive sections (or of the length they
// span on isotropic voxels) go to their own disc's centre where the other tube goes on past both ends of the run, and
// so do the decisive points between the run and its unfused ends, and the unfused ends themselves (their end sections'
// own centres; two_tubes.cpp). Returns the count moved.
size_t fitTwoTubes(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                   const TrilinearSampler& sample, const Vec3& spacing, std::vector<Vec3>& q,
                   std::vector<double>* radiusOut = nullptr, const std::vector<uint8_t>* oneLobe = nullptr);

// The cubic Hermite segment from a (tangent ta) to b (tangent tb) at s in [0, 1] (fork_centring.cpp).
Vec3 hermite(const Vec3& a, const Vec3& ta, const Vec3& b, const Vec3& tb, double s);

// A chain's own curve between two of its points, a up the tree from b (session 39 kiss232; fork_centring.cpp): the
// Hermite segment from q[a] to q[b] whose tangents are the chain's directions beyond them (over chainTangentSteps
// points outward, centre35's arm direction), both scaled by |q[b] - q[a]|, at s in [0, 1]. A straight chain gives its
// straight line; a bending one its bend, where the straight line would cut across the bend's inside.
inline constexpr size_t chainTangentSteps = 3;
Vec3 chainCurveAt(const JunctionInput& in, const std::vector<Vec3>& q, size_t a, size_t b, double s);

// A fork's fused junction blob (centre35, fork36): a section wider than an arm's own radius `own` by blobRadii times
// (or by half a voxel, the smaller) is the blob's, not the arm's; an arm's own radius is the median over at most
// ownRadiusPoints of its points (sections) past the junction's reach.
inline constexpr double blobRadii = 1.2;
inline constexpr size_t ownRadiusPoints = 20;
inline double blobWidth(double own, double voxMm) { return std::min(blobRadii * own, own + 0.5 * voxMm); }

// Points k and j lie within the fork reach of each other along the tree (two_tubes.cpp): a point up the tree from k
// and from j within lobeForkRadii x the larger of their radii along the input points is the same - one tube's forking,
// not two tubes touching (drawnTogether's and holdReversedSteps' exclusion). upK / upJ: scratch.
bool withinForkReach(const JunctionInput& in, const CentrelineOptions& o, size_t k, size_t j, std::vector<size_t>& upK,
                     std::vector<size_t>& upJ);

// Per point, another traced path whose lumen touches it (session 37 touch37; touching_paths.cpp): the point (-1:
// none) whose path voxel (`in.raw`) lies nearest the point's position `q` within the sum of the two radii
// (`in.radius`, the last casts'), of another branch more than lobeForkRadii x the larger radius along the tree from it
// (withinForkReach: not its own fork), where the two paths parted before the touch: up the point's chain, a point with
// no voxel of another line of the tree within the two radii comes before a branch point or the root (else the paths
// share one tube from their fork on: a narrow fork's children side by side, two paths along one trunk's walls - the
// family's 11230 / 11328). Points of unknown radius (0: not cast yet) are neither touched nor touch. The rounds'
// own-lobe step (centreline.cpp) takes it as a trigger where that voxel lies in the other of two lobes.
std::vector<int64_t> touchingPaths(const JunctionInput& in, const CentrelineOptions& o, const std::vector<Vec3>& q);

// Runs of points no cast centred (session 36 contact36; uncentred_runs.cpp): `cast` per point 0 never cast, 1 cast
// but never moved by its cast (too few chords in every round and the final one: rule 0's, and rule 2 refused - a
// route along a wall whose section is not round or not closed, as at a kissing contact), 2 centred by a cast. A
// plain chain's run of 1s whose neighbours up and down are plain, unplaced points centred by their own casts (the
// tube's own axis either side, not a fork's or a daughter's ostium), their radii within fusedBumpRadii x each other
// (one tube either side, neither end a bump: a junction blob, a wider lumen), goes onto the straight line between them,
// at each point's share of the way along the path voxels, where every run point lies within lobeForkRadii x each end's
// radius of it along the path; each point only where that line lies within the own radius (interpolated between the
// ends) of its path voxel's cell (xfit34's lumen test), its radius then the interpolated one. Returns the count moved.
size_t lineUncentred(const JunctionInput& in, const std::vector<uint8_t>& frozen, const std::vector<uint8_t>& cast,
                     const CentrelineOptions& o, const Vec3& spacing, std::vector<Vec3>& q,
                     std::vector<double>& radiusOut);

// The shared chain's points in a fork's fused junction blob (session 35 centre35; fork_centring.cpp): per branch
// point, the points of its parent's plain chain within the trunk's radius + its widest child's radius of it whose
// radius exceeds 1.2 x the trunk's own (its points' median past the junction's reach) and that no placement froze go
// onto the trunk's curve: per child, the cubic Hermite segment from the trunk's last unfused point (along the trunk)
// to the child's first unfused point past that zone (along the child), the point's nearest sample on each, averaged
// over the children; their radius interpolated between those unfused ends. Only where that moves the point by more
// than half a voxel and at most the trunk's radius. Then (session 37 cross37) a junction the tree does not fork at (the
// sibling's start traced by no path: its paths entered it elsewhere): a plain chain point whose chain runs on past
// that reach both ways, where the chain's own radius up and down differ by more than blobWidth's margin (the wider at
// most wideRadii x maxRadiusMm) and the point is wider than both, is with its run of such points the junction's blob
// where that run is a bump (its widest section wider than blobWidth of both ends') and no point off the chain lies
// within the two radii of a run point; the run goes onto the chain's own curve, the Hermite segment between the first
// points up and down at or under the wider radius (within twice the two radii of each other), by the same half-voxel /
// radius bounds (the narrower radius). Only with o.junctions and o.iterations. Returns the count moved.
size_t centreForkTrunks(const JunctionInput& in, const std::vector<uint8_t>& frozen, const CentrelineOptions& o,
                        double voxMm, std::vector<Vec3>& q, std::vector<double>& radiusOut);

// One cross-section's fit (two_tubes.cpp): normal to t at o, sampled by value (mm; NaN outside the volume) in a window
// of about 1.6 blobR, as one blurred disc and as two (the own at ownR, its centre guessed at ownGuess's offset; the
// other beyond the blob's centre, or at otherGuess with radius otherR past the contact). decisive: two discs explain
// it better by more than bicMin (dBic) as two tubes, not one with a bulge; own / otherAt: the discs' centres (mm), sep
// their distance, other the other's radius, blur the Gaussian's width; own is read again with the own radius free
// where that narrows the own disc within the fixed one (thick slices read a thin tube's chain radius wide).
struct TwoTubeFit {
  bool decisive = false;
  Vec3 own = Vec3::Zero(), otherAt = Vec3::Zero();
  double dBic = 0, sep = 0, other = 0, blur = 0;
};
TwoTubeFit fitTwoTubeSection(const Vec3& o, const Vec3& t, const Vec3& ownGuess, double ownR, double blobR,
                             const Vec3& spacing, const std::function<double(const Vec3&)>& value, double bicMin,
                             const Vec3* otherGuess = nullptr, double otherR = 0);

// fusedAt(point, discMm): whether the point's cross-section disc of that radius leaves the lumen.
using FusedAt = std::function<bool(size_t, double)>;

// widths(point, maxMm, widest, narrowest): the lumen's widest and narrowest chords (mm) across the
// point's cross-section (normal to its tangent); false where a wall is not found within maxMm.
using SectionWidths = std::function<bool(size_t, double, double&, double&)>;

// The count of an arm's leading points (of its first `end`) whose sections read the parent's own lumen at the branch
// point b (session 47 kindC; parted_lead.cpp): no wider than b's section and the parent's own diameter, no narrower
// than b's, each by half a voxel - the children's lobes side by side read wider, a child's own lumen narrower. They lie
// before the junction; placeParted and placeFork leave them to the rounds, whatever their J (a J where the arms' paths
// part, short of the fork; axes meeting early or beside it, session 49 scan140). Across thick slices (coarseMm) the
// widest chord may exceed the diameter by half a slice, but no section by more than half a voxel over the widest read
// at b or before it in the run (a fork's widening rises past them; session 49 fork16110). maxMm: the widths' reach.
size_t inParent(const std::vector<size_t>& arm, size_t b, size_t end, const SectionWidths& widths, double maxMm,
                double parentRadiusMm, double voxMm, double coarseMm = 0);

// A fused section's lobe's centre from its own walls (parted_lobe.cpp; sessions 49 lobewalls, 50 lobewalls2): along
// the widest chord d through c from the lobe's outer wall (outerMm, signed) towards the other (innerMm), the chord
// across (normal to d and the tangent) that dips deepest between the two lobes is their waist; the centre is that of
// the circle fitted to the lobe's own walls (its outer wall and the ends of every chord across between it and the
// waist). A child's disc whatever its radius (18430's, read in the parent's lumen where the paths part early, 2.86 mm
// for 2.1, does not enter); not through the waist's ends, which thick slices read filled (11932); a wall read wider
// all round widens the circle about the same centre. False where no waist dips, fewer than two chords lie between it
// and the outer wall, or a wall is not found within maxMm.
bool lobeCentreFromWalls(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                         double surroundings, double step, const Vec3& d, double outerMm, double innerMm, double maxMm,
                         Vec3& centre);

// lobes(point, maxMm, dir, plus, minus, narrowest): the widest chord of the point's cross-section
// (normal to its tangent): its direction (unit, mm) and the walls' distances from the point along
// +dir and -dir, and the section's narrowest chord; false where a wall is not found within maxMm.
using SectionLobes = std::function<bool(size_t, double, Vec3&, double&, double&, double&)>;

// Point k's section (`lobes`) fitted as two discs at the ends of its widest chord (session 24), of radii ra / rb:
// the own radii, scaled up where half the narrowest chord exceeds them. Two discs where the centres'
// separation is at least half the smaller radius and half a voxel (a round lumen cut a little
// obliquely is elongated by less: 505) and at most both radii, and the narrowest chord at most 2.5 x
// the wider own radius (not a wide lumen). ePlus / eMinus: the centres, ePlus's disc of radius ra.
bool twoDiscs(const SectionLobes& lobes, size_t k, const Vec3& qk, double ownA, double ownB, double voxMm,
              double reachMm, Vec3& ePlus, Vec3& eMinus, double& ra, double& rb);

// Children whose lumens still overlap past the junction zones (session 24; thin15: 30 of the 50 far
// points on the family's thin misses). There the rays and sections see one lumen and centre both
// children's chains onto its middle, half the axes' separation off each (545: 5-6 points per child
// 1.1-1.6 voxels off, refined radius 1.5 x the child's). The overlap: a child's points beyond its
// zone that lie within half the smaller child's radius (at least half a voxel) of the sibling's
// chain; each child's own radius is the median of its rays' radii over the next points. Each
// section there is fitted as two discs (twoDiscs; half the narrowest chord is the fused section's own
// measure of the children's width: the rays beyond read low where the children taper). Each child
// takes the disc nearer its previous point, walking back from its first point past the overlap:
// continuity, not the raw voxel (545's discrete paths swap lumens inside the overlap). A side branch off a trunk over
// twice as wide is left alone (532: the trunk's chain went by up to 9 mm; its ostium is the zones' and the wide
// trunk's). Points the fork placements put on J -> G there are re-placed by the fit; sections that are not two discs
// are skipped. A child whose walk back took its sibling's disc at every point over more than the two own radii goes to
// the other discs where its discrete path lies nearer them (session 39 route124: continuity across a tight U's bottom).
// A fork left free (`freeFork`: no junction found, no child continues the parent) has its junction zones' points fitted
// too, from the child's first round section back to b: their sections' centring put them between the children (11302's
// b5 -> {b9, b10}: b10's first points 1.2-1.8 voxels off it, two on b9; session 30).
struct OverlapArms {
  const std::vector<std::vector<size_t>>& arms;      // the parent arm first, outward from the branch point
  const std::vector<size_t>& zone;                   // per arm: its junction zone's point count
  const std::vector<double>& ownR;                   // per arm: its own radius (mm)
  const std::function<Vec3(size_t)>* raw = nullptr;  // per point its discrete path's voxel (mm); null: not known
};
// Returns false where a child's overlap runs to (within 3 points of) its arm's end, leaving no points to give its own
// radius; placeJunctions then follows an arm that ends at a fork into each of that fork's children.
bool placeOverlaps(const OverlapArms& g, const std::vector<double>& radius, const std::vector<Vec3>& q, double voxMm,
                   const SectionLobes& lobes, std::vector<Vec3>& target, std::vector<uint8_t>& moved,
                   std::vector<double>& lobeR, bool freeFork = false);

// Places the junction zones of every branch point (see centreline_junctions.cpp) and freezes them;
// returns the count of moved points. `ownRadius`, when given (sized as q, NaN), receives the radius
// (mm) of the points placed in their own lobe of a fused section: the child's own, not the blob's.
// A side branch's zone goes onto the line from the branch point b to its first round section only where b is its
// ostium: in a lumen wider than `wideTrunkMm` (the parent arm's own radius; the wide trunk's bound, placeWide's
// wideRadii x maxRadiusMm; infinity: none) the discrete routes to its daughters may part anywhere inside it (14404:
// 12 mm before a daughter's opening, the line cut across the trunk to its wall), and placeWideTrunk places such a
// daughter from its junction on the trunk's axis (wide_trunk.h): the zone is left to it.
size_t placeJunctions(const JunctionInput& in, std::vector<Vec3>& q, std::vector<uint8_t>& frozen, double voxMm,
                      const FusedAt& fusedAt, const SectionWidths& widths = {}, const SectionLobes& lobes = {},
                      std::vector<double>* ownRadius = nullptr,
                      double wideTrunkMm = std::numeric_limits<double>::infinity());

// A fork's fused section placed by its lobes (session 41 lobeC; fused_lobes.cpp), after placeJunctions, wherever the
// discrete branch point lies: along each child's chain from a two-child fork, the first section that is the child's
// own tube alone (one lobe, ownLobe at ownLobeOffset's level) past one of two lobes or more within lobeForkRadii x the
// fork point's radius ends the fused section; from there back towards the fork, while a section holds two lobes or
// more and the child's lobe is not the one its sibling's own tube reads, the point goes to the peak of lumen-ness of
// its own lobe, each lobe read from the point placed before it (the child's own lobe followed in order along it), and
// is frozen with the lobe's radius in `ownRadius`. Lobes wider than wideRadii x maxRadiusMm are the wide trunk's.
// Returns the count of placed points.
struct FusedLobeInput {
  const TrilinearSampler& sample;
  const Vec3& spacing;
  const CentrelineOptions& o;
  const std::vector<double>& surroundings;  // per point: its section's background (the rounds')
  std::function<Vec3(size_t)> tangent;
};
size_t placeFusedLobes(const JunctionInput& in, const FusedLobeInput& f, std::vector<Vec3>& q,
                       std::vector<uint8_t>& frozen, std::vector<double>& ownRadius);

// Re-branches forks whose discrete branch point lies past the junction (see
// centreline_junctions.cpp); `copy(k)` appends a copy of point k to every per-point array and
// returns its index. Returns the number of forks re-branched. With `widths` and `lobes`, also a narrow fork whose
// children run on side by side past the junction, re-branched where the sections show two lumens start (session 26),
// or where they show the children's fused run (twoDiscRun below; `spacing`: the grid's, for its sections).
size_t splitForks(std::vector<int32_t>& parent, std::vector<std::vector<int32_t>>& children, std::vector<Vec3>& q,
                  std::vector<uint8_t>& frozen, const std::vector<double>& radius, double voxMm, const FusedAt& fusedAt,
                  const std::function<size_t(size_t)>& copy, const SectionWidths& widths = {},
                  const std::function<Vec3(size_t)>& raw = {}, const SectionLobes& lobes = {},
                  const Vec3& spacing = Vec3::Zero());

// splitForks' shared stretch (fork_start.cpp, session 36): P, the parent arm's point where the fork is re-branched,
// `above` its points above P (outward from P), `shared` the points from P's child down to the discrete branch point;
// parentR the parent arm's own radius, reachMm the junction's reach (parentR + the wider child's own radius).
struct SharedStretch {
  size_t P;
  const std::vector<size_t>& above;
  const std::vector<size_t>& shared;
  const std::vector<Vec3>& q;
  double parentR, reachMm, voxMm;
};
// How many of the shared points stay the trunk's before the fork: where the two children's placed chains
// (`apartMm(k)`: shared point k's two placements apart) stay within the parent's radius of each other from P on for
// longer than the junction's reach, the fork is not there yet (11932: a parent between two 2.19 mm slices, its
// sections elongated, read as a plateau of widening): it starts at the last section before the first one whose widest
// chord exceeds the trunk's own (the median over its sections above P beyond the reach) by centre35's factor.
// 0: P stays; shared.size(): no section is wider, the fork stays where the tree branches.
size_t trunkPointsBeforeFork(const SharedStretch& s, const std::function<double(size_t)>& apartMm,
                             const SectionWidths& widths);
// A narrow fused fork whose tree branches past the junction where neither the axes nor the sections' widening show it
// (fork_start.cpp; session 36 shared36: 11932's b4 -> {b11, b12}, 11902's fork, whose children cross where the tree
// branches; session 37 fused37: 12024's b2 -> {b5, b6}, nearly parallel, fused ~12 mm). A run section is one that
// twoDiscs fits as the children's two discs (their own radii, twoLumens' window) whose centres lie more than one voxel
// of the grid apart (each axis in its own spacing): a round parent whose axis lies between two thick slices is smeared
// over both, by up to a slice, and twoDiscs reads it as two discs along the slice axis (10531 / 10603 / 11901:
// 0.85-1.67 mm apart on 2.0-2.6 mm slices, under one voxel of the grid).
struct RunInput {
  const std::vector<std::vector<size_t>>& arms;  // the parent arm first, outward from b
  const std::vector<size_t>& zone;               // per arm: its junction zone's point count
  const std::vector<uint8_t>& hasLine;           // per arm: an axis past its zone
  const std::vector<double>& ownR;               // parent, child, child (mm)
  const std::vector<Vec3>& q;
  double voxMm;
  Vec3 spacing;  // the grid's (mm); zero: voxMm on every axis
  const SectionLobes& lobes;
  const FusedAt& fusedAt;  // the zones' lumen test (analyseFork's disc: 1.5 own radii + a voxel)
};
// The run from b: `up` parent-arm sections (outward from b), `arm[a]` sections of child arm a (from its first point).
struct FusedRun {
  size_t up = 0, arm[3] = {0, 0, 0};
};
// The children's shared stretch: the run up the parent arm from b, or, where both children's arms start with a run,
// the run from its top down through b to the nearer arm run's end, along the tree (the children fused side by side past
// b: 12024's run up is one section, 2.1 mm, and goes on 3.3-5.2 mm into both arms), if it reaches farther than the
// junction's reach (the parent's radius + the wider child's: a shorter run is the junction zone's own, placeFork's)
// and both children have an axis past their zones. J: the trunk's section above the run, G[1] / G[2]: the children's
// first sections past their zones. False: no run section above b, or a run too short.
bool twoDiscRun(const RunInput& in, size_t b, FusedRun& run, Vec3& J, Vec3 (&G)[3]);
// The places of the run's points: each shared point (kept: child `keep`'s chain) and its copy (the other child's) go to
// its section's two discs, and each child arm's run points to one of their section's discs - section by section, the
// way that puts the two discs nearer the children's axis lines (each through the child's first point past its zone and
// its run, along its next points: children that cross past a narrow fork (11902) lie on the sides their lines extended
// back give; twoDiscs' order of the discs flips along 12024's run): those go into q, frozen, where true is returned.
// False (the fork left alone) where a section's two discs lie farther apart than the children's own radii together:
// not two overlapping (fused) children of this fork (the head CTA's tangle at 229,150,6 read 12 mm apart).
bool runDiscs(const RunInput& in, const FusedRun& run, const std::vector<size_t>& shared, size_t keep,
              std::vector<Vec3>& kept, std::vector<Vec3>& copied, std::vector<Vec3>& q, std::vector<uint8_t>& frozen);
// Evidence that splitForks' image stretch is two lumens side by side, not a parent widened before a fork branched at
// its junction (10201): most shared sections are two discs of the children's own radii (ownA, ownB), and the
// children's first points past b lie a voxel or more apart (the paths step into their own lumens where the stretch
// ends; 10929 / 10221 2.9 / 1.6 voxels, 10201's start together, 0.76). A section counts as two discs only where their
// centres lie more than a voxel of the grid apart (`spacing`; RunInput's smear test, session 37 run37).
bool twoLumens(double ownA, double ownB, size_t b, const std::vector<std::vector<int32_t>>& children,
               const std::vector<Vec3>& q, const std::vector<size_t>& shared, double voxMm, const SectionLobes& lobes,
               const Vec3& spacing = Vec3::Zero());
// placeFork's point p for child point k lies past the midline between the two children's discrete paths: nearer the
// sibling's first path voxel than its own (kiss39's midline test; session 36, 11902: the children cross past a
// narrow fork and the child's line from J starts on the sibling's side). False where the path voxels are not known.
bool ontoSibling(const JunctionInput& in, size_t k, const std::vector<size_t>& sibling, const Vec3& p);

// Where the discrete paths part before a fork's junction J (placeFork), J lies ahead of b on the parent's own course:
// within the parent's radius `parentR` of its line through b (from `up`'s fifth point, or its last, b's parent arm
// outward from b). Where both children turn back past a hairpin fork, their axes, extrapolated behind their first
// round sections, meet between the returning limbs instead, beside the parent (15429: 6.1 mm off a 3.4 mm trunk, the
// zones laid on b -> J across the lumen, 1.7-1.9 voxels off a child's axis the rounds had them on). Only a J more than
// a voxel ahead of b along the parent is read so: a J level with b beside it (11825: 5.0 mm aside, 0.45 mm behind)
// is the junction at b's own level, and b -> J the step across the fused section there.
bool alongParent(const std::vector<size_t>& up, double parentR, double voxMm, const std::vector<Vec3>& q, size_t b,
                 const Vec3& J);

// Forks placed where the children's chains part (centreline_together.cpp): per fork of two children, the later
// chain's points whose voxels stay neighbours of the earlier chain's from the fork on, over at least
// minTogetherMm along it, follow the earlier chain's (`leader`, the point `stepsUp` above the refined parent of
// the later chain's first point past the run, `reattached`), and that point hangs from the earlier chain's
// point where they part. `merged`: the tree without the followers; newIndex per input point (-1: a follower),
// oldIndex per merged point.
struct TogetherForks {
  CentrelineTree merged;
  std::vector<int32_t> newIndex, oldIndex, leader, stepsUp, reattached;
  size_t merges = 0;
};
TogetherForks mergeTogetherChains(const CentrelineTree& tree, const Vec3& spacing, double minTogetherMm);

// The refinement of the merged tree `r` as one of `tree`: every input point in its order (a follower at its
// leader's refined position and radius), then r's copies; each path's chain keeps its input parents.
RefinedCentreline expandTogether(const TogetherForks& t, const CentrelineTree& tree, const RefinedCentreline& r);

// refineCentreline on the tree as given (centreline.cpp).
RefinedCentreline refineTree(const VolumeF32& vol, const CentrelineTree& tree, const CentrelineOptions& o,
                             Progress& progress);

}  // namespace vs::centreline_detail
