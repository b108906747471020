// Polygonal data files through VTK's own readers and writers: XML PolyData (.vtp, ASCII,
// binary, appended and compressed) and legacy VTK (.vtk, the 5.1 layout VTK 9 writes, and the
// older one). Plain types in and out, so no VTK header reaches the callers (io/overlay_io reads
// .vtp overlays through here; .vtk overlays keep io's own hardened reader).
// Coordinates are taken as they are stored (world mm for this project's files).
#pragma once

#include <string>
#include <vector>

#include "mesh/tri_mesh.h"

namespace vs {

struct PolyDataContent {
  TriMesh mesh;                 // every point of the file; triangles from polygons and strips
  std::vector<Polyline> lines;  // one per line cell; radii from a point array "radius" if present
  bool empty() const { return mesh.triangles.empty() && lines.empty(); }
};

// By extension (.vtp or .vtk). IoError naming the file and VTK's complaint when the file cannot
// be read or holds no polygonal data, a point is not finite or an index is out of range;
// InvalidArgument for another extension.
PolyDataContent readPolyDataFile(const std::string& path);

struct PolyDataWriteOptions {
  bool binary = true;      // .vtp: appended raw binary (false: ASCII); .vtk: binary (false: ASCII)
  bool compressed = true;  // .vtp only: zlib-compressed blocks
};

// Writes atomically by extension (.vtp or .vtk) with VTK's writers (IoError on failure).
void writePolyDataFile(const PolyDataContent& content, const std::string& path,
                       const PolyDataWriteOptions& options = {});

}  // namespace vs
