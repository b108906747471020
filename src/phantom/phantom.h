// The project's own synthetic data with exact ground truth (issue 2): a branching
// vessel tree, a layered head, and a 2D image of simple shapes. Everything is
// deterministic for a given seed on every platform: randomness comes from
// std::mt19937_64 (whose output sequence the standard specifies) through the
// hand-written distributions of PhantomRng below (no std::*_distribution, whose
// output is implementation-defined).
//
// Conventions (as everywhere in volscissors):
//  * Volumes are x fastest; geometry has origin (0,0,0) and identity direction, so
//    world mm = index * spacing.
//  * Truth coordinates are 0-based voxel/pixel INDEX coordinates (x, y, z) unless a
//    field name ends in "Mm". Radii are in mm (anisotropic spacing: shapes are defined
//    in world mm, so tubes stay round in mm and become elliptic in index space).
//  * Partial-volume edges: a voxel's value blends the two tissues by an estimate of the
//    fraction of the voxel inside the shape (linear ramp of the signed distance over the
//    voxel's extent along the surface normal).
//  * Failure: bad options throw InvalidArgument naming the option; a tree that cannot
//    be placed in a (tiny) volume throws DataError. Readers throw IoError naming the
//    file and the missing/malformed field.
// The phantoms serve the tests of tracking (thesis ch. 4, vessel tracking), live-wire
// (thesis ch. 3, Intelligent Scissors on 2D images) and surface extraction/cutting.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <nlohmann/json_fwd.hpp>
#include <random>
#include <string>
#include <vector>

#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

using Vec2 = Eigen::Vector2d;
using Index2 = std::array<int64_t, 2>;

// ---------------------------------------------------------------------------------
// Deterministic random numbers: same seed -> same sequence with any standard library.
class PhantomRng {
 public:
  explicit PhantomRng(uint64_t seed) : engine_(seed) {}
  uint64_t next() { return engine_(); }
  // Uniform in [0, 1) with 53 random bits: (next() >> 11) * 2^-53.
  double uniform();
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Integer uniform in [lo, hi] (inclusive); lo <= hi.
  int64_t integer(int64_t lo, int64_t hi);
  // Standard normal by the Box-Muller transform (pairs; the second value is cached).
  double normal();
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  // Derives an independent seed for a sub-stream (splitmix64 of seed ^ salt).
  static uint64_t derive(uint64_t seed, uint64_t salt);

 private:
  std::mt19937_64 engine_;
  bool hasSpare_ = false;
  double spare_ = 0.0;
};

// ---------------------------------------------------------------------------------
// Vessel tree: curved tapered tubes, bright on a dark noisy background (uint8).
struct VesselPhantomOptions {
  uint64_t seed = 1;
  Index3 dims{128, 128, 128};   // voxels; each >= 24
  Vec3 spacing{1.0, 1.0, 1.0};  // mm per voxel, > 0
  double noiseSigma = 10.0;     // std dev of additive Gaussian noise (grey levels), >= 0
  double background = 30.0;     // grey level outside the tubes (0..255)
  double foreground = 200.0;    // grey level inside the tubes (0..255)
  // Radii are given in "radius voxels": 1 unit = the largest spacing (mm), so a tube of
  // radius 1 is at least one voxel thick along every axis.
  double rootRadius = 5.0;  // at the root; shrinks towards the leaves (clamped to fit small volumes)
  double minRadius = 1.0;   // thinnest leaf
  int minTerminals = 8;     // the number of terminals is drawn in [min, max] (fewer if the
  int maxTerminals = 16;    //   tree cannot be placed after many re-draws)
  // The tube's contrast above the background falls by this fraction from the root to the
  // farthest terminal, linearly in path length from the root (partial volume, wash-out); [0, 1).
  double contrastFalloff = 0;
  // Angle of each daughter to its parent's direction, drawn uniformly (degrees).
  double branchAngleMinDeg = 25, branchAngleMaxDeg = 50;
};

