// ITK ImageIO classes used directly: no IO-factory registration is needed and single
// files need no pixel-type templates. The header is read first, the caller allocates
// (after checking the size), then the voxels are read straight into that buffer.
#include "io/itk_bridge.h"

#include <gdcmTrace.h>
#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkImageIOBase.h>
#include <itkMetaDataObject.h>
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

// GDCM prints its warnings and errors straight to std::cerr, as lines such as "Error: In
// .../gdcmJPEG2000Codec.cxx, line 745, function ..." that name no file, and the JPEG 2000
// decoder prints its own ("Tile part length size inconsistent with stream length") with C stdio
// on file descriptor 2. While a DICOM series is read both are collected here instead: a
// failure's IoError names the file and carries them, and on success they become ReadInfo notes
// ("DICOM reader: ..."). Reading is single-threaded and draws no progress, so swapping GDCM's
// global streams and descriptor 2 for the duration is safe; a line of our own that arrives
// meanwhile (the Ctrl-C handler's) is passed on to the real stderr afterwards.
class GdcmMessages {
 public:
  GdcmMessages()
      : debug_(gdcm::Trace::GetDebugStream()),
        warning_(gdcm::Trace::GetWarningStream()),
        error_(gdcm::Trace::GetErrorStream()) {
    gdcm::Trace::SetStream(buffer_);
    std::fflush(stderr);
    capture_ = std::tmpfile();
    savedFd_ = capture_ ? ::dup(STDERR_FILENO) : -1;
    if (savedFd_ >= 0) ::dup2(::fileno(capture_), STDERR_FILENO);
  }
  ~GdcmMessages() { finish(); }
  GdcmMessages(const GdcmMessages&) = delete;
  GdcmMessages& operator=(const GdcmMessages&) = delete;

  // The distinct message lines, without GDCM's source-location lines; at most `limit`.
  std::vector<std::string> lines(size_t limit = 5) {
    finish();
    std::vector<std::string> out;
    std::istringstream in(buffer_.str());
    std::string line;
    while (std::getline(in, line) && out.size() < limit) {
      line = oneLine(line);
      if (line.empty() || line.rfind("Error: In ", 0) == 0 || line.rfind("Warning: In ", 0) == 0 ||
          line.rfind("Debug: In ", 0) == 0 || line.rfind("volscissors", 0) == 0)
        continue;
      if (std::find(out.begin(), out.end(), line) == out.end()) out.push_back(line);
    }
    return out;
  }
  std::string detail() {
    std::string s;
    for (const auto& l : lines()) s += (s.empty() ? " (DICOM reader: " : "; ") + l;
    return s.empty() ? s : s + ")";
  }

 private:
  // Restores GDCM's streams and descriptor 2 (once) and appends what the descriptor received.
  void finish() {
    if (finished_) return;
    finished_ = true;
    gdcm::Trace::SetDebugStream(debug_);
    gdcm::Trace::SetWarningStream(warning_);
    gdcm::Trace::SetErrorStream(error_);
    if (savedFd_ >= 0) {
      std::fflush(stderr);
      ::dup2(savedFd_, STDERR_FILENO);
      ::close(savedFd_);
      std::rewind(capture_);
      std::string text;
      char chunk[4096];
      for (size_t n; (n = std::fread(chunk, 1, sizeof chunk, capture_)) > 0 && text.size() < (1u << 20);)
        text.append(chunk, n);
      std::istringstream in(text);
      for (std::string line; std::getline(in, line);)
        if (line.rfind("volscissors", 0) == 0) std::fprintf(stderr, "%s\n", line.c_str());
      buffer_ << text;
    }
    if (capture_) std::fclose(capture_);
  }

  std::ostream &debug_, &warning_, &error_;
  std::ostringstream buffer_;
  std::FILE* capture_ = nullptr;
  int savedFd_ = -1;
  bool finished_ = false;
};

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

std::string dicomTag(itk::GDCMImageIO* io, const char* key) {
  std::string v;
  itk::ExposeMetaData<std::string>(io->GetMetaDataDictionary(), key, v);
  while (!v.empty() && (v.back() == ' ' || v.back() == '\0')) v.pop_back();
  return v;
}

