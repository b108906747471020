// libFuzzer target for one file reader: the input bytes become a file with the reader's
// extension (VS_FUZZ_EXT) in a private folder, read by VS_FUZZ_READER. A reader may refuse
// the file with vs::Error (that is its job); anything else (a crash, a sanitizer report,
// another exception, a hang, an out-of-memory) is a bug the fuzzer reports.
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/contour_io.h"
#include "io/mesh_io.h"
#include "io/overlay_io.h"
#include "io/png_io.h"
#include "io/report_io.h"
#include "io/targets_io.h"
#include "io/volume_io.h"
#include "io/zarr_io.h"

namespace {

const std::string& scratchFile() {
  static const std::string path = [] {
    const auto dir = std::filesystem::temp_directory_path() / ("vs_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(std::filesystem::temp_directory_path() / ("vs_fuzz_" + std::to_string(::getpid())),
                                  ec);
    });
    return (dir / ("input" VS_FUZZ_EXT)).string();
  }();
  return path;
}

void readAs(const std::string& path) {
  const std::string kind = VS_FUZZ_READER;
  if (kind == "volume")
    vs::readVolume(path);
  else if (kind == "mesh")
    vs::readTriMesh(path);
  else if (kind == "tree")
    vs::readTree(path);
  else if (kind == "polylines")
    vs::readPolylines(path);
  else if (kind == "png")
    vs::readPng(path);
  else if (kind == "contour")
    vs::readContour(path);
  else if (kind == "report")
    vs::readTraceReport(path);
  else if (kind == "overlay") {
    // A small anisotropic, rotated volume: overlays in voxel index are mapped through it.
    vs::Geometry geometry;
    geometry.dims = {40, 30, 20};
    geometry.spacing = {0.8, 0.8, 2.0};
    geometry.origin = {-10.0, 5.0, 3.0};
    geometry.direction << 0, 1, 0, -1, 0, 0, 0, 0, 1;
    vs::readOverlay(path, geometry);
  } else if (kind == "targets") {
    vs::readTargetList(path);
  } else if (kind == "zarr") {
    // The input is an OME-Zarr folder in one file: level 0's .zarray text, a NUL byte, then the
    // bytes of its chunk 0.0.0 (scripts/fuzz.sh builds the seed from a converted phantom).
    std::ifstream in(path, std::ios::binary);
    const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t cut = all.find('\0');
    const std::filesystem::path dir = path + ".zarr";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "0");
    std::ofstream(dir / ".zattrs") << R"({"multiscales": [{"version": "0.4", "axes": [{"name": "z", "type": "space"},
      {"name": "y", "type": "space"}, {"name": "x", "type": "space"}], "datasets": [{"path": "0"}]}]})";
    std::ofstream(dir / "0" / ".zarray") << all.substr(0, cut);
    if (cut != std::string::npos) std::ofstream(dir / "0" / "0.0.0", std::ios::binary) << all.substr(cut + 1);
    vs::readVolume(dir.string());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string& path = scratchFile();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  try {
    readAs(path);
  } catch (const vs::Error&) {
    // refused with a message: fine
  }
  return 0;
}
