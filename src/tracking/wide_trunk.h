// Wide trunks and the daughters that leave them (issue 21, session 15 wide5; internal to
// src/tracking, used by refineCentreline). In a lumen wider than the rays the discrete paths hug
// the wall or cut the corner towards a daughter, and a section normal to such a path contains the
// trunk's axis, so centring in it does not bring the point back onto the trunk's axis.
//
// ballCentre: the centroid of the lumen (the samples beyond `level` on c's side, 6-connected to
// c's sample) within a ball of radius rhoMm around c, iterated from c (mean shift with a flat
// kernel): in a tube of radius R <= rhoMm it converges onto the axis through c's cross-section,
// without a direction (the trunk's direction is not the path's). A thin daughter's share of the
// ball is small. Grid step max(smallest spacing, rhoMm / 8). False (c unchanged) where c's sample
// is not lumen.
//
// placeWideTrunk: every wide point (its lumen centred by its section, wide[k]) that is neither
// the root, an end nor frozen moves to its ballCentre (ball radius 1.5 x its section's radius) and
// is frozen. Then, where a chain leaves the wide lumen for a daughter (a wide point followed by
// `linePoints` points that are not wide: the daughter's own lumen, its first point G), the
// daughter's axis (a line through its next points, refitted without its farthest one while that lies
// more than 0.75 voxel off it, then through those of them outside the trunk) is followed back into
// the trunk to J, the trunk's axis point nearest it (on the line fitted through the ball centres of the
// wide points near G the ball moved, or also of those the rays centred where those are too few, where
// onTrunkAxis holds for that line - then J's place along it from the daughter's axial course: its points'
// position along the axis against their distance from it, carried back to the axis, the path's end left out
// - else ballCentre from the point of the daughter's line a trunk radius behind G, then
// alternately the line's point nearest the centre found and that point's ballCentre, 4 times); the
// chain's own points from its last branch point up to G (those shared with no other path) that lie
// after the one nearest J go evenly onto J -> G, the daughter's points still inside the trunk onto its
// line; the others move to their ballCentre. All of them are frozen. Returns the count of points moved.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "volume/sample.h"

