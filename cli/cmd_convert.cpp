// `volscissors convert IN OUT`: any readable volume (file, DICOM folder or OME-Zarr folder) to
// NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), MetaImage (.mha, .mhd) or an OME-Zarr folder with a
// pyramid (.zarr), keeping spacing, origin, direction and the voxel type. Written atomically.
#include <iostream>

#include "args.h"
#include "command.h"
#include "io/volume_io.h"
#include "util/atomic_file.h"

namespace {

vs::cli::Runner setup(CLI::App& sub) {
  struct Opts {
    std::string in, out, series;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option("input", o->in, "volume file, DICOM folder or OME-Zarr folder")->required();
  sub.add_option(
         "output", o->out,
         "output: .nii .nii.gz .nrrd .nhdr .mha .mhd, or an OME-Zarr folder .zarr (chunks of 64, zlib, a pyramid)")
      ->required();
  sub.add_option("--series", o->series, "DICOM folder: series instance UID (prefix) to read");
  return [o] {
    vs::cli::requireExtension(o->out, "output", vs::cli::volumeOutputExtensions());
    vs::ReadOptions ro;
    ro.dicomSeriesUid = o->series;
    vs::ReadInfo info;
    const vs::AnyVolume vol = vs::readVolume(o->in, ro, &info);
    for (const auto& n : info.notes) vs::cli::note("note: " + n);
    vs::writeVolume(vol, o->out);
    const vs::Geometry& g = vs::geometryOf(vol);
    vs::cli::note("wrote " + o->out + " (" + g.describe() + ", " + vs::voxelTypeName(vs::voxelType(vol)) + ")");
    return 0;
  };
}

const vs::cli::Registration reg{"convert", "convert a volume to NIfTI, NRRD, MetaImage or OME-Zarr", setup};

}  // namespace
