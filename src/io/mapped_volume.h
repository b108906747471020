// Uncompressed NIfTI and NRRD volumes as chunked volumes through a memory mapping (issue 25):
// the voxel data of a file larger than memory is mapped read-only and served chunk by chunk
// (volume/chunked_volume.h: ChunkCache), converted when a chunk is read (byte order, type, NIfTI
// scl_slope/scl_inter), so only the pages of the chunks a search or a slice touches are read.
//
// Mappable: NIfTI-1/NIfTI-2 single files (.nii) and pairs (.hdr/.img), NRRD (.nrrd/.nhdr) with
// raw encoding, one component per voxel and the data attached or in one detached file (byte
// skip >= 0 or -1, line skip). Not mappable (isMappable false, openMapped IoError): gzip'd
// files, ASCII or compressed NRRD encodings, slice patterns and LISTs of data files.
// Geometry as readVolume gives it (nibabel's sform/qform reading for NIfTI, space directions or
// spacings for NRRD); the first 3D volume of a 4D NIfTI. Values: uint8/int16/uint16/float32
// kept (served as float), other types and scaled NIfTI data served as float32
// (double(v) * slope + inter, like the in-memory reader).
// Validation (IoError naming the file): header fields, dims >= 1, supported type, the data's
// offset and size against the file's length (a truncated file is refused when opened, not when a
// chunk past its end is read), overflow of every size.
#pragma once

#include <string>

#include "io/volume_io.h"
#include "volume/chunked_volume.h"

namespace vs {

// True if `path` is a NIfTI or NRRD file whose voxels openMapped can map (reads the header only;
// false for unreadable or malformed headers: the ordinary reader then says what is wrong).
bool isMappable(const std::string& path);

// Maps the voxel data of `path` (see above). `info`: format, source type, notes.
ChunkedVolume openMapped(const std::string& path, ReadInfo* info = nullptr, const Index3& chunk = {64, 64, 64});

}  // namespace vs