struct VesselBranch {
  int parent = -1;              // index into VesselTruth::branches; -1 for the root branch
  std::vector<int> children;    // empty for a terminal branch
  int depth = 0;                // 0 for the root branch
  std::vector<Vec3> points;     // centerline, continuous voxel index (x,y,z); first point = parent's last
  std::vector<double> radiiMm;  // tube radius at each point, mm
};

struct VesselBranchPoint {
  Vec3 position{0, 0, 0};     // continuous voxel index of the junction
  Index3 voxel{0, 0, 0};      // nearest voxel
  int parent = -1;            // branch ending here
  std::vector<int> children;  // branches starting here
};

struct VesselTruth {
  uint64_t seed = 0;
  Index3 dims{0, 0, 0};
  Vec3 spacing{1, 1, 1};
  double background = 0, foreground = 0, noiseSigma = 0;
  double iso = 0;           // (background + foreground) / 2: the tube surface
  double radiusUnitMm = 1;  // mm per "radius voxel" (largest spacing)
  double clearanceMm = 0;   // guaranteed gap between surfaces of non-adjacent branches
  std::vector<VesselBranch> branches;
  Index3 rootVoxel{0, 0, 0};           // first centerline point of branch 0 (a voxel centre)
  std::vector<Index3> terminalVoxels;  // last centerline point of each leaf branch (voxel centres)
  std::vector<int> terminalBranches;   // leaf branch of each terminal
  std::vector<VesselBranchPoint> branchPoints;
};

struct VesselPhantom {
  VolumeU8 volume;
  VesselTruth truth;
};

// Builds the tree in world mm (rejection sampling keeps every tube inside the volume
// with a margin and non-adjacent branches apart), then renders it. O(voxels + tube
// length * radius^3). Throws InvalidArgument for bad options, DataError if no tree fits.
VesselPhantom makeVesselPhantom(const VesselPhantomOptions& options, Progress& progress = Progress::none());
// The same tree (same truth for the same options) rendered chunk by chunk, for volumes larger
// than memory (issue 25: OME-Zarr phantoms of 2048^3): sink(c, voxels) receives chunk c's
// chunk^3 grey levels (float, x fastest; voxels outside dims are background), each chunk once,
// from up to workerCount() threads at a time. The noise comes from a counter-based generator
// per voxel (seeded from options.seed), so the voxels are not makeVesselPhantom's but follow the
// same distribution. Memory: O(chunk^3 per thread + tree), never the volume.
using VesselChunkSink = std::function<void(const Index3& chunk, const float* voxels)>;
VesselTruth makeVesselPhantomChunked(const VesselPhantomOptions& options, int chunk, const VesselChunkSink& sink,
                                     Progress& progress = Progress::none());

// A bone-like block beside the vessels (makeVesselFamilyBoneCase): a box, world mm (voxel index x spacing).
struct BoneBlock {
  Vec3 centre{0, 0, 0};
  std::array<Vec3, 3> axes{};  // unit; axes[0] points away from the vessel the block lies beside
  Vec3 halfMm{0, 0, 0};        // half edge lengths along the axes
  double value = 0;            // intensity inside, before bias and noise
  double gapVoxels = 0;        // the gap between the block and that vessel's wall (smallest spacings)
  double signedDistanceMm(const Vec3& pMm) const;  // < 0 inside
};

