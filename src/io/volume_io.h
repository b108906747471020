// Volume file I/O. The only part of volscissors that sees ITK (and GDCM through it).
// Reads NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), MetaImage (.mha, .mhd), legacy VTK
// structured points (.vtk), VTK XML image data (.vti), a DICOM series from a directory,
// and 2D PNG/TIFF images. Writes NIfTI, NRRD and MetaImage keeping spacing, origin, direction.
// World coordinates are LPS mm as ITK reports them.
// Errors: IoError naming the file and the problem (missing, truncated, wrong magic,
// unsupported type), DataError for dimensions too large to allocate (checked from the
// header before allocating); never a partial output (writes are atomic). Messages are one line.
//
// Voxel types (see docs/notes/io.md): uint8, int16, uint16, float32 are kept; int8 -> int16;
// wider integers -> the smallest of uint8/int16/uint16 that holds the actual range, else
// float32; float64 -> float32; RGB(A) -> luminance, other multi-component -> first component;
// each conversion adds a note. Intensity scaling: NIfTI scl_slope/scl_inter and DICOM rescale
// are applied; the result is float32 unless the stored type is an integer and slope and
// intercept are integral, in which case the narrowest integer type holding the values is used.
// DICOM folders: the series with most files (others listed in notes), slices sorted by
// position, z spacing = mean step along the slice normal.
// Cost: one pass over the file; supported scalar types are read straight into the volume.
#pragma once

#include <string>
#include <vector>

#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

struct ReadOptions {
  bool allow2D = true;         // false: a 2D image where a volume is needed is an IoError
  std::string dicomSeriesUid;  // DICOM directory: pick this series (default: the largest)
};

struct ReadInfo {
  std::string format;               // "nifti", "nrrd", "metaimage", "dicom", "vtk", "vti", "png", "tiff"
  std::string sourceType;           // voxel type on disk before conversion, e.g. "uint8*2.2086"
  std::vector<std::string> notes;   // conversions applied, other DICOM series found, ...
  bool orientationInHeader = true;  // false: the header states no orientation, identity (LPS) assumed
};

// Reads any supported volume; `path` may be a DICOM folder or one file of a series.
// 2D images come back with dims.z == 1. Throws IoError / DataError.
// Progress: report(0, "read") before the voxels are read and report(1, "read") when the volume is
// ready; a cancel takes effect at these two points (Cancelled), not inside one reader call.
AnyVolume readVolume(const std::string& path, const ReadOptions& options = {}, ReadInfo* info = nullptr,
                     Progress& progress = Progress::none());

// Writes by extension: .nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd, keeping the voxel type
// (label maps stay uint8/uint16), spacing, origin and direction. .nii.gz/.nrrd/.mha are
// compressed. Atomic (.nhdr/.mhd: data file first, header last). Throws IoError.
void writeVolume(const AnyVolume& volume, const std::string& path);

// The extensions writeVolume writes (lower case; ".nii.gz" one extension, ".zarr" a folder): the
// one list every front end checks an output name against.
const std::vector<std::string>& volumeWriteExtensions();
// True when writeVolume writes `path` (by its extension, compared case-insensitively).
bool isVolumeWritePath(const std::string& path);

}  // namespace vs
