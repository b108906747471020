// `volscissors info FILE [--json OUT]`: what a volume file holds - dims, spacing, origin,
// direction, voxel type, value range (and NaN/inf count), memory size, format, notes.
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "command.h"
#include "io/volume_io.h"
#include "io/zarr_io.h"
#include "util/atomic_file.h"
#include "volume/slice.h"

namespace {

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(8) << (v == 0 ? 0.0 : v);  // no "-0"
  return os.str();
}

std::string vec3(const vs::Vec3& v) { return num(v[0]) + " " + num(v[1]) + " " + num(v[2]); }

// An OME-Zarr folder from its metadata (issue 25: volumes larger than memory): the value range is
// read from the coarsest pyramid level (at most a chunk or so), or from level 0 when the folder
// has no pyramid and level 0 is small; `rangeOf` says which.
void zarrSummary(const std::string& path, vs::ReadInfo& info, vs::Geometry& g, vs::ValueRange& r, uint64_t& bytes,
                 std::string& type, std::string& rangeOf) {
  vs::ZarrInfo zi;
  const vs::ChunkedVolume cv = vs::openZarr(path, 0, &zi);
  g = cv.geometry;
  type = vs::voxelTypeName(cv.type);
  bytes = uint64_t(g.voxelCount()) * vs::voxelTypeSize(cv.type);
  info.format = "ome-zarr";
  info.sourceType = zi.dtype;
  info.notes = zi.notes;
  info.orientationInHeader = zi.hasDirection;
  const auto& L = zi.levels;
  std::string levels;
  for (size_t l = 0; l < L.size(); ++l)
    levels += (l ? ", " : "") + std::to_string(L[l].dims[0]) + "x" + std::to_string(L[l].dims[1]) + "x" +
              std::to_string(L[l].dims[2]);
  info.notes.push_back(std::to_string(L.size()) + " level(s) " + levels + "; chunks " + std::to_string(cv.chunk[0]) +
                       "x" + std::to_string(cv.chunk[1]) + "x" + std::to_string(cv.chunk[2]) + ", compressor " +
                       zi.compressor + "; only the metadata" + (L.size() > 1 ? " and the coarsest level" : "") +
                       " were read");
  const int last = int(L.size()) - 1;
  if (last > 0) {
    r = vs::valueRange(vs::readZarr(path, last));
    const std::string side = std::to_string(1 << last);
    rangeOf = "of level " + std::to_string(last) + ", means of " + side + "x" + side + "x" + side +
              " voxels: the full resolution's extremes may lie outside";
  } else if (bytes <= (uint64_t(64) << 20)) {
    r = vs::valueRange(vs::readZarr(path, 0));
  } else {
    r = {std::nan(""), std::nan(""), 0};
    rangeOf = "not read: no pyramid, and reading every chunk of level 0 would be needed";
  }
}

vs::cli::Runner setup(CLI::App& sub) {
  struct Opts {
    std::string file, json, series;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option(
         "file", o->file,
         "volume file (.nii .nii.gz .nrrd .nhdr .mha .mhd .vtk .vti .png .tif), DICOM folder, or OME-Zarr folder "
         "(.zarr: only its metadata and coarsest level are read)")
      ->required();
  sub.add_option("--json", o->json, "also write the report as JSON to this file");
  sub.add_option("--series", o->series, "DICOM folder: series instance UID (prefix) to read (default: the largest)");
  return [o] {
    vs::ReadInfo info;
    vs::Geometry g;
    vs::ValueRange r;
    uint64_t bytes = 0;
    std::string type, rangeOf;  // rangeOf: what the range was taken from, when not every voxel
    if (vs::isZarrPath(o->file)) {
      if (!o->series.empty()) throw vs::UsageError("--series applies to DICOM folders only");
      zarrSummary(o->file, info, g, r, bytes, type, rangeOf);
    } else {
      vs::ReadOptions ro;
      ro.dicomSeriesUid = o->series;
      const vs::AnyVolume vol = vs::readVolume(o->file, ro, &info);
      g = vs::geometryOf(vol);
      r = vs::valueRange(vol);
      bytes = vs::byteSize(vol);
      type = vs::voxelTypeName(vs::voxelType(vol));
    }

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
    if (!rangeOf.empty()) std::cout << "   (" << rangeOf << ")";
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
      if (!rangeOf.empty()) j["range_of"] = rangeOf;
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
