// Tube phantoms with exact cross-section truth, for vessel / airway quantification (issue 24):
// straight and curved tubes of a given radius at a random orientation, tapering tubes, elliptic
// cross-sections, stenoses (a plateau of given degree over the middle half of the lesion's length,
// cosine shoulders), bifurcations with a known
// angle. Anisotropic spacing, Gaussian blur and Rician noise.
//
// Geometry is analytic in world mm (origin 0, identity direction: world = index * spacing):
// every branch is a straight line or a circular arc with a radius profile a(s), b(s) (the semi-axes
// of an elliptic section; a = b for round tubes) and a fixed a-axis direction perpendicular to the
// tangent. Voxels get the fraction of their volume inside the union of the branches (4x4x4
// sub-samples near the surface), a sphere fills the junction of a bifurcation. Intensity:
// background + (foreground - background) x fraction, blurred by blurMm (separable Gaussian), then
// Rician noise sqrt((I + n1)^2 + n2^2), n ~ N(0, noise). Deterministic for a seed (PhantomRng).
// Radii are in "radius voxels" = the largest spacing, as the vessel phantom's.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mesh/tri_mesh.h"
#include "phantom/phantom.h"

namespace vs {

enum class TubeKind { Straight, Curved, Taper, Elliptic, Stenosis, Bifurcation };
std::string tubeKindName(TubeKind k);                // straight, curved, taper, elliptic, stenosis, bifurcation
TubeKind tubeKindFromName(const std::string& name);  // throws InvalidArgument

struct TubePhantomOptions {
  uint64_t seed = 1;
  TubeKind kind = TubeKind::Straight;
  double radiusVoxels = 3;  // (parent) radius in units of the largest spacing, 0.5..20
  // <= 0: drawn from the seed (smallest spacing in [0.4, 0.8] mm, one axis 1-2x coarser).
  Vec3 spacing{0, 0, 0};
  double background = 100, foreground = 400;  // foreground < background: a dark lumen (airway)
  double noiseSigma = 10;                     // Rician sigma (grey levels), >= 0
  double blurMm = -1;                         // Gaussian blur sigma, mm (< 0: half the smallest spacing)
  // Kind parameters (NaN: drawn from the seed within the ranges).
  double stenosisDegree = std::numeric_limits<double>::quiet_NaN();    // by diameter, 0.2..0.8
  double stenosisLengthMm = std::numeric_limits<double>::quiet_NaN();  // 3..15 mm
  double bifurcationDeg = std::numeric_limits<double>::quiet_NaN();    // angle between the children, 30..120
  double aspect = std::numeric_limits<double>::quiet_NaN();            // elliptic: a / b, 1.3..2
  double taperRatio =
      std::numeric_limits<double>::quiet_NaN();  // taper: radius at the end / at the start over the volume, 0.4..0.7
};

struct TubeBranch {
  int parent = -1;
  bool arc = false;
  // Line: p0 + s * dir, s in [0, length]. Arc: centre + R (cos(s/R) e1 + sin(s/R) e2).
  Vec3 p0{0, 0, 0}, dir{1, 0, 0};
  Vec3 centre{0, 0, 0}, e1{1, 0, 0}, e2{0, 1, 0};
  double curvatureRadiusMm = 0;
  double lengthMm = 0;
  Vec3 aAxis{0, 1, 0};  // line: fixed direction of the a semi-axis (arc: the arc's normal e1 x e2)
  // Radius profile: a(s) = radiusMm * profile(s) * sqrt(aspect), b(s) = radiusMm * profile(s) / sqrt(aspect).
  double radiusMm = 1, aspect = 1;
  double taperEnd = 1;  // profile multiplier at s = length (linear from 1 at s = 0)
  double stenosisDegree = 0, stenosisCentreMm = 0, stenosisLengthMm = 0;

  Vec3 at(double s) const;       // world mm
  Vec3 tangent(double s) const;  // unit
  double profile(double s) const;
  double semiA(double s) const;
  double semiB(double s) const;
  double equivalentRadiusMm(double s) const;  // sqrt(a b)
};

struct TubeTruth {
  uint64_t seed = 0;
  TubeKind kind = TubeKind::Straight;
  Index3 dims{0, 0, 0};
  Vec3 spacing{1, 1, 1};
  double radiusUnitMm = 1;  // largest spacing
  double background = 0, foreground = 0, noiseSigma = 0, blurMm = 0;
  std::vector<TubeBranch> branches;  // bifurcation: 0 parent (ends at the junction), 1 and 2 children
  double bifurcationDeg = 0;         // bifurcation: angle between the children's directions
  Vec3 junctionMm{0, 0, 0};
};

struct TubePhantom {
  VolumeF32 volume;
  TubeTruth truth;
};

TubePhantom makeTubePhantom(const TubePhantomOptions& options, Progress& progress = Progress::none());

// The part of a branch's centreline at least `marginMm` inside the volume, sampled every
// stepMm: {s} values (arc along the branch). Empty when it never gets that far in.
std::vector<double> tubeArcsInside(const TubeTruth& truth, int branch, double marginMm, double stepMm);

// The true centrelines as a tree (world mm), every stepMm where at least half the largest spacing
// inside the volume (a bifurcation's parent up to the junction, the children hung on it), moved
// off centre by up to jitterMm (smooth, low frequency, as a tracker leaves) and with radii
// hintFactor x the truth: the input of the quantification tests and of bench/quantify_tune.
Tree tubeTruthTree(const TubeTruth& truth, double jitterMm, double hintFactor, double stepMm = 0.5);

struct TubeNearest {
  int branch = -1;
  double s = 0, distanceMm = std::numeric_limits<double>::infinity();
};
// The nearest point of the true centrelines to a world point (0.005 mm).
TubeNearest nearestTubeCentre(const TubeTruth& truth, const Vec3& p);

struct TubeDiameterErrors {
  int count = 0;
  double meanAbsVoxels = 0, meanVoxels = 0, meanAbsRelative = 0;  // voxels: radius units (largest spacing)
};
// Diameters measured at world points against 2 x the true equivalent radius at the nearest
// centreline point.
TubeDiameterErrors tubeDiameterErrors(const TubeTruth& truth, const std::vector<Vec3>& centres,
                                      const std::vector<double>& diameters);

}  // namespace vs
