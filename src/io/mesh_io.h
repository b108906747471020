// Meshes, polylines and trees to and from files. Coordinates are world mm (the
// writers do not change them). Writes are atomic; errors are IoError naming the file.
#pragma once

#include <string>
#include <vector>

#include "mesh/tri_mesh.h"

namespace vs {

// By extension: .obj (text), .ply (binary little-endian), .stl (binary), .vtk (legacy polydata).
void writeTriMesh(const TriMesh& mesh, const std::string& path);
TriMesh readTriMesh(const std::string& path);

// By extension: .swc, .vtk (legacy polydata lines), .json ({"nodes": [{"id","parent","xyz","radius","type"}]}).
void writeTree(const Tree& tree, const std::string& path);
Tree readTree(const std::string& path);

// By extension: .vtk (legacy polydata lines), .json ({"polylines": [{"points": [[x,y,z],...], "closed": b}]}).
void writePolylines(const std::vector<Polyline>& lines, const std::string& path);
std::vector<Polyline> readPolylines(const std::string& path);

}  // namespace vs
