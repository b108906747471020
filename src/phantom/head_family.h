// A randomised family of head phantoms for validating cuts (issue 26): per seed, layers of random
// thickness and value (skin, fat, muscle, a skull shell of random thickness and brightness, brain),
// a nose, an ear and a chin of random size and tilt, noise, a smooth multiplicative bias and
// anisotropic spacing up to 2:1 (slices along z), with a truth label volume and the analytic
// shapes behind it.
#pragma once

#include <cstdint>
#include <vector>

#include "phantom/phantom.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

// An ellipsoid with a rotation: level |R^T (p - c) / a| < 1 inside.
struct TiltedEllipsoid {
  Vec3 centerMm{0, 0, 0};
  Vec3 semiAxesMm{1, 1, 1};
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // columns: the local axes in world
  double level(const Vec3& pointMm) const;
  // Approximate signed distance (mm, < 0 inside), exact to first order near the surface.
  double signedDistance(const Vec3& pointMm) const;
};

struct HeadFamilyOptions {
  uint64_t seed = 1;
  // Scales the head and its parts (not the layer thicknesses, values or spacing): 1 = an adult
  // head (semi-axes ~ 70 x 90 x 95 mm); CI tests use small heads.
  double sizeScale = 1.0;
};

// Truth labels.
enum HeadLabel : uint8_t {
  kHeadAir = 0,
  kHeadSoft = 1,   // skin, fat, muscle
  kHeadBone = 2,   // the skull shell
  kHeadBrain = 3,  // inside the skull
  kHeadNose = 4,   // the nose where it stands out of the head
  kHeadEar = 5,    // the ear where it stands out of the head
};

struct HeadFamilyTruth {
  uint64_t seed = 0;
  double sizeScale = 1;
  Vec3 spacing{1, 1, 1};
  double air = -1000, skin = 40, fat = -100, muscle = 45, bone = 1000, brain = 30;  // HU before bias and noise
  double noiseSigma = 0;
  double biasSlope = 0;  // relative change of (value - air) per 100 mm along biasDirection
  Vec3 biasDirection{1, 0, 0};
  double skinMm = 0, fatMm = 0, muscleMm = 0, boneMm = 0;  // layer thicknesses
  double iso = -500;                                       // the skin surface: (air + skin) / 2
  TiltedEllipsoid head;                                    // the skin surface of the head
  TiltedEllipsoid chin, nose, ear;                         // added to the head (union)
  Vec3 faceDirection{0, -1, 0};                            // the face looks towards -y (world)
  // Signed distance (mm, < 0 inside the skull shell's outer surface) to the skull's outer
  // surface: the head ellipsoid shrunk by skin + fat + muscle.
  double boneOuterSignedDistance(const Vec3& pointMm) const;
  // The head's skin without the nose and ear (the chin included): < 0 inside.
  double faceSignedDistance(const Vec3& pointMm) const;
  // Loops of `count` points (world mm) on the skin, in angular order: around the nose's base (just
  // outside where the nose stands out), around the ear's base, and around patches of the face
  // without protrusions (the forehead, a cheek) of radius `radiusMm`.
  std::vector<Vec3> noseLoopMm(int count = 12) const;
  std::vector<Vec3> earLoopMm(int count = 12) const;
  std::vector<Vec3> foreheadLoopMm(double radiusMm, int count = 12) const;
  // A patch of the cheek beside the nose (45 degrees towards the ear's side, level with the nose).
  std::vector<Vec3> cheekLoopMm(double radiusMm, int count = 12) const;
  // A loop of `radiusMm` on the skin around the point `upDeg` above and `sideDeg` towards the
  // ear's side of the face direction (seen from the head's centre).
  std::vector<Vec3> faceLoopMm(double upDeg, double sideDeg, double radiusMm, int count = 12) const;
};

struct HeadFamilyPhantom {
  VolumeI16 volume;
  VolumeU8 labels;  // HeadLabel per voxel (by its centre)
  HeadFamilyTruth truth;
};

// A cut against the truth: `cutLabels` 2 = cut away (the cutting module's labels), same dims.
// The truth labels go by voxel centre, but the object at the iso-value also holds partial-volume
// voxels whose centre lies just outside every shape (label air): each of those is the part's when
// its centre is nearer the part's surface than the rest's (the analytic shapes decide).
struct PartCutScore {
  int64_t partVoxels = 0;
  double removed = 0;        // cut-away voxels of the part / part voxels
  double takenRest = 0;      // cut-away voxels of the rest (its tissue and its partial-volume rim) / part voxels
  double takenByCentre = 0;  // every cut-away voxel whose centre is not in the part / part voxels
  double partRimCut = 0;     // cut-away partial-volume voxels nearer the part's surface / part voxels
};
PartCutScore scorePartCut(const HeadFamilyPhantom& phantom, HeadLabel part, const VolumeU8& cutLabels);

// Mean |distance| (mm) of points to the skull's outer surface.
double meanDistanceToBoneMm(const HeadFamilyTruth& truth, const std::vector<Vec3>& pointsMm);

// The truth as JSON (kind "head-family"): the draws, the label legend and the loops a user would
// click (nose, ear, forehead, cheek), in voxel index coordinates of `geometry` and as the
// "x,y,z;x,y,z" text `volscissors cut --points` takes.
nlohmann::json toJson(const HeadFamilyTruth& truth, const Geometry& geometry);

// O(voxels). Throws InvalidArgument for a bad size scale (0.3 .. 1.5).
HeadFamilyPhantom makeHeadFamilyPhantom(const HeadFamilyOptions& options, Progress& progress = Progress::none());

}  // namespace vs
