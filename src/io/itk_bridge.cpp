// ITK ImageIO classes used directly: no IO-factory registration is needed and single
// files need no pixel-type templates. The header is read first, the caller allocates
// (after checking the size), then the voxels are read straight into that buffer.
#include "io/itk_bridge.h"

#include <itkImageIOBase.h>
#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>
#include <itkPNGImageIO.h>
#include <itkTIFFImageIO.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "io/one_line.h"
#include "util/error.h"

namespace vs::io_detail {

namespace {

using IOComp = itk::IOComponentEnum;

std::string flat(const std::string& s) {
  std::string out = oneLine(s);
  // Drop ITK's "ITK ERROR: NrrdImageIO(0x55d1...): " prefix: the file name says enough.
  const size_t p = out.find("ITK ERROR: ");
  if (p != std::string::npos) {
    const size_t close = out.find("): ", p);
    if (close != std::string::npos && out.find("(0x", p) < close) out.erase(p, close + 3 - p);
  }
  return out;
}

bool toComp(IOComp c, Comp& out) {
  switch (c) {
    case IOComp::CHAR:
      out = Comp::Int8;
      return true;
    case IOComp::UCHAR:
      out = Comp::UInt8;
      return true;
    case IOComp::SHORT:
      out = Comp::Int16;
      return true;
    case IOComp::USHORT:
      out = Comp::UInt16;
      return true;
    case IOComp::INT:
      out = Comp::Int32;
      return true;
    case IOComp::UINT:
      out = Comp::UInt32;
      return true;
    case IOComp::LONG:
      out = sizeof(long) == 8 ? Comp::Int64 : Comp::Int32;
      return true;
    case IOComp::ULONG:
      out = sizeof(long) == 8 ? Comp::UInt64 : Comp::UInt32;
      return true;
    case IOComp::LONGLONG:
      out = Comp::Int64;
      return true;
    case IOComp::ULONGLONG:
      out = Comp::UInt64;
      return true;
    case IOComp::FLOAT:
      out = Comp::Float32;
      return true;
    case IOComp::DOUBLE:
      out = Comp::Float64;
      return true;
    default:
      return false;
  }
}

IOComp toItk(Comp c) {
  switch (c) {
    case Comp::Int8:
      return IOComp::CHAR;
    case Comp::UInt8:
      return IOComp::UCHAR;
    case Comp::Int16:
      return IOComp::SHORT;
    case Comp::UInt16:
      return IOComp::USHORT;
    case Comp::Int32:
      return IOComp::INT;
    case Comp::UInt32:
      return IOComp::UINT;
    case Comp::Int64:
      return IOComp::LONGLONG;
    case Comp::UInt64:
      return IOComp::ULONGLONG;
    case Comp::Float32:
      return IOComp::FLOAT;
    case Comp::Float64:
      return IOComp::DOUBLE;
  }
  return IOComp::FLOAT;
}

// ITK prints warnings to stderr (e.g. about Analyze files); our readers report through
// ReadInfo notes and exceptions instead.
void quietItk() {
  static const bool once = [] {
    itk::Object::GlobalWarningDisplayOff();
    return true;
  }();
  (void)once;
}

itk::ImageIOBase::Pointer makeIO(ItkFormat f) {
  quietItk();
  switch (f) {
    case ItkFormat::Nifti:
      return itk::NiftiImageIO::New().GetPointer();
    case ItkFormat::Nrrd:
      return itk::NrrdImageIO::New().GetPointer();
    case ItkFormat::Meta:
      return itk::MetaImageIO::New().GetPointer();
    case ItkFormat::Png:
      return itk::PNGImageIO::New().GetPointer();
    case ItkFormat::Tiff:
      return itk::TIFFImageIO::New().GetPointer();
  }
  return nullptr;
}

void fillHeader(itk::ImageIOBase* io, const std::string& path, RawHeader& h) {
  const unsigned nd = io->GetNumberOfDimensions();
  if (nd < 2) throw IoError(path + ": image has " + std::to_string(nd) + " dimension(s), need 2 or 3");
  h.ndim = static_cast<int>(nd);
  for (unsigned i = 0; i < 3; ++i) {
    if (i < nd) {
      h.dims[i] = static_cast<int64_t>(io->GetDimensions(i));
      h.spacing[i] = io->GetSpacing(i);
      h.origin[i] = io->GetOrigin(i);
      const auto dir = io->GetDirection(i);
      for (unsigned r = 0; r < 3; ++r) h.direction[3 * r + i] = r < dir.size() ? dir[r] : (r == i ? 1.0 : 0.0);
    } else {
      h.dims[i] = 1;
      h.spacing[i] = 1;
      h.origin[i] = 0;
      for (unsigned r = 0; r < 3; ++r) h.direction[3 * r + i] = r == i ? 1.0 : 0.0;
    }
  }
  for (unsigned i = 3; i < nd; ++i)
    if (io->GetDimensions(i) > 1)
      h.notes.push_back("dimension " + std::to_string(i + 1) + " has " + std::to_string(io->GetDimensions(i)) +
                        " entries: only the first 3D volume was read");
  if (!toComp(io->GetComponentType(), h.comp))
    throw IoError(path + ": unsupported voxel type '" +
                  itk::ImageIOBase::GetComponentTypeAsString(io->GetComponentType()) + "'");
  h.ncomp = static_cast<int>(io->GetNumberOfComponents());
  if (h.ncomp < 1 || h.ncomp > 64)
    throw IoError(path + ": unsupported number of components per voxel (" + std::to_string(h.ncomp) + ")");
}

}  // namespace

void itkReadFile(ItkFormat fmt, const std::string& path, const Allocator& alloc, RawHeader& h) {
  try {
    itk::ImageIOBase::Pointer io = makeIO(fmt);
    if (!io->CanReadFile(path.c_str()))
      throw IoError(path + ": not a readable " + std::string(io->GetNameOfClass()) +
                    " file (wrong magic or corrupt header)");
    io->SetFileName(path);
    io->ReadImageInformation();
    fillHeader(io, path, h);
    if (h.sourceType.empty())
      h.sourceType = compName(h.comp) + (h.ncomp > 1 ? cat("x", std::to_string(h.ncomp)) : std::string());
    void* dest = alloc(h);
    const unsigned nd = io->GetNumberOfDimensions();
    // Volumes beyond the first 3D one (4D/5D files): NrrdImageIO and others ignore a smaller
    // IO region and fill the whole image, so read everything into a checked scratch buffer
    // and keep the first volume instead of letting the reader run past `dest`.
    uint64_t volumes = 1;
    for (unsigned i = 3; i < nd; ++i) volumes = checkedMul(volumes, io->GetDimensions(i), path, "image size");
    const uint64_t volumeBytes = checkedMul(
        checkedMul(checkedMul(static_cast<uint64_t>(h.dims[0]), static_cast<uint64_t>(h.dims[1]), path, "image size"),
                   static_cast<uint64_t>(h.dims[2]) * compSize(h.comp), path, "image size"),
        static_cast<uint64_t>(h.ncomp), path, "image size");
    itk::ImageIORegion region(nd);
    for (unsigned i = 0; i < nd; ++i) {
      region.SetIndex(i, 0);
      region.SetSize(i, io->GetDimensions(i));
    }
    io->SetIORegion(region);
    if (volumes == 1) {
      io->Read(dest);
    } else {
      const uint64_t all = checkedMul(volumeBytes, volumes, path, "image size");
      checkScratchBytes(all, path);
      std::vector<char> scratch(static_cast<size_t>(all));
      io->Read(scratch.data());
      std::memcpy(dest, scratch.data(), static_cast<size_t>(volumeBytes));
    }
  } catch (const itk::ExceptionObject& e) {
    throw IoError(path + ": " + flat(e.GetDescription()));
  }
}

void itkWriteFile(ItkFormat fmt, const std::string& path, const RawHeader& h, const void* data, bool compress) {
  try {
    itk::ImageIOBase::Pointer io = makeIO(fmt);
    io->SetNumberOfDimensions(3);
    for (unsigned i = 0; i < 3; ++i) {
      io->SetDimensions(i, static_cast<itk::SizeValueType>(h.dims[i]));
      io->SetSpacing(i, h.spacing[i]);
      io->SetOrigin(i, h.origin[i]);
      std::vector<double> col{h.direction[i], h.direction[3 + i], h.direction[6 + i]};
      io->SetDirection(i, col);
    }
    io->SetPixelType(itk::IOPixelEnum::SCALAR);
    io->SetNumberOfComponents(1);
    io->SetComponentType(toItk(h.comp));
    io->SetUseCompression(compress);
    io->SetFileName(path);
    itk::ImageIORegion region(3);
    for (unsigned i = 0; i < 3; ++i) {
      region.SetIndex(i, 0);
      region.SetSize(i, static_cast<itk::SizeValueType>(h.dims[i]));
    }
    io->SetIORegion(region);
    io->Write(data);  // writes the header too (an extra WriteImageInformation() leaks in nifticlib)
  } catch (const itk::ExceptionObject& e) {
    throw IoError(path + ": " + flat(e.GetDescription()));
  }
}

}  // namespace vs::io_detail