// GDCM reads a file whose uncompressed pixel data is cut short without complaint (the
// missing voxels become whatever the buffer held): the file must at least be as long as the
// pixel data it announces. Compressed transfer syntaxes are checked by their decoders.
void checkDicomPixelDataPresent(itk::GDCMImageIO* io, const std::string& file) {
  const std::string ts = dicomTag(io, "0002|0010");
  if (ts != "1.2.840.10008.1.2" && ts != "1.2.840.10008.1.2.1" && ts != "1.2.840.10008.1.2.2") return;
  const int bits = std::atoi(dicomTag(io, "0028|0100").c_str());
  if (bits <= 0) return;
  const uint64_t need = checkedMul(checkedMul(io->GetDimensions(0), io->GetDimensions(1), file, "pixel data size"),
                                   static_cast<uint64_t>(bits) * io->GetNumberOfComponents(), file, "pixel data size") /
                        8;
  std::error_code ec;
  const uint64_t have = std::filesystem::file_size(file, ec);
  if (!ec && have < need)
    throw IoError(file + ": truncated DICOM pixel data (file has " + std::to_string(have) + " bytes, the image needs " +
                  std::to_string(need) + ")");
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

bool itkIsDicomFile(const std::string& path) {
  GdcmMessages dropped;  // a probe: a file that is not DICOM is not worth a message
  try {
    auto io = itk::GDCMImageIO::New();
    return io->CanReadFile(path.c_str());
  } catch (const itk::ExceptionObject&) {
    return false;
  }
}

void itkReadDicom(const std::string& dir, const std::string& uid, const Allocator& alloc, RawHeader& h) {
  GdcmMessages gdcmMessages;
  std::string current = dir;  // the file being read, for messages
  try {
    quietItk();
    auto names = itk::GDCMSeriesFileNames::New();
    names->SetUseSeriesDetails(true);
    names->SetGlobalWarningDisplay(false);
    names->SetDirectory(dir);
    const std::vector<std::string> uids = names->GetSeriesUIDs();
    if (uids.empty()) throw IoError(dir + ": directory holds no readable DICOM series");
    std::string chosen;
    size_t best = 0;
    std::vector<std::pair<std::string, size_t>> all;
    for (const auto& u : uids) {
      const size_t n = names->GetFileNames(u).size();
      all.emplace_back(u, n);
      if (!uid.empty()) {
        if (u.rfind(uid, 0) == 0 && chosen.empty()) chosen = u, best = n;
      } else if (n > best) {
        best = n;
        chosen = u;
      }
    }
    if (chosen.empty()) throw IoError(dir + ": no DICOM series with UID '" + uid + "'");
    for (const auto& [u, n] : all)
      if (u != chosen) h.notes.push_back("other DICOM series in folder: " + u + " (" + std::to_string(n) + " files)");
    const std::vector<std::string> files = names->GetFileNames(chosen);
    if (files.empty()) throw IoError(dir + ": DICOM series " + chosen + " has no files");

    // Header from the first file.
    auto io = itk::GDCMImageIO::New();
    io->SetFileName(files.front());
    io->ReadImageInformation();
    if (io->GetNumberOfComponents() != 1) throw IoError(dir + ": colour DICOM series are not supported");
    if (io->GetNumberOfDimensions() > 2 && io->GetDimensions(2) > 1)
      throw IoError(dir + ": multi-frame DICOM files are not supported (" + files.front() + ")");
    fillHeader(io, files.front(), h);
    h.ndim = 3;
    h.dims[2] = static_cast<int64_t>(files.size());
    Comp internal;
    h.sourceType = toComp(io->GetInternalComponentType(), internal) ? compName(internal) : "?";
    h.rescaleSlope = io->GetRescaleSlope();
    h.rescaleIntercept = io->GetRescaleIntercept();
    h.notes.push_back("DICOM series " + chosen + " (" + std::to_string(files.size()) + " files)");

    // Slice normal and positions: the sorted order from GDCM follows the normal.
    const double* d = h.direction;
    const double n[3] = {d[1] * d[5] - d[2] * d[4], d[2] * d[3] - d[0] * d[5], d[0] * d[4] - d[1] * d[3]};
    std::vector<std::array<double, 3>> pos;
    pos.reserve(files.size());
    const size_t sliceBytes = static_cast<size_t>(
        checkedMul(checkedMul(static_cast<uint64_t>(h.dims[0]), static_cast<uint64_t>(h.dims[1]), dir, "slice size"),
                   compSize(h.comp), dir, "slice size"));
    // A few-byte file must not make us allocate gigabytes: the stored pixel data, even
    // deflate-compressed, cannot decode to more than kDeflateExpansion times the files' size.
    uint64_t stored = 0;
    for (const auto& f : files) {
      std::error_code ec;
      stored += static_cast<uint64_t>(std::filesystem::file_size(f, ec));
    }
    checkDataCanHold(checkedMul(sliceBytes, files.size(), dir, "series size"), stored, kDeflateExpansion, dir);
    // Allocate once the full size is known (checks happen in alloc).
    char* dest = static_cast<char*>(alloc(h));
    for (size_t k = 0; k < files.size(); ++k) {
      current = files[k];
      auto s = itk::GDCMImageIO::New();
      s->SetFileName(files[k]);
      s->ReadImageInformation();
      // Every file is checked, not only the first: a later multi-frame or colour file
      // would otherwise be read past its slot in the series buffer.
      if (s->GetNumberOfComponents() != 1)
        throw IoError(files[k] + ": colour DICOM slice in a grey series (not supported)");
      if (s->GetNumberOfDimensions() > 2 && s->GetDimensions(2) > 1)
        throw IoError(files[k] + ": multi-frame DICOM file inside a series (not supported)");
      if (static_cast<int64_t>(s->GetDimensions(0)) != h.dims[0] ||
          static_cast<int64_t>(s->GetDimensions(1)) != h.dims[1])
        throw IoError(files[k] + ": slice size differs from the rest of the series");
      if (s->GetComponentType() != io->GetComponentType())
        throw IoError(files[k] +
                      ": pixel type after rescale differs from the first slice (per-slice rescale is not supported)");
      checkDicomPixelDataPresent(s, files[k]);
      pos.push_back({s->GetOrigin(0), s->GetOrigin(1), s->GetOrigin(2)});
      itk::ImageIORegion region(2);
      region.SetIndex(0, 0);
      region.SetIndex(1, 0);
      region.SetSize(0, static_cast<itk::SizeValueType>(h.dims[0]));
      region.SetSize(1, static_cast<itk::SizeValueType>(h.dims[1]));
      s->SetIORegion(region);
      s->Read(dest + k * sliceBytes);
    }
    current = dir;
    for (const auto& line : gdcmMessages.lines()) h.notes.push_back("DICOM reader: " + line);
    h.origin[0] = pos[0][0];
    h.origin[1] = pos[0][1];
    h.origin[2] = pos[0][2];
    if (files.size() > 1) {
      auto proj = [&](const std::array<double, 3>& p) { return p[0] * n[0] + p[1] * n[1] + p[2] * n[2]; };
      const double span = proj(pos.back()) - proj(pos.front());
      const double step = span / static_cast<double>(files.size() - 1);
      double maxDev = 0;
      for (size_t k = 1; k < pos.size(); ++k)
        maxDev = std::max(maxDev, std::fabs(proj(pos[k]) - proj(pos[k - 1]) - step));
      if (std::fabs(step) < 1e-6) throw IoError(dir + ": all slices of the series are at the same position");
      h.spacing[2] = std::fabs(step);
      if (step < 0)  // slices ordered against the normal: flip the third direction column
        for (int r = 0; r < 3; ++r) h.direction[3 * r + 2] = -n[r];
      else
        for (int r = 0; r < 3; ++r) h.direction[3 * r + 2] = n[r];
      if (maxDev > 0.01 * std::fabs(step))
        h.notes.push_back("slice spacing is not uniform (deviation up to " + std::to_string(maxDev) +
                          " mm); mean step used");
    } else {
      for (int r = 0; r < 3; ++r) h.direction[3 * r + 2] = n[r];
    }
  } catch (const itk::ExceptionObject& e) {
    throw IoError((current == dir ? dir : current + " (series " + dir + ")") + ": " + flat(e.GetDescription()) +
                  gdcmMessages.detail());
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
