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

#include <cstdint>
#include <vector>

#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct CuttingSurfaceOptions {
  double wg = 1.0;     // eq. 15 gradient weight (G / boundary contrast, clamped to 1)
  double wc = 0.1;     // eq. 15 continuity weight (S in pixels)
  double pixelMm = 0;  // projection grid pixel, mm; 0 = the smallest voxel spacing
  // Search along each line within +-depthFactor * contour radius of the shape without contrast (a
  // cap behind a hemispherical interface is as deep as the contour's radius).
  double depthFactor = 1.2;
  int rimPixels = 2;                   // the surface extends this many pixels beyond the contour (closes the rim)
  double gradientBlurVoxels = 1.0;     // binomial pre-smoothing of the volume before G (noise), voxels
  double noiseFloor = 0.1;             // G below this fraction of the boundary contrast counts as no edge
  double boundaryErosionVoxels = 1.5;  // G is ignored this close to the object's outer boundary
  // A contour point is on a seam when the object's inside, just below the surface, differs across
  // the contour by this fraction of the object's step at the surface; w_g is scaled by the
  // fraction of points on one.
  double seamThreshold = 0.2;
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
  double seamFraction = 0;      // of the contour points, those on a seam that interior edges start from

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
