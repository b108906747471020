// The only interface to ITK (internal to src/io). Kept free of Eigen and of our volume
// types: ITK 5.2 ships its own Eigen 3.3 in namespace Eigen, which cannot share a
// translation unit with the system Eigen 3.4 our Geometry uses. All functions convert
// itk::ExceptionObject into vs::IoError naming the file.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "io/io_comp.h"

namespace vs::io_detail {

enum class ItkFormat { Nifti, Nrrd, Meta, Png, Tiff };

struct RawHeader {
  int ndim = 3;  // dimensions in the file (2..n); only the first 3 are read
  int64_t dims[3] = {1, 1, 1};
  double spacing[3] = {1, 1, 1};
  double origin[3] = {0, 0, 0};
  double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major; column j = world direction of axis j
  Comp comp = Comp::UInt8;                            // component type delivered into the buffer
  int ncomp = 1;
  std::string sourceType;  // type stored on disk (DICOM: before rescale)
  std::vector<std::string> notes;
};

// Called once the header is known; returns where to read count * compSize * ncomp bytes
// (the callee checks the allocation size and may throw).
using Allocator = std::function<void*(const RawHeader&)>;

// Reads one file. Fills `header` and the buffer returned by alloc.
void itkReadFile(ItkFormat fmt, const std::string& path, const Allocator& alloc, RawHeader& header);

// Writes a scalar 3D volume (header.comp must be uint8/int16/uint16/float32).
void itkWriteFile(ItkFormat fmt, const std::string& path, const RawHeader& header, const void* data, bool compress);

}  // namespace vs::io_detail
