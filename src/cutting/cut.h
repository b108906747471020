// Volume cutting, the whole pipeline of thesis ch. 3 / 5.1 (issue 14): surface mesh of the object
// -> closed live-wire contour through the user's points on the mesh -> internal cutting surface
// -> split into two labelled parts. Points are continuous voxel indices of the volume.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cutting/cutting_surface.h"
#include "cutting/mesh_livewire.h"
#include "cutting/split.h"
#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

enum class CutMeshKind {
  Iso,     // iso-surface (vtkFlyingEdges3D), the component nearest the points
  EnvMap,  // the thesis's environment map from the object's centroid (star-shaped objects only)
};

struct CutOptions {
  double iso = 0;  // the object is the voxels >= iso
  CutMeshKind meshKind = CutMeshKind::Iso;
  std::vector<Vec3> pointsIndex;   // the user's points around the part, in loop order (either way)
  double snapRadiusMm = 3;         // 3D snap radius; farther points are refused
  std::optional<Index3> keepSeed;  // voxel whose side is kept (default: the larger side)
  MeshCostOptions cost;
  CuttingSurfaceOptions surface;
};

struct CutResult {
  TriMesh mesh;  // the object's surface mesh (component nearest the points)
  MeshContour contour;
  std::vector<Vec3> contourMm;  // contour vertex positions, world mm
  std::vector<double> snapDistanceMm;
  CuttingSurface surface;
  SplitResult split;
  double seconds[4] = {0, 0, 0, 0};  // mesh, contour, cutting surface, split
};

// The weights of every front end (surface wg, wc, wp, wd; contour wg, wn, wl), checked before any
// work: InvalidArgument naming the weight. cutVolume calls it; the viewer calls it when they are set.
void checkCutWeights(const CutOptions& options);

// Throws InvalidArgument (< 3 points, bad options), DataError with a message that says what to
// change (no surface at iso, a point too far from the surface, a self-crossing loop, a contour that
// separates nothing, a bad seed).
CutResult cutVolume(const VolumeF32& volume, const CutOptions& options, Progress& progress = Progress::none());

// The object's surface mesh ready for live-wire: vertex features and the eq. 13 graph. Made once
// for many cuts of one object (the interactive case, the robustness campaign).
struct CutMesh {
  TriMesh mesh;
  VertexFeatures features;
  CsrGraph graph;
};
CutMesh prepareCutMesh(const VolumeF32& volume, TriMesh mesh, const MeshCostOptions& cost = {});

// cutVolume after the mesh: `mesh` must be the surface of `volume` at options.iso, made with
// options.cost (CutResult::seconds[0] stays 0). Same errors as cutVolume.
CutResult cutOnMesh(const VolumeF32& volume, const CutMesh& mesh, const CutOptions& options,
                    Progress& progress = Progress::none());

}  // namespace vs
