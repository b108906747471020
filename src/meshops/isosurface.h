// The one module that includes VTK (Debian's libvtk9-dev, VTK 9.1), kept behind this boundary as
// ITK is behind src/io: iso-surfaces (vtkFlyingEdges3D), smoothing (vtkWindowedSincPolyDataFilter),
// decimation (vtkQuadricDecimation) and connected components (vtkPolyDataConnectivityFilter).
// Inputs and outputs are the project's plain types (Volume, TriMesh in world mm), so no VTK header
// leaks to callers.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/tri_mesh.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct IsoSurfaceOptions {
  double iso = 0;  // iso-value in the volume's units
  bool largestComponentOnly = true;
  int smoothIterations = 0;      // vtkWindowedSincPolyDataFilter, 0 = off
  double decimateReduction = 0;  // vtkQuadricDecimation target reduction in [0,1), 0 = off
};

// World-mm (LPS) triangle mesh with outward vertex normals, via vtkFlyingEdges3D.
// "Outward" points from values above `iso` to values below it (the object is the bright side);
// triangles are counter-clockwise seen from outside. Runs in index space and maps the vertices
// through the volume's geometry, so anisotropic spacing and any direction matrix are honoured.
// Throws InvalidArgument (empty volume, non-finite iso, iterations < 0, reduction outside [0,1)),
// DataError when the iso-value crosses no voxel edge (names the volume's value range).
// Cancellable between stages through `progress`.
TriMesh extractIsoSurface(const Volume<float>& volume, const IsoSurfaceOptions& options,
                          Progress& progress = Progress::none());

// Connected components (vertices joined through triangles), vtkPolyDataConnectivityFilter.
// Returns one component id per vertex, ids 0..count-1 ordered by decreasing vertex count
// (0 = the largest); vertices used by no triangle get -1.
std::vector<int32_t> meshComponents(const TriMesh& mesh, int32_t* componentCount = nullptr);

// The sub-mesh of the vertices whose component id is `component` (ids as meshComponents
// returns them), vertices renumbered in their original order, normals kept.
TriMesh keepComponent(const TriMesh& mesh, const std::vector<int32_t>& componentOfVertex, int32_t component);

// The component "nearest the user's points": each point votes for the component of its nearest
// vertex; the most votes win (ties: the larger component). Points are world mm. Throws
// InvalidArgument on an empty mesh or no points.
TriMesh keepComponentNearest(const TriMesh& mesh, const std::vector<Vec3>& pointsMm);

// Area-weighted vertex normals from the triangles' winding (unit length; zero for isolated vertices).
std::vector<Eigen::Vector3d> vertexNormals(const TriMesh& mesh);

}  // namespace vs
