// Polygonal data files, the one home of these formats: XML PolyData (.vtp, ASCII, binary,
// appended and compressed: VTK's reader and writer), legacy VTK (.vtk, the 5.1 layout VTK 9
// writes and the older one, ASCII or binary: our reader in polydata_scan, VTK's writer) and STL
// (.stl, binary or ASCII: VTK's reader and writer). Plain types in and out, so no VTK header
// reaches the callers (io/mesh_io reads and writes meshes, trees and polylines through here;
// io/overlay_io reads overlays). Coordinates are taken as they are stored (world mm here).
//
// Safety: VTK 9.1's legacy reader crashed under the project's fuzz targets, so legacy files are
// parsed by our own reader (every count checked against the bytes left before allocating). An
// STL file's size must match its triangle count (binary) or it must be text starting with
// "solid" (ASCII) before VTK's reader, which allocates what the header announces, sees it.
// VTK's errors and warnings are collected by an observer on the reader and become one IoError
// naming the file; every cell's point ids are checked and every point must be finite.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "mesh/tri_mesh.h"

namespace vs {

// A polygonal-data file as VTK holds it: every point once, cells as point ids into `points`,
// and named one-component point arrays. What a tree needs (its parent links are 2-point line
// cells sharing points; its radius and type are point arrays).
struct PolyDataCells {
  TriMesh mesh;                                             // every point (normals when the file has them for
                                                            // every point); polygons (fanned) and strips as triangles
  std::vector<std::vector<int32_t>> lines;                  // line cells, point ids into mesh.positions
  std::map<std::string, std::vector<double>> pointScalars;  // one value per point, by array name
};

// By extension (.vtp, .vtk or .stl). IoError naming the file and the problem (VTK's complaint,
// a count the file cannot hold, a point id out of range, a non-finite point); InvalidArgument
// for another extension.
PolyDataCells readPolyDataCells(const std::string& path);

struct PolyDataWriteOptions {
  bool binary = true;      // .vtp: appended raw binary (false: ASCII); .vtk: binary (false: ASCII,
                           // which VTK writes with 11 significant digits); .stl: binary (false: ASCII)
  bool compressed = true;  // .vtp only: zlib-compressed blocks
};

// Writes atomically by extension (.vtp, .vtk or .stl) with VTK's writers (IoError on failure,
// and no file under `path`). STL holds triangles only (float32, no normals, no lines).
void writePolyDataCells(const PolyDataCells& cells, const std::string& path, const PolyDataWriteOptions& options = {});

// The same files seen as a mesh and polylines (overlays).
struct PolyDataContent {
  TriMesh mesh;                 // every point of the file; triangles from polygons and strips
                                // (empty when the file holds no triangle)
  std::vector<Polyline> lines;  // one per line cell; radii from a point array "radius" if present;
                                // a cell whose last id repeats its first (4 ids or more) is closed
  bool empty() const { return mesh.triangles.empty() && lines.empty(); }
};

PolyDataContent readPolyDataFile(const std::string& path);

// Each polyline gets its own points (a closed one repeats its first id at the end); a point
// array "radius" is written when every line has radii (so radii read back as written).
void writePolyDataFile(const PolyDataContent& content, const std::string& path,
                       const PolyDataWriteOptions& options = {});

// The cells of `lines` appended to `cells` (as writePolyDataFile stores them).
void appendPolylineCells(const std::vector<Polyline>& lines, PolyDataCells& cells);

}  // namespace vs