namespace vs::centreline_detail {

struct BallScratch {
  std::vector<uint8_t> lumen;
  std::vector<int32_t> stack;
};

bool ballCentre(const TrilinearSampler& sample, const Vec3& spacing, Vec3& c, double rhoMm, double level,
                BallScratch& scratch);

// Whether the line through J (mm) along `dir` is the axis of the tube of radius trunkMm J lies in: a
// ball of the tube's radius (ballCentre) leaves J on the line (a shift along it is allowed: beside
// the tube's end, or the volume's, the ball's lumen is cut on one side) and one of J +- trunkMm x dir
// where it is (within the smallest spacing). A line across the tube, or beside its axis, moves them.
bool onTrunkAxis(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& J, const Vec3& dir, double trunkMm,
                 double level, BallScratch& scratch);

struct WideTrunkInput {
  const TrilinearSampler& sample;
  Vec3 spacing;
  // per point: 1 centred by its wide section in the last round, 2 its rays resolved a lumen as wide
  // (they centre it: the ball moves it only from more than a quarter of the trunk's radius off)
  const std::vector<uint8_t>& wide;
  const std::vector<double>& radiusMm;      // per point: its last radius (the section's where wide)
  const std::vector<double>& sectionLevel;  // per point: its section's half-way level (else its rays')
  int polarity;  // the lumen's side of the level: 1 bright, -1 dark, 0 unknown (then the trunk point's side)
};

// Clears `wide` on runs of wide points (connected along the tree) shorter than 5 points: a trunk
// is a run, a flicker in a thin branch is not (its rays reached beyond a faint bronchus's wall). Runs on two
// of the root's children are one run through the root (never cast, never wide: the trace starts in its lumen).
void keepWideRuns(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                  std::vector<uint8_t>& wide);

// A daughter whose J placeWideTrunk took from its axial course on a found trunk axis, as placed (q in mm):
// what re-placing J after the final centring needs (replaceJunctions).
struct PlacedJunction {
  Vec3 ac, ea;                       // the trunk's axis
  bool found = false;                // ... where one was found (else ac, ea are not set)
  Vec3 dc, ed, first;                // the daughter's chord, and its first point where it was before placing
  double minSpanMm = 0, wallMm = 0;  // axialJunction's
  double level = 0, trunkMm = 0, daughterMm = 0, ownLevel = 0;  // junctionInLumen's
  int side = 0;                                                 // ... and the lumen's side of the level
  std::vector<size_t> chord;                                    // the points the axial course was fitted on
  size_t end = SIZE_MAX;                                        // the path's end, left out of that fit (SIZE_MAX: none)
  size_t beyond = SIZE_MAX;         // J -> G runs on to this point (SIZE_MAX: along the chord)
  std::vector<size_t> onLine, seq;  // the points put on the daughter's line, and on J -> G
  std::vector<Vec3> onLineFrom;     // ... the former where they were before
  std::vector<Vec3> opening;        // the daughter's own lumen walked back to the trunk's wall (openingCourse)
};

// The daughter's own lumen walked back from G (mm) along its axis (unit ed, outward) towards J, half the smallest
// spacing a step: the centroid of the section normal to ed (its samples on the lumen's side of `level`, 4-connected
// to the centre, within two daughter radii) for each section until one holds no lumen at its centre or its lumen
// reaches the disc's rim (the daughter's lumen has opened into the trunk's). The points on the daughter's axis from
// G to its opening in the trunk's wall, read from the image, not from the rays.
std::vector<Vec3> openingCourse(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& G, const Vec3& ed,
                                const Vec3& J, double daughterMm, double level, int side);

// A daughter placeWideTrunk put on J -> G, as placed (point indices): what its ostium's radii need after the final
// centring (ostiumRadii).
struct PlacedOstium {
  Vec3 centre, dir;           // the trunk's axis where it was found (a point, its unit direction), else J and zero
  std::vector<size_t> line;   // the points put on J -> G and on the daughter's line (its first ones)
  std::vector<size_t> trunk;  // the trunk's axis points near G (their radius: the trunk's)
  size_t own = SIZE_MAX;      // the daughter's first point past those, in its own lumen (its radius: the daughter's)
};

// q in mm (index x spacing).
// `placed` receives 1 for every point moved. Where the chain's points past J are shared with other
// paths, they are copied for the daughter (`copy(k)` appends a copy of point k to every per-point
// array, `in`'s and `placed` included, and returns its index) and the daughter's own points
// re-parented to the last copy; the copies go onto J -> G, the shared points stay on the axis.
// A point its rays centred near its ball's centre, which lies no deeper, is kept where it is (`placed`
// 2, not frozen); `kept` (sized as q) receives its trunk's radius (mm; 0 where not kept). A placed
// daughter's points past those put on its line, beyond the trunk's wall, get `placed` 3 (unkeepShallow).
// `junctions`, where given, receives each daughter whose J came from its axial course (replaceJunctions), `ostia`
// every daughter placed (ostiumRadii).
size_t placeWideTrunk(const WideTrunkInput& in, std::vector<int32_t>& parent,
                      std::vector<std::vector<int32_t>>& children, std::vector<Vec3>& q, std::vector<uint8_t>& frozen,
                      std::vector<uint8_t>& placed, const std::function<size_t(size_t)>& copy,
                      std::vector<double>& kept, std::vector<PlacedJunction>* junctions = nullptr,
                      std::vector<PlacedOstium>* ostia = nullptr);

// After the final centring (q in mm): J of each of `junctions` fitted again by axialJunction on its chord's
// points as now centred (their own rays' last step included; placed, they were the rounds' points), and the
// daughter's points on J -> G and on its line placed again from it, where J -> G stays in the lumen. J lies
// 16-26 mm back along the axis from a daughter's chord, so the chord's axial errors of 0.1-0.5 mm become 1.4-1.8
// mm at J (docs/notes/tracking.md, session 29 wide26); the centred points' are smaller (wide seeds' junctions
// more than a voxel off the truth's: 9 -> 4 of 142). The chord's points go first onto the daughter's axis as
// fitted to the image's voxels around them (daughter_tube.h; session 31 wide29: 10206 / 11206's J 1.5 / 1.8 mm
// off from plateaus along thick slices), where that fit holds. Returns the count of junctions moved.
size_t replaceJunctions(const TrilinearSampler& sample, const Vec3& spacing,
                        const std::vector<PlacedJunction>& junctions, std::vector<Vec3>& q);

// placeWideTrunk's per-point state for after the final centring: per point kept (placed 2) its trunk's radius
// (mm) and its level, and the junctions to place again.
struct KeptWide {
  std::vector<double> radiusMm, level;
  std::vector<PlacedJunction> junctions;
  std::vector<PlacedOstium> ostia;
};

// After the final centring (q in mm, radiiMm the final radii): a point a daughter's placement put on J -> G or on the
// daughter's line that lies beyond the trunk's wall (farther from the trunk's axis than the trunk's radius, as the
// final cast reads it on the axis points near G, less half a voxel: the blurred wall's place is known to about that)
// lies in the daughter's lumen, but where its section, normal to the daughter, opens into the trunk through the
// ostium its rays measure the trunk (16305 / 16606: 12.8 / 11.0 mm where the daughter is 1.2 / 1.6 mm). Such a point
// - its radius reaches back past the wall and exceeds the daughter's by more than the radius bound (half a
// voxel; a reading within it is the daughter's own) - takes the daughter's radius as the final cast reads it on the
// daughter's first point in its own lumen: its reading nearest the ostium (a daughter tapers, so a median along it
// lies under the ostium's: aorta MRA 74,140,16, 4.55 mm against that point's 5.05, a step down and up again).
void ostiumRadii(const std::vector<Vec3>& q, const std::vector<PlacedOstium>& ostia, double voxelMm,
                 std::vector<double>& radiiMm);

// After the final centring (q in mm, `level` per point, `keptMm` as placeWideTrunk's `kept`, `radiiMm` the
// points' last radii): a point placeWideTrunk kept (placed 2) stays kept, and a placed daughter's point beyond
// the trunk's wall that its own rays centred (placed 3) becomes placed 1 (VesselTracker::confineToLumen leaves
// it: judged by its own section's level, not the cost's global lumen level), only where it lies on the lumen's
// side of its level and at least half its radius (the trunk's for placed 2) deep; else placed 0.
void unkeepShallow(const TrilinearSampler& sample, const Vec3& spacing, const std::vector<Vec3>& q,
                   const std::vector<double>& keptMm, const std::vector<double>& level,
                   const std::vector<double>& radiiMm, int polarity, std::vector<uint8_t>& placed);

// The distance (mm) from c to the nearest crossing of `level` along 26 directions (up to maxMm):
// how deep c lies in the lumen on its side of the level.
double lumenClearance(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, double level, double maxMm);

}  // namespace vs::centreline_detail
