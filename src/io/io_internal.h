// Internal helpers shared by the I/O readers (not part of the public API).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "io/io_comp.h"
#include "io/one_line.h"
#include "io/volume_io.h"

namespace vs::io_detail {

// Converts `count` voxels of `ncomp` interleaved components of type `c` at `src` (native
// byte order) into a supported volume: uint8/int16/uint16/float32 are kept, other types go
// to the smallest supported type that holds their range (else float32), multi-component
// voxels are reduced (RGB/RGBA -> luminance, otherwise first component). Notes are added
// to `info`. `what` names the file in errors.
AnyVolume convertBuffer(const void* src, Comp c, int ncomp, const Geometry& g, ReadInfo& info, const std::string& what);

// If `vol` is float32 and every voxel is integral and fits uint8/int16/uint16, returns the
// narrowest such integer volume (for integer data with an integral rescale); else unchanged.
AnyVolume narrowIntegral(AnyVolume vol, ReadInfo& info);

// Whole file contents; transparently gunzips when the file starts with the gzip magic.
std::string readFileBytes(const std::string& path, bool allowGzip = true);
// Bytes a gzip stream starting at `offset` in `path` inflates to: the trailer's ISIZE if it
// equals `expect` (mod 2^32, cheap; only when trustTrailer), otherwise a streaming count
// (multi-member or damaged; zlib streams, which have no ISIZE, always need the count).
double gzipInflatedSize(const std::string& path, double expect, uint64_t offset = 0, bool trustTrailer = true);
// Throws IoError if a NRRD file's (attached or single detached, raw/gzip) data is shorter
// than its header promises; does nothing for layouts it does not understand.
void checkNrrdComplete(const std::string& path);
// Inflates gzip (or zlib) data; `path` names the source in errors.
std::string gunzip(const std::string& bytes, const std::string& path);

// A data-file pattern "name%03d.raw first last step [subdim]" (NRRD `data file:`, MetaImage
// `ElementDataFile`). The format must hold exactly one integer conversion %d/%i/%u with an
// optional 0 flag and a width below 100 (and any number of "%%"); anything else is refused
// with an IoError naming `path`, because ITK's readers hand the pattern to printf as a
// format. Returns the expanded file names relative to the header's folder (at most 100000).
bool isSlicePattern(const std::string& field);
std::vector<std::string> expandSlicePattern(const std::string& field, const std::string& path);

// A NRRD header: its fields (keys lower case), the LIST data file names, where attached data starts.
struct NrrdHeader {
  std::map<std::string, std::string> fields;
  std::vector<std::string> listFiles;
  size_t dataStart = 0;
  std::string get(const std::string& k) const {
    auto it = fields.find(k);
    return it == fields.end() ? std::string() : it->second;
  }
};
// Parses the header at the start of `bytes` (IoError naming `path` when malformed); the type name
// of a NRRD `type:` field (false when unknown); the geometry of the spatial axes first..dim-1
// (space directions + origin, or spacings; RAS turned to LPS); the detached data files (empty:
// attached data).
NrrdHeader parseNrrdHeader(const std::string& bytes, const std::string& path);
bool nrrdType(const std::string& t, Comp& c);
void nrrdGeometry(const NrrdHeader& h, int first, int dim, Geometry& g, const std::string& path);
std::vector<std::string> nrrdDataFiles(const NrrdHeader& h, const std::string& path);

// Own readers (no ITK).
AnyVolume readVtkLegacyVolume(const std::string& path, ReadInfo& info);
AnyVolume readVtiVolume(const std::string& path, ReadInfo& info);
AnyVolume readNrrdOwn(const std::string& path, ReadInfo& info);
AnyVolume readPngVolume(const std::string& path, ReadInfo& info);  // in png_io.cpp
// A DICOM folder (the largest series, or options.dicomSeriesUid) or one DICOM file (its own
// series and orientation); see dicom_reader.cpp. Rescaled values, narrowed like NIfTI.
AnyVolume readDicomVolume(const std::string& path, const ReadOptions& options, ReadInfo& info, Progress& progress);

// Replaces the geometry ITK gave a NIfTI image with nibabel's reading of the header: sform
// when its code is set (a note when the qform differs), else qform; units applied to spacing
// and origin; near-orthonormal axes orthonormalised with a note. No change without codes.
void applyNiftiGeometry(const std::string& path, Geometry& g, ReadInfo& info);

// NIfTI voxels read without ITK (its NiftiImageIO refuses near-orthonormal float32 sforms
// and applies scl_inter when scl_slope is 0 or NaN, where nibabel applies no scaling):
// first 3D volume, |pixdim| spacing (applyNiftiGeometry sets the geometry), scaling applied
// when slope is finite and non-zero.
AnyVolume readNiftiVoxels(const std::string& path, double slope, double inter, ReadInfo& info);

// Whether the header states the axes' orientation (else the identity direction was assumed).
// `format` is ReadInfo::format.
bool headerHasOrientation(const std::string& path, const std::string& format);

void byteSwap(void* data, size_t elemSize, size_t count);
bool hostIsLittleEndian();

}  // namespace vs::io_detail
