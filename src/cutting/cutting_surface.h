// The internal cutting surface spanned by a closed contour (thesis 3.3, eq. 14-18; reading notes):
// the contour is projected onto the plane of largest projected area, the projected disc is split
// into rings of equal hop distance L from the contour (eq. 14), and each pixel of the disc picks,
// along its projection line, the point minimising
//   C = -w_g G + w_c S                                              (eq. 15)
// where G is the image gradient (normalised by the object's own boundary contrast) and S the
// distance to the neighbouring pixels' choices (eq. 16-18). The thesis decides ring by ring from
// the contour inwards; here eq. 15 summed over the whole disc is minimised exactly (a minimum cut),
// so the surface can follow an interface that leaves the contour steeply. The result is a height
// field over the disc, so it has no holes by construction; where the image has no contrast S alone
// decides and the surface is a smooth membrane spanning the contour.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct CuttingSurfaceOptions {
  double wg = 1.0;  // eq. 15 image weight: -w_g E per pixel, E = edge strength (G / boundary contrast) x direction
  double wc = 0.1;  // eq. 15 continuity weight (S in pixels of depth per pixel)
  // Part weight: where the part stands out of the object's surface around the contour (a nose on a
  // face), the part is what stands out; each pixel of depth below the continuation of that surface
  // costs w_p (scaled by how far the part stands out there). 0: the surface may follow any deeper edge.
  double wp = 1.0;
  // Direction consistency of the image term (eq. 15-16): E is scaled by (1 - wd) + wd |n . g/|g||,
  // n the projection direction: an edge the height field can lie along faces the projection
  // direction; a wall parallel to it is crossed, not followed. 0: gradient magnitude alone.
  double wd = 0.5;
  double pixelMm = 0;  // projection grid pixel, mm; 0 = the smallest voxel spacing
  // Search along each line within +-depthFactor * contour radius of the shape without contrast (a
  // cap behind a hemispherical interface is as deep as the contour's radius).
  double depthFactor = 1.2;
  int rimPixels = 2;                   // the surface extends this many pixels beyond the contour (closes the rim)
  double gradientBlurVoxels = 1.0;     // binomial pre-smoothing of the volume before G (noise), voxels
  double noiseFloor = 0.1;             // G below this fraction of the boundary contrast counts as no edge
  double boundaryErosionVoxels = 1.5;  // G is ignored this close to the object's outer boundary
};

// The terms of the energy the minimum cut minimised, at its optimum (before the ridge step):
// image = -w_g sum E (<= 0), continuity = w_c sum S, part = w_p sum (depth below the continuation).
struct CuttingSurfaceEnergy {
  double image = 0, continuity = 0, part = 0;
  int64_t pixels = 0;       // free pixels of the disc
  double edgeFraction = 0;  // of those, the pixels whose chosen depth lies on an edge (E > 0)
  double standingOut = 0;   // mean weight of the part term over the disc (0: nothing stands out)
  // sum over the free pixels of the strongest E along the pixel's search line (pixels' worth of
  // edge): what the image term could gain if the other terms allowed; with image ~ 0 it tells "no
  // edge within reach" (0) from "edges, but too deep or too steep for their price" (> 0)
  double edgeWithinReach = 0;
  // Share of a term in the minimised energy: |term| / (|image| + continuity + part); 0 when all vanish.
  double share(double term) const {
    const double total = std::abs(image) + continuity + part;
    return total > 0 ? std::abs(term) / total : 0.0;
  }
};

struct CuttingSurface {
  Vec3 center{0, 0, 0};  // plane origin, world mm
  Vec3 normal{0, 0, 1};  // plane normal (direction of the contour's vector area)
  Vec3 axisU{1, 0, 0}, axisV{0, 1, 0};
  double pixelMm = 1;
  int64_t width = 0, height = 0;
  double u0 = 0, v0 = 0;        // plane coordinates (mm) of pixel (0,0)'s centre
  std::vector<int32_t> ring;    // L per pixel: 0 on the contour and the rim beyond it, k inside, -1 outside the domain
  std::vector<double> depth;    // height t (mm along normal) per pixel; NaN outside the domain
  double projectedAreaMm2 = 0;  // area enclosed by the projected contour
  CuttingSurfaceEnergy energy;

  bool inDomain(int64_t x, int64_t y) const {
    return x >= 0 && y >= 0 && x < width && y < height && ring[size_t(y * width + x)] >= 0;
  }
  Vec3 point(int64_t x, int64_t y) const {
    return center + (u0 + double(x) * pixelMm) * axisU + (v0 + double(y) * pixelMm) * axisV +
           depth[size_t(y * width + x)] * normal;
  }
  // The surface as triangles (two per grid cell with four domain corners), world mm.
  TriMesh mesh() const;
};

// `contourMm`: the closed loop (world mm, each point once). G is normalised by the object's
// boundary contrast near the cut (the 99th percentile of G around it) less `noiseFloor`.
// Throws DataError when the contour encloses no area in any plane, InvalidArgument on bad options.
CuttingSurface buildCuttingSurface(const VolumeF32& volume, double iso, const std::vector<Vec3>& contourMm,
                                   const CuttingSurfaceOptions& options = {}, Progress& progress = Progress::none());

}  // namespace vs
