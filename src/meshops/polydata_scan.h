// Our own parsing where VTK's reader is not safe on hostile files (polydata_file.cpp): the legacy
// VTK reader, and the STL size check before VTK's STL reader allocates what its header announces.
#pragma once

#include <string>

#include "meshops/polydata_file.h"

namespace vs::polydata_detail {

// A legacy VTK polydata file (versions up to 5.1, ASCII or big-endian binary), parsed by our
// own reader: VTK 9.1's vtkPolyDataReader dereferences a closed stream on malformed cells (the
// fuzz targets meshvtk, treevtk and overlayvtk crashed it within 150 inputs), so it is not used.
// Every count is checked against the bytes left before anything is allocated ("POINTS count N is
// not possible with B bytes left (truncated or corrupt)"); cell ids are checked against the
// points; polygons are fanned from their first point; one-component point arrays (SCALARS and
// FIELD arrays) by name. IoError naming the file.
PolyDataCells readLegacyVtk(const std::string& path, const std::string& bytes);

// An STL file: binary when its size is 84 + 50 * (the count at byte 80), ASCII when it starts
// with "solid" and holds text only; anything else is an IoError (truncated or not STL).
void checkStlSize(const std::string& path, const std::string& bytes);

}  // namespace vs::polydata_detail
