// `volscissors info FILE [--json OUT]`: what a volume file holds - dims, spacing, origin,
// direction, voxel type, value range (and NaN/inf count), memory size, format, notes.
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "command.h"
#include "io/volume_io.h"
#include "util/atomic_file.h"
#include "volume/slice.h"

namespace {

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(8) << (v == 0 ? 0.0 : v);  // no "-0"
  return os.str();
}

std::string vec3(const vs::Vec3& v) { return num(v[0]) + " " + num(v[1]) + " " + num(v[2]); }

vs::cli::Runner setup(CLI::App& sub) {
  struct Opts {
    std::string file, json, series;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option("file", o->file,
                 "volume file (.nii .nii.gz .nrrd .nhdr .mha .mhd .vtk .vti .png .tif) or DICOM folder")
      ->required();
  sub.add_option("--json", o->json, "also write the report as JSON to this file");
  sub.add_option("--series", o->series, "DICOM folder: series instance UID (prefix) to read (default: the largest)");
  return [o] {
    vs::ReadOptions ro;
    ro.dicomSeriesUid = o->series;
    vs::ReadInfo info;
    const vs::AnyVolume vol = vs::readVolume(o->file, ro, &info);
    const vs::Geometry& g = vs::geometryOf(vol);
    const vs::ValueRange r = vs::valueRange(vol);
    const uint64_t bytes = vs::byteSize(vol);
    const std::string type = vs::voxelTypeName(vs::voxelType(vol));

    const std::string orientation = vs::orientationCode(g);
    static const char* const words[] = {"left", "posterior", "superior", "right", "anterior", "inferior"};
    const vs::AxisAlignment align = vs::alignAxes(g);
    std::string axisWords, planes;
    for (int a = 0; a < 3; ++a) {
      const size_t i = static_cast<size_t>(a);
      axisWords += std::string(a ? ", " : "") + words[align.worldAxis[i] + (align.sign[i] < 0 ? 3 : 0)];
      planes += std::string(a ? ", " : "") + "xyz"[a] + "=K " + vs::anatomicalPlaneName(vs::sliceFrame(g, a, 0).plane);
    }
    if (!info.orientationInHeader)
      vs::cli::warn(o->file + ": the " + info.format +
                    " header states no orientation; identity direction (LPS) assumed, so left/right and "
                    "anterior/posterior may be wrong");
    std::cout << "file:      " << o->file << '\n'
              << "format:    " << info.format << '\n'
              << "dims:      " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << '\n'
              << "spacing:   " << vec3(g.spacing) << " mm\n"
              << "origin:    " << vec3(g.origin) << " mm (LPS)\n"
              << "direction: [" << vec3(g.direction.row(0)) << "; " << vec3(g.direction.row(1)) << "; "
              << vec3(g.direction.row(2)) << "] (columns = index axes)\n"
              << "orientation: " << orientation << " (index x, y, z point to " << axisWords << ")"
              << (info.orientationInHeader ? "" : " - NOT in the header: assumed") << '\n'
              << "slices:    " << planes << '\n'
              << "type:      " << type << " (on disk: " << info.sourceType << ")\n"
              << "range:     " << num(r.min) << " .. " << num(r.max);
    if (r.nonFinite > 0) std::cout << "   (" << r.nonFinite << " NaN/inf voxels)";
    std::cout << '\n' << "memory:    " << bytes << " bytes (" << num(double(bytes) / (1 << 20)) << " MiB)\n";
    for (const auto& n : info.notes) std::cout << "note:      " << n << '\n';

    if (!o->json.empty()) {
      nlohmann::json j;
      j["file"] = o->file;
      j["format"] = info.format;
      j["dims"] = {g.dims[0], g.dims[1], g.dims[2]};
      j["spacing"] = {g.spacing[0], g.spacing[1], g.spacing[2]};
      j["origin"] = {g.origin[0], g.origin[1], g.origin[2]};
      nlohmann::json d = nlohmann::json::array();
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) d.push_back(g.direction(row, col) == 0 ? 0.0 : g.direction(row, col));
      j["direction"] = d;
      j["type"] = type;
      j["source_type"] = info.sourceType;
      j["range"] = {r.min, r.max};
      j["non_finite"] = r.nonFinite;
      j["bytes"] = bytes;
      j["notes"] = info.notes;
      j["orientation"] = orientation;
      j["orientation_in_header"] = info.orientationInHeader;
      vs::writeFileAtomically(o->json, j.dump(2) + "\n");
    }
    return 0;
  };
}

const vs::cli::Registration reg{"info", "print dims, spacing, orientation, type and value range of a volume", setup};

}  // namespace