// A randomised case of the vessel family that tracking is validated on (issue 21). The variant is
// drawn from `seed` (its own stream: a seed drawn as a thin tree gives the same case as before the
// variants existed), the other parameters as below for every variant:
//  * Thin: the tree above with radius 4 -> 0.8 voxels of the smallest spacing (at least 0.5 voxel
//    of the largest), daughters 10-60 degrees off their parent (20-120 between them), 4-8
//    terminals, in `dims` (uint8 levels).
//  * WideLumen: a straight trunk (aorta, trachea) of radius 8-25 voxels, flat inside, with 2-4
//    daughters of radius 1.5-4 voxels (tapering to 0.75x) leaving it at 50-130 degrees to its axis
//    and running 12-25 voxels beyond its wall; terminals: the trunk's far end and each daughter's.
//  * Kissing / Parallel: a trunk (radius 3-4.5 voxels) splits into A (straight on) and B, which
//    bends away, comes back and runs beside A (surface gap `gapVoxels`: 0-1 voxel kissing, 2-4
//    parallel) for 25-40 voxels, then leaves it; radii 1.5-3.5 voxels (0.8x at the end), a gentle
//    common bend; terminals: the ends of A and B (branches 1 and 2).
// The trunk axis of the last three is x, y or z (tilted up to ~15 degrees) and their volume is sized
// to the drawn geometry (`dims` is not used). Every variant: contrast falling 30-60 % from the root
// to the farthest terminal (path length), spacing s,s,a*s with s in [0.6, 1] mm and anisotropy a
// in [1, 3], rendered without noise, then a smooth multiplicative bias field (peak to peak
// 0-40 %), bright (tubes 200 on 30) or dark polarity (mirrored: 30 on 200, airways) and Rician
// noise (sigma 5-15). Float voxels. Voxel = the smallest spacing.
//  * Flat (never drawn from a seed: only given, makeVesselFamilyCase(seed, Flat)): WideLumen's trunk with an
//    elliptic section (a dural sinus): semi-axis 5-25 voxels across and that over an aspect of 2-3 deep, the
//    wide axis at a random angle about the trunk's axis, 2-4 daughters (radius 1.5-4 voxels, at most the
//    lumen's depth) leaving it from the two ends of its wide axis in turn. Its truth: the section's centre and
//    its equivalent radius sqrt(across x deep) / 2 (the circle of the same area). The head CTA's sinus at
//    126,32,87 (about 9.5 x 4 mm at 0.55 x 0.55 x 1 mm) has semi-axes 8.6 x 3.6 voxels: in the lower part.
enum class VesselFamilyVariant { Thin, WideLumen, Kissing, Parallel, Flat };
std::string vesselFamilyVariantName(VesselFamilyVariant v);  // thin, wide, kissing, parallel, flat
struct VesselFamilyCase {
  VolumeF32 volume;
  VesselTruth truth;
  VesselFamilyVariant variant = VesselFamilyVariant::Thin;
  bool dark = false;
  double falloff = 0, bias = 0, rician = 0, anisotropy = 1;
  double lumenRadiusVoxels = 0;  // WideLumen: the trunk's radius (voxels); Flat: its semi-axis across
  double flatAspect = 0;         // Flat: across / deep
  double gapVoxels = 0;          // Kissing / Parallel: the surface gap between A and B where they run side by side
  std::vector<BoneBlock> bones;  // makeVesselFamilyBoneCase only
  std::string describe() const;  // "seed 7: thin, dark, spacing 0.7,0.7,1.5, falloff 0.42, bias 0.31, rician 9.2"
};
// The variant a seed draws (uniform over the first four; never Flat).
VesselFamilyVariant vesselFamilyVariantOf(uint64_t seed);
// Bone beside the vessels (the lumen model's upper edge, session 15): the seed's case as drawn
// (makeVesselFamilyCase(seed, dims): the same tubes, contrast, spacing, bias and noise), made bright
// (bone is brighter than a contrast lumen; the drawn polarity is ignored), with 2-4 boxes of bone from a
// stream of their own: each beside a random point of a random branch, its face 0-3 voxels from the wall
// (0: touching), 1.5-4 x 4-12 x 3-10 voxels half edges, 1.5-3 lumen contrasts brighter than the lumen
// (fg + k (fg - bg): 455-710 on 200 over 30, 2.3-3.6 x the lumen's intensity), never over another vessel
// (re-drawn while a centreline point lies inside it by more than its radius - half a voxel) nor within the
// root's radius + 3 voxels of the root. Partial volume at its faces; the vessels stay in front of it.
VesselFamilyCase makeVesselFamilyBoneCase(uint64_t seed, const Index3& dims = {80, 80, 48});
VesselFamilyCase makeVesselFamilyCase(uint64_t seed, const Index3& dims = {80, 80, 48});
// The same with the variant given (the other draws are the seed's: a thin case is the seed's thin tree).
VesselFamilyCase makeVesselFamilyCase(uint64_t seed, VesselFamilyVariant variant, const Index3& dims = {80, 80, 48});

