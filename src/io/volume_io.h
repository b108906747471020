// Volume file I/O. The only part of volscissors that sees ITK (and GDCM through it).
// Reads NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), MetaImage (.mha, .mhd), legacy VTK
// structured points (.vtk), VTK XML image data (.vti), a DICOM series from a directory,
// and 2D PNG/TIFF images. Writes NIfTI, NRRD and MetaImage keeping spacing, origin, direction.
// World coordinates are LPS mm as ITK reports them.
// Errors: IoError naming the file and the problem (missing, truncated, wrong magic,
// unsupported type, absurd dimensions); never a partial output (writes are atomic).
#pragma once

#include <string>
#include <vector>

#include "volume/volume.h"

namespace vs {

struct ReadOptions {
  bool allow2D = true;            // false: a 2D image where a volume is needed is an IoError
  std::string dicomSeriesUid;     // DICOM directory: pick this series (default: the largest)
};

struct ReadInfo {
  std::string format;                    // "nifti", "nrrd", "metaimage", "dicom", "vtk", "vti", "png", "tiff"
  std::string sourceType;                // voxel type on disk before conversion, e.g. "uint8*2.2086"
  std::vector<std::string> notes;        // conversions applied, other DICOM series found, ...
};

// Reads any supported volume. Throws IoError / DataError.
AnyVolume readVolume(const std::string& path, const ReadOptions& options = {}, ReadInfo* info = nullptr);

// Writes by extension: .nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd. Atomic. Throws IoError.
void writeVolume(const AnyVolume& volume, const std::string& path);

}  // namespace vs
