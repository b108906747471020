// Overlays drawn over a volume (render, viewer): meshes, trees, polylines, tracking reports
// and live-wire contours, read by extension and, for JSON, by content. One reader and one
// bounds check for every front end.
//   .obj .ply .stl            triangle mesh, world mm
//   .vtk .vtp                 legacy (versions up to 5.1) and XML polydata, read by VTK
//                             (meshops/polydata_file.h): its mesh and its lines (neither: IoError)
//   .swc                      tree, world mm
//   .json {"paths":[{"voxels":[[x,y,z]..]}..]}          tracking report, voxel index
//   .json {"points_index":[[x,y,z]..], "closed":b}      live-wire contour (io/contour_io.h), voxel index
//   .json {"points":[[u,v]..], "slice":"z=40" | {"axis":2|"z","index":40}}   slice pixels (volume/slice.h)
//   .json {"nodes":[..]} / {"polylines":[..]}           tree / polylines, world mm (io/mesh_io.h)
// Voxel-index overlays are mapped to world mm through the volume's geometry.
// Errors: IoError naming the file (unreadable, malformed, unknown JSON layout);
// InvalidArgument for an unsupported extension (the front end's usage error).
#pragma once

#include <string>
#include <vector>

#include "mesh/tri_mesh.h"
#include "volume/geometry.h"

namespace vs {

struct Overlay {
  TriMesh mesh;                 // world mm
  std::vector<Polyline> lines;  // world mm
  int64_t points = 0;           // mesh vertices + line points
  int64_t pointsOutside = 0;    // of which outside the volume (Geometry::nearVolume false)
  bool empty() const { return points == 0; }
};

// Extensions readOverlay accepts, for messages: ".obj .ply .stl .vtk .vtp .swc .json".
const char* overlayExtensions();

Overlay readOverlay(const std::string& path, const Geometry& volumeGeometry);

}  // namespace vs