struct CenterlineDistance {
  double distanceMm = std::numeric_limits<double>::infinity();  // to the nearest centerline segment
  int branch = -1;        // branch of the nearest segment (-1 if the tree is empty)
  int segment = -1;       // nearest segment [segment, segment+1] of that branch
  double radiusMm = 0;    // interpolated tube radius at the nearest point
  Vec3 closest{0, 0, 0};  // nearest centerline point, continuous voxel index
};
// Distance (mm, anisotropic spacing respected) from a continuous voxel index point to
// the true centerline. O(total centerline points).
CenterlineDistance distanceToCenterline(const VesselTruth& truth, const Vec3& indexPoint);

// ---------------------------------------------------------------------------------
// Head: nested ellipsoids in HU-like int16 values, with a nose on the face side.
struct HeadPhantomOptions {
  uint64_t seed = 1;            // jitters the proportions by a few percent and drives the noise
  Index3 dims{128, 128, 128};   // voxels; each >= 16
  Vec3 spacing{1.0, 1.0, 1.0};  // mm per voxel
  double noiseSigma = 10.0;     // HU
  double air = -1000, softTissue = 40, bone = 1000, brain = 30;  // HU
};

struct Ellipsoid {
  std::string name;          // "skin", "skull_outer", "skull_inner" (= brain), "nose"
  Vec3 centerMm{0, 0, 0};    // world mm (= index * spacing)
  Vec3 semiAxesMm{1, 1, 1};  // axis-aligned semi-axes, mm
  double value = 0;          // HU inside (skull_inner: brain value; skull_outer: bone)
  // Axis-aligned ellipsoid "radius" |(p - c) / a| of a world point: < 1 inside.
  double level(const Vec3& pointMm) const;
  Vec3 centerIndex(const Vec3& spacing) const { return centerMm.cwiseQuotient(spacing); }
};

struct HeadTruth {
  uint64_t seed = 0;
  Index3 dims{0, 0, 0};
  Vec3 spacing{1, 1, 1};
  double noiseSigma = 0;
  double air = 0, softTissue = 0, bone = 0, brain = 0;
  double isoSkin = 0;  // (air + softTissue) / 2: the skin surface
  double isoBone = 0;  // (softTissue + bone) / 2: the outer and inner skull surfaces
  Ellipsoid skin, skullOuter, skullInner, nose;
  Index3 noseBoxMin{0, 0, 0}, noseBoxMax{0, 0, 0};  // inclusive voxel bounds of the nose ellipsoid
  Vec3 faceDirection{0, -1, 0};                     // index space: the face looks towards y = 0 (anterior in LPS)
};

struct HeadPhantom {
  VolumeI16 volume;
  HeadTruth truth;
};

// A loop of `count` points (world mm) on the skin around the nose's base, in angular order: on
// each of `count` rays in the nose's x-z plane, the first point on the skin ellipsoid (face side)
// whose nose level reaches `noseLevel` (> 1: just outside the nose). Where cutting tests and
// demos click to cut the nose off. A ray that finds no such point is left out.
std::vector<Vec3> noseBaseLoopMm(const HeadTruth& truth, int count = 10, double noseLevel = 1.1);

// O(voxels). Throws InvalidArgument for bad options.
HeadPhantom makeHeadPhantom(const HeadPhantomOptions& options, Progress& progress = Progress::none());

// ---------------------------------------------------------------------------------
// 2D shapes: blurred, noisy disc / ellipse / rounded rectangle / star on a uint8 image.
enum class ShapeKind { Disc, Ellipse, RoundedRect, Star };
std::string shapeKindName(ShapeKind k);                // "disc", "ellipse", "rounded_rect", "star"
ShapeKind shapeKindFromName(const std::string& name);  // throws InvalidArgument

