// Checks on a polygonal-data file's bytes before VTK's reader sees them (polydata_file.cpp):
// VTK allocates what a header announces, so a count the file cannot hold is refused first.
#pragma once

#include <string>

namespace vs::polydata_detail {

// A legacy VTK file ("# vtk DataFile"): every count of POINTS, POLYGONS / LINES / VERTICES /
// TRIANGLE_STRIPS, POINT_DATA / CELL_DATA arrays (SCALARS, COLOR_SCALARS, VECTORS, NORMALS,
// TEXTURE_COORDINATES, TENSORS, GLOBAL_IDS, PEDIGREE_IDS), LOOKUP_TABLE and FIELD arrays must fit
// in the bytes after its keyword line: ASCII values take at least 2 bytes ("1 "), binary ones
// their type's size. IoError "<path>: POINTS count N is not possible with B bytes left (truncated
// or corrupt)".
void checkLegacyVtkCounts(const std::string& path, const std::string& bytes);

// An STL file: binary when its size is 84 + 50 * (the count at byte 80), ASCII when it starts
// with "solid"; anything else is an IoError (truncated or not STL).
void checkStlSize(const std::string& path, const std::string& bytes);

}  // namespace vs::polydata_detail