struct Shapes2DOptions {
  uint64_t seed = 1;
  int64_t width = 256, height = 256;  // pixels; each >= 48
  Vec2 spacing{1.0, 1.0};             // mm per pixel (metadata only; shapes live in pixel space)
  double noiseSigma = 8.0;            // grey levels
  double background = 40.0;
  double blurSigma = 1.0;  // Gaussian edge blur, pixels (0: area-sampled sharp edge)
  int shapeCount = 4;      // 1..8, kinds cycle disc, ellipse, rounded_rect, star
};

struct Shape2D {
  ShapeKind kind = ShapeKind::Disc;
  int label = 0;      // 1-based, value in the label image
  double value = 0;   // grey level inside
  double iso = 0;     // (background + value) / 2
  Vec2 center{0, 0};  // pixel coordinates
  // Parameters (pixels / radians; unused ones are 0):
  //  disc: radius; ellipse: semiAxes, angle; rounded_rect: semiAxes (half width/height),
  //  cornerRadius, angle; star: radius r0, amplitude A, lobes k, phase: r(t) = r0 (1 + A sin(k t + phase)).
  double radius = 0, angle = 0, cornerRadius = 0, amplitude = 0, phase = 0;
  Vec2 semiAxes{0, 0};
  int lobes = 0;
  // The exact boundary as a dense closed polygon (vertex spacing <= 0.25 px, last vertex
  // not repeated), pixel coordinates (x, y), positive signed area in the (x right, y down) frame.
  std::vector<Vec2> boundary;
  // Pixels whose centre is inside the shape and that have a 4-neighbour outside it.
  std::vector<Index2> boundaryPixels;
};

struct Shapes2DTruth {
  uint64_t seed = 0;
  Index3 dims{0, 0, 1};
  Vec3 spacing{1, 1, 1};
  double background = 0, noiseSigma = 0, blurSigma = 0;
  std::vector<Shape2D> shapes;
};

struct Shapes2DPhantom {
  VolumeU8 image;   // dims width x height x 1
  VolumeU8 labels;  // 0 background, shape.label where the pixel centre is inside
  Shapes2DTruth truth;
};

// Shapes are placed with gaps wider than the blur, so they never touch. O(pixels near
// shapes * polygon vertices). Throws InvalidArgument for bad options.
Shapes2DPhantom makeShapes2DPhantom(const Shapes2DOptions& options, Progress& progress = Progress::none());

struct BoundaryDistance {
  double distance = std::numeric_limits<double>::infinity();  // pixels, to the nearest true boundary
  int shape = -1;                                             // index into Shapes2DTruth::shapes (-1 if none)
  bool inside = false;                                        // point inside that shape
};
// Distance from a pixel-coordinate point to the nearest true boundary. O(polygon vertices).
BoundaryDistance distanceToBoundary(const Shapes2DTruth& truth, const Vec2& point);
// Signed distance to one shape's boundary polygon: negative inside. O(vertices).
double signedDistanceToShape(const Shape2D& shape, const Vec2& point);

// ---------------------------------------------------------------------------------
// Truth <-> JSON (nlohmann::json). Files carry "kind": "vessels" | "head" | "shapes2d"
// and "format_version": 1. Readers throw IoError naming the file/field.
nlohmann::json toJson(const VesselTruth& truth);
nlohmann::json toJson(const HeadTruth& truth);
nlohmann::json toJson(const Shapes2DTruth& truth);
VesselTruth vesselTruthFromJson(const nlohmann::json& j);
HeadTruth headTruthFromJson(const nlohmann::json& j);
Shapes2DTruth shapes2DTruthFromJson(const nlohmann::json& j);

// Atomic write (util/atomic_file.h); throws IoError.
void writeTruthFile(const nlohmann::json& j, const std::string& path);
// Reads a truth file and checks its "kind".
VesselTruth readVesselTruth(const std::string& path);
HeadTruth readHeadTruth(const std::string& path);
Shapes2DTruth readShapes2DTruth(const std::string& path);

}  // namespace vs
