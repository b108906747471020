// DICOM series reading (see io_internal.h, readDicomVolume). Every file's header is parsed by
// our own parser (io/dicom_parse.h) and validated before GDCM sees it; GDCM only decodes the
// compressed pixel data of files already known to be single-frame grey images. Geometry is
// computed here from ImageOrientationPatient / ImagePositionPatient as pydicom users and
// dcm2niix do: direction columns = row cosine, column cosine, their cross product; in-plane
// spacing from PixelSpacing (row spacing = y); slice spacing from the positions.
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmPixelFormat.h>
#include <gdcmTrace.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/dicom_parse.h"
#include "io/io_internal.h"
#include "util/cancel.h"

namespace fs = std::filesystem;

namespace vs::io_detail {

namespace {

// GDCM prints its warnings and errors straight to std::cerr, and the JPEG 2000 decoder prints
// its own with C stdio on descriptor 2. While GDCM decodes both are collected here instead:
// a failure's IoError carries them, and on success they become ReadInfo notes. Decoding is
// single-threaded, so swapping GDCM's streams and descriptor 2 for the duration is safe; a
// line of our own that arrives meanwhile (the Ctrl-C handler's) is passed on afterwards.
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
    for (const auto& l : lines()) s += (s.empty() ? " (DICOM decoder: " : "; ") + l;
    return s.empty() ? s : s + ")";
  }

 private:
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

std::string fmtNum(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

struct PixelFormat {
  int bitsAllocated = 16, bitsStored = 16, highBit = 15, pixelRep = 0;
  bool bigEndian = false;
};

// Stored values (masked to BitsStored, sign-extended for PixelRepresentation 1) of `n`
// pixels at `src`, rescaled into `out`.
void storedToFloat(const unsigned char* src, size_t n, const PixelFormat& f, double slope, double inter, float* out) {
  if (f.bitsAllocated == 1) {
    for (size_t i = 0; i < n; ++i) out[i] = static_cast<float>(((src[i >> 3] >> (i & 7)) & 1) * slope + inter);
    return;
  }
  const int bytes = f.bitsAllocated / 8;
  const int shift = std::max(0, f.highBit + 1 - f.bitsStored);
  const uint64_t mask = f.bitsStored >= 32 ? 0xFFFFFFFFull : ((uint64_t{1} << f.bitsStored) - 1);
  const uint64_t sign = uint64_t{1} << (f.bitsStored - 1);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char* p = src + i * static_cast<size_t>(bytes);
    uint64_t u = 0;
    for (int b = 0; b < bytes; ++b) u |= uint64_t{p[f.bigEndian ? bytes - 1 - b : b]} << (8 * b);
    u = (u >> shift) & mask;
    const double v = (f.pixelRep == 1 && (u & sign))
                         ? static_cast<double>(static_cast<int64_t>(u) - static_cast<int64_t>(mask) - 1)
                         : static_cast<double>(u);
    out[i] = static_cast<float>(v * slope + inter);
  }
}

uint64_t storedBytes(const DicomHeader& h) {
  const uint64_t n = static_cast<uint64_t>(h.rows) * static_cast<uint64_t>(h.cols);
  return h.bitsAllocated == 1 ? (n + 7) / 8 : n * static_cast<uint64_t>(h.bitsAllocated / 8);
}

// "" if the header describes a grey single-frame slice we can read, else why not.
std::string unreadable(DicomHeader& h) {
  std::string why = dicomNotAnImage(h);
  if (!why.empty()) return why;
  if (h.enhanced) return "an enhanced multi-frame object (per-frame geometry in functional groups; not supported)";
  if (h.frames > 1) return "a multi-frame file (" + std::to_string(h.frames) + " frames; not supported)";
  if (h.frames < 1) return "NumberOfFrames " + std::to_string(h.frames) + " is invalid";
  if (h.samples != 1)
    return "a colour image (" + std::to_string(h.samples) + " samples per pixel, " + h.photometric +
           "; colour DICOM is not supported)";
  if (!h.photometric.empty() && h.photometric != "MONOCHROME1" && h.photometric != "MONOCHROME2")
    return "photometric interpretation " + h.photometric + " is not supported (grey images only)";
  if (h.rows < 1 || h.cols < 1)
    return "image size " + std::to_string(h.cols) + "x" + std::to_string(h.rows) + " is invalid";
  if (h.bitsAllocated != 1 && h.bitsAllocated != 8 && h.bitsAllocated != 16 && h.bitsAllocated != 32)
    return "BitsAllocated " + std::to_string(h.bitsAllocated) + " is not supported";
  if (h.bitsStored <= 0) h.bitsStored = h.bitsAllocated;
  if (h.bitsStored > h.bitsAllocated)
    return "BitsStored " + std::to_string(h.bitsStored) + " exceeds BitsAllocated " + std::to_string(h.bitsAllocated);
  if (h.highBit < 0 || h.highBit >= h.bitsAllocated || h.highBit + 1 < h.bitsStored) h.highBit = h.bitsStored - 1;
  if (h.pixelRep != 0 && h.pixelRep != 1) return "PixelRepresentation " + std::to_string(h.pixelRep) + " is invalid";
  if (!std::isfinite(h.slope) || !std::isfinite(h.intercept) || h.slope == 0)
    return "RescaleSlope " + fmtNum(h.slope) + " / RescaleIntercept " + fmtNum(h.intercept) + " is invalid";
  if (h.hasPixelSpacing && !(h.pixelSpacing[0] > 0 && h.pixelSpacing[1] > 0))
    return "PixelSpacing " + fmtNum(h.pixelSpacing[0]) + "\\" + fmtNum(h.pixelSpacing[1]) + " is not positive";
  if (!h.encapsulated && h.pixelLength < storedBytes(h))
    return "truncated pixel data (" + std::to_string(h.pixelLength) + " bytes, the image needs " +
           std::to_string(storedBytes(h)) + ")";
  if (h.hasIop) {
    const Vec3 r(h.iop[0], h.iop[1], h.iop[2]), c(h.iop[3], h.iop[4], h.iop[5]);
    if (std::fabs(r.norm() - 1) > 0.01 || std::fabs(c.norm() - 1) > 0.01 || std::fabs(r.dot(c)) > 0.01)
      return "ImageOrientationPatient is not two orthonormal vectors";
  }
  return "";
}

// Reads one slice's rescaled values into `out` (rows*cols floats).
void readSlice(const DicomHeader& h, float* out, std::vector<std::string>& decoderNotes) {
  const size_t n = static_cast<size_t>(h.rows) * static_cast<size_t>(h.cols);
  PixelFormat f{h.bitsAllocated, h.bitsStored, h.highBit, h.pixelRep, h.bigEndian};
  if (!h.encapsulated) {
    const uint64_t need = storedBytes(h);
    std::string bytes;
    if (h.deflated) {
      std::string all;
      const DicomHeader again = parseDicomHeader(h.file, &all);
      if (again.pixelOffset + need > all.size()) throw IoError(h.file + ": truncated DICOM pixel data");
      bytes = all.substr(static_cast<size_t>(again.pixelOffset), static_cast<size_t>(need));
    } else {
      std::ifstream in(h.file, std::ios::binary);
      in.seekg(static_cast<std::streamoff>(h.pixelOffset));
      bytes.resize(static_cast<size_t>(need));
      in.read(bytes.data(), static_cast<std::streamsize>(need));
      if (!in || static_cast<uint64_t>(in.gcount()) != need)
        throw IoError(h.file + ": truncated DICOM pixel data (the image needs " + std::to_string(need) +
                      " bytes after byte " + std::to_string(h.pixelOffset) + ")");
    }
    storedToFloat(reinterpret_cast<const unsigned char*>(bytes.data()), n, f, h.slope, h.intercept, out);
    return;
  }
  // Compressed: GDCM decodes (the header was validated above: a single-frame grey image).
  GdcmMessages messages;
  try {
    gdcm::ImageReader reader;
    reader.SetFileName(h.file.c_str());
    if (!reader.Read()) throw IoError(h.file + ": the DICOM decoder cannot read this file" + messages.detail());
    const gdcm::Image& img = reader.GetImage();
    const gdcm::PixelFormat& pf = img.GetPixelFormat();
    const unsigned* d = img.GetDimensions();
    if (img.GetNumberOfDimensions() < 2 || d[0] != static_cast<unsigned>(h.cols) ||
        d[1] != static_cast<unsigned>(h.rows) || pf.GetSamplesPerPixel() != 1)
      throw IoError(h.file + ": the decoded image does not match its header (size or samples per pixel)");
    const unsigned long len = img.GetBufferLength();
    f.bitsAllocated = pf.GetBitsAllocated();
    f.bitsStored = pf.GetBitsStored();
    f.highBit = pf.GetHighBit();
    f.pixelRep = pf.GetPixelRepresentation();
    f.bigEndian = false;
    if ((f.bitsAllocated != 8 && f.bitsAllocated != 16 && f.bitsAllocated != 32) || f.bitsStored < 1 ||
        f.bitsStored > f.bitsAllocated)
      throw IoError(h.file + ": decoded pixel format is not supported");
    if (f.highBit + 1 < f.bitsStored || f.highBit >= f.bitsAllocated) f.highBit = f.bitsStored - 1;
    if (len < n * static_cast<size_t>(f.bitsAllocated / 8))
      throw IoError(h.file + ": the decoded image is shorter than its header says" + messages.detail());
    std::vector<char> buf(len);
    if (!img.GetBuffer(buf.data())) throw IoError(h.file + ": cannot decode the pixel data" + messages.detail());
    storedToFloat(reinterpret_cast<const unsigned char*>(buf.data()), n, f, h.slope, h.intercept, out);
    for (const auto& l : messages.lines())
      if (std::find(decoderNotes.begin(), decoderNotes.end(), l) == decoderNotes.end()) decoderNotes.push_back(l);
  } catch (const std::exception& e) {
    if (dynamic_cast<const IoError*>(&e)) throw;
    throw IoError(h.file + ": DICOM decoder failed: " + oneLine(e.what()) + messages.detail());
  }
}

Vec3 rowCos(const DicomHeader& h) { return Vec3(h.iop[0], h.iop[1], h.iop[2]).normalized(); }
Vec3 colCos(const DicomHeader& h) { return Vec3(h.iop[3], h.iop[4], h.iop[5]).normalized(); }

std::string groupKey(const DicomHeader& h) {
  // One volume = one series, one orientation, one slice size and one pixel format.
  const std::string format = "|" + std::to_string(h.bitsAllocated) + (h.pixelRep ? "s" : "u") + h.photometric;
  char b[160];
  if (h.hasIop) {
    const Vec3 r = rowCos(h), c = colCos(h);
    std::snprintf(b, sizeof b, "|%.3f,%.3f,%.3f,%.3f,%.3f,%.3f|%dx%d", r[0] + 0.0, r[1] + 0.0, r[2] + 0.0, c[0] + 0.0,
                  c[1] + 0.0, c[2] + 0.0, h.cols, h.rows);
  } else {
    std::snprintf(b, sizeof b, "|no-orientation|%dx%d", h.cols, h.rows);
  }
  return h.seriesUid + b + format;
}

std::string orientationWord(const DicomHeader& h) {
  if (!h.hasIop) return "no orientation";
  const Vec3 n = rowCos(h).cross(colCos(h));
  const int a = n.cwiseAbs().maxCoeff() == std::fabs(n[2]) ? 2 : (n.cwiseAbs().maxCoeff() == std::fabs(n[1]) ? 1 : 0);
  const char* names[3] = {"sagittal", "coronal", "axial"};
  const bool oblique = n.cwiseAbs().maxCoeff() < 0.9999;
  return std::string(oblique ? "oblique " : "") + names[a];
}

// The series name of files without SeriesInstanceUID (also what --series matches for them).
const char* const kNoSeriesUid = "no-SeriesInstanceUID";

struct Group {
  std::string key;
  std::vector<DicomHeader> slices;
};

// In-plane shift of every slice so that a gantry-tilted (sheared) stack lies on an
// orthogonal grid anchored at the first slice, as dcm2niix does: bilinear, outside = `fill`.
void shiftSlice(float* s, int64_t nx, int64_t ny, double dx, double dy, float fill, std::vector<float>& tmp) {
  tmp.assign(s, s + nx * ny);
  for (int64_t y = 0; y < ny; ++y)
    for (int64_t x = 0; x < nx; ++x) {
      const double fx = static_cast<double>(x) + dx, fy = static_cast<double>(y) + dy;
      const double x0 = std::floor(fx), y0 = std::floor(fy);
      const double ax = fx - x0, ay = fy - y0;
      double acc = 0, wsum = 0;
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
          const int64_t xi = static_cast<int64_t>(x0) + i, yi = static_cast<int64_t>(y0) + j;
          const double w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
          if (w <= 0) continue;
          const float v = (xi >= 0 && yi >= 0 && xi < nx && yi < ny) ? tmp[static_cast<size_t>(yi * nx + xi)] : fill;
          acc += w * v;
          wsum += w;
        }
      s[y * nx + x] = static_cast<float>(wsum > 0 ? acc / wsum : fill);
    }
}

}  // namespace

namespace {

// Every file's header in a folder (not recursively), validated, grouped into stackable series;
// the named file (if any) is taken as already parsed.
struct FolderScan {
  std::map<std::string, Group> groups;
  std::vector<std::string> skippedNonImage, skippedBad;
};

FolderScan scanFolder(const std::string& dir, const std::string& named, DicomHeader& namedHeader, Progress& progress) {
  std::error_code ec;
  std::vector<std::string> files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (fs::is_regular_file(it->path(), ec)) files.push_back(it->path().string());
  if (ec && files.empty()) throw IoError(dir + ": cannot list the folder: " + ec.message());
  std::sort(files.begin(), files.end());
  FolderScan scan;
  auto& groups = scan.groups;
  auto& skippedNonImage = scan.skippedNonImage;
  auto& skippedBad = scan.skippedBad;
  size_t scanned = 0;
  for (const auto& f : files) {
    if (++scanned % 64 == 0) progress.check();
    if (globalCancelRequested()) throw Cancelled();
    if (!named.empty() && fs::equivalent(f, named, ec)) {
      const std::string key = groupKey(namedHeader);
      groups[key].key = key;
      namedHeader.file = f;
      groups[key].slices.push_back(namedHeader);
      continue;
    }
    if (!looksLikeDicom(f)) continue;
    DicomHeader h;
    try {
      h = parseDicomHeader(f);
    } catch (const IoError& e) {
      skippedBad.push_back(oneLine(e.what()));
      continue;
    }
    if (h.seriesUid.empty()) h.seriesUid = kNoSeriesUid;  // anonymised files: one group per orientation/size
    const std::string why = unreadable(h);
    if (!why.empty()) {
      (dicomNotAnImage(h).empty() ? skippedBad : skippedNonImage)
          .push_back(fs::path(f).filename().string() + ": " + why);
      continue;
    }
    const std::string key = groupKey(h);
    groups[key].key = key;
    groups[key].slices.push_back(std::move(h));
  }
  return scan;
}

std::string listSome(const std::vector<std::string>& v) {
  std::string s;
  for (size_t i = 0; i < v.size() && i < 3; ++i) s += (i ? "; " : "") + v[i];
  if (v.size() > 3) s += "; and " + std::to_string(v.size() - 3) + " more";
  return s;
}

// Copies of one image (same SOPInstanceUID, e.g. one slice saved in several transfer
// syntaxes) count once: the named file, else the first by name.
std::vector<DicomHeader> uniqueSlices(const Group& chosen, const std::string& named, const DicomHeader& namedHeader,
                                      ReadInfo& info) {
  std::vector<DicomHeader> slices;
  {
    std::map<std::string, size_t> byInstance;
    size_t copies = 0;
    for (const auto& s : chosen.slices) {
      if (s.sopInstance.empty()) {
        slices.push_back(s);
        continue;
      }
      auto [it, fresh] = byInstance.emplace(s.sopInstance, slices.size());
      if (fresh) {
        slices.push_back(s);
      } else {
        ++copies;
        if (!named.empty() && s.file == namedHeader.file) slices[it->second] = s;
      }
    }
    if (copies > 0)
      info.notes.push_back(std::to_string(copies) +
                           " file(s) are copies of another slice (same SOPInstanceUID): " + "each image read once");
  }
  return slices;
}

// The stack's geometry: slices ordered along the normal (positions), else by InstanceNumber, else
// by name; spacing, origin and direction; the in-plane shift of each slice of a tilted stack.
struct Stack {
  Mat3 dir3 = Mat3::Identity();
  Vec3 spacing{1, 1, 1}, origin{0, 0, 0};
  std::vector<Vec3> shift;  // in-plane offset in voxels
  bool tilted = false;
};

Stack orderStack(const DicomHeader& first, std::vector<DicomHeader>& slices, const std::string& dir,
                 const std::string& named, ReadInfo& info) {
  Stack st;
  Mat3& dir3 = st.dir3;
  Vec3 &spacing = st.spacing, &origin = st.origin;
  const int64_t nz = static_cast<int64_t>(slices.size());
  bool allPos = true;
  for (const auto& s : slices) allPos = allPos && s.hasIpp && s.hasIop;
  Vec3 n(0, 0, 1);
  if (first.hasIop) {
    const Vec3 r = rowCos(first), c = colCos(first);
    n = r.cross(c).normalized();  // the normal from the direction matrix's columns
    dir3.col(0) = r;
    dir3.col(1) = c;
    dir3.col(2) = n;
  } else {
    info.notes.push_back("no ImageOrientationPatient: identity direction assumed");
  }
  if (first.hasPixelSpacing) {
    spacing[0] = first.pixelSpacing[1];  // between columns (along a row)
    spacing[1] = first.pixelSpacing[0];  // between rows
  } else if (first.hasImagerSpacing && first.imagerSpacing[0] > 0 && first.imagerSpacing[1] > 0) {
    spacing[0] = first.imagerSpacing[1];
    spacing[1] = first.imagerSpacing[0];
    info.notes.push_back("no PixelSpacing: ImagerPixelSpacing (at the detector) used");
  } else {
    info.notes.push_back("no PixelSpacing: 1 mm assumed in-plane");
  }
  auto proj = [&](const DicomHeader& s) { return Vec3(s.ipp[0], s.ipp[1], s.ipp[2]).dot(n); };
  if (allPos) {
    std::stable_sort(slices.begin(), slices.end(),
                     [&](const DicomHeader& a, const DicomHeader& b) { return proj(a) < proj(b); });
  } else if (nz > 1) {
    bool allInst = true;
    for (const auto& s : slices) allInst = allInst && s.hasInstance;
    if (allInst)
      std::stable_sort(slices.begin(), slices.end(),
                       [](const DicomHeader& a, const DicomHeader& b) { return a.instanceNumber < b.instanceNumber; });
    info.notes.push_back(std::string("slices have no ImagePositionPatient/ImageOrientationPatient: ordered by ") +
                         (allInst ? "InstanceNumber" : "file name"));
  }
  if (first.hasIpp)
    origin = Vec3(slices.front().ipp[0], slices.front().ipp[1], slices.front().ipp[2]);
  else
    info.notes.push_back("no ImagePositionPatient: origin 0 assumed");

  // Slice step and gantry tilt (in-plane offsets of the slices) from the positions.
  std::vector<Vec3>& shift = st.shift;
  shift.assign(static_cast<size_t>(nz), Vec3::Zero());
  bool& tilted = st.tilted;
  if (nz > 1 && allPos) {
    const double span = proj(slices.back()) - proj(slices.front());
    const double step = span / static_cast<double>(nz - 1);
    for (size_t k = 1; k < slices.size(); ++k)
      if (proj(slices[k]) - proj(slices[k - 1]) < 1e-4 * std::max(1.0, std::fabs(step)))
        throw IoError(dir + ": " + slices[k - 1].file + " and " + slices[k].file + " of series " + first.seriesUid +
                      " lie at the same position (several acquisitions, echoes or phases in one series?); "
                      "not a single volume");
    double maxDev = 0;
    for (size_t k = 1; k < slices.size(); ++k)
      maxDev = std::max(maxDev, std::fabs(proj(slices[k]) - proj(slices[k - 1]) - step));
    spacing[2] = step;
    if (maxDev > 0.1 * step) {
      double lo = 1e300, hi = 0;
      for (size_t k = 1; k < slices.size(); ++k) {
        const double d = proj(slices[k]) - proj(slices[k - 1]);
        lo = std::min(lo, d), hi = std::max(hi, d);
      }
      throw IoError((named.empty() ? dir : named) + ": the " + std::to_string(nz) + " slices of series " +
                    first.seriesUid + " are unevenly spaced (steps from " + fmtNum(lo) + " to " + fmtNum(hi) +
                    " mm: missing slices, or several stacks in one series?), not one regular volume");
    }
    if (maxDev > 0.01 * step)
      info.notes.push_back("slice spacing is not uniform (deviation up to " + fmtNum(maxDev) +
                           " mm, a missing slice?); mean step " + fmtNum(step) + " mm used");
    const Vec3 p0(slices.front().ipp[0], slices.front().ipp[1], slices.front().ipp[2]);
    double maxShift = 0;
    for (size_t k = 0; k < slices.size(); ++k) {
      const Vec3 d = Vec3(slices[k].ipp[0], slices[k].ipp[1], slices[k].ipp[2]) - p0;
      const Vec3 inPlane = d - d.dot(n) * n;
      shift[k] = Vec3(inPlane.dot(dir3.col(0)) / spacing[0], inPlane.dot(dir3.col(1)) / spacing[1], 0);
      maxShift = std::max(maxShift, shift[k].norm());
    }
    if (maxShift > 0.01) {
      tilted = true;
      const Vec3 last = Vec3(slices.back().ipp[0], slices.back().ipp[1], slices.back().ipp[2]) - p0;
      const double angle = std::acos(std::min(1.0, std::fabs(last.dot(n)) / last.norm())) * 180.0 / M_PI;
      info.notes.push_back("gantry tilt / sheared stack (" + fmtNum(angle) +
                           " degrees): slices shifted in-plane onto an orthogonal grid (bilinear, as dcm2niix does)");
    }
  } else if (nz == 1 || !allPos) {
    if (first.spacingBetweenSlices > 0)
      spacing[2] = first.spacingBetweenSlices;
    else if (first.sliceThickness > 0)
      spacing[2] = first.sliceThickness;
    if (nz > 1)
      info.notes.push_back("slice spacing " + fmtNum(spacing[2]) + " mm from " +
                           (first.spacingBetweenSlices > 0 ? "SpacingBetweenSlices" : "SliceThickness or 1 mm"));
  }
  return st;
}

// The stored pixel type as the read report names it, and the rescale's notes.
std::string storedType(const DicomHeader& first, bool sameRescale, ReadInfo& info) {
  std::string stored = first.bitsAllocated == 1
                           ? std::string("bit1")
                           : std::string(first.pixelRep ? "int" : "uint") + std::to_string(first.bitsAllocated);
  if (first.bitsStored < first.bitsAllocated && first.bitsAllocated > 1)
    stored += " (" + std::to_string(first.bitsStored) + " bits stored)";
  if (!sameRescale) {
    stored += "*(per-slice rescale)";
    info.notes.push_back("DICOM rescale applied per slice (slopes/intercepts differ between slices)");
  } else if (first.slope != 1 || first.intercept != 0) {
    stored += cat("*", fmtNum(first.slope), first.intercept < 0 ? "" : "+", fmtNum(first.intercept));
    info.notes.push_back(cat("DICOM rescale applied: value = ", fmtNum(first.slope), " * stored ",
                             first.intercept < 0 ? "- " : "+ ", fmtNum(std::fabs(first.intercept))));
  }
  if (first.photometric == "MONOCHROME1")
    info.notes.push_back("MONOCHROME1 (viewers show high values dark): values kept as rescaled, not inverted");
  return stored;
}

}  // namespace

AnyVolume readDicomVolume(const std::string& path, const ReadOptions& opt, ReadInfo& info, Progress& progress) {
  std::error_code ec;
  const bool isDir = fs::is_directory(path, ec);
  std::string named;  // the file the user named, if any
  DicomHeader namedHeader;
  std::string dir = path;
  if (!isDir) {
    if (!looksLikeDicom(path)) throw IoError(path + ": unknown format (not a DICOM file and no known extension)");
    namedHeader = parseDicomHeader(path);
    if (namedHeader.seriesUid.empty()) namedHeader.seriesUid = kNoSeriesUid;
    std::string why = unreadable(namedHeader);
    if (!why.empty()) throw IoError(path + ": cannot read as a volume: " + why);
    named = path;
    const fs::path parent = fs::path(path).parent_path();
    dir = parent.empty() ? std::string(".") : parent.string();
  }

  // Scan the folder (not recursively): every file's header, validated.
  FolderScan scan = scanFolder(dir, named, namedHeader, progress);
  const auto& groups = scan.groups;
  const auto& skippedNonImage = scan.skippedNonImage;
  const auto& skippedBad = scan.skippedBad;
  if (groups.empty()) {
    if (!skippedNonImage.empty() || !skippedBad.empty())
      throw IoError(dir + ": no readable DICOM image series (" +
                    listSome(skippedNonImage.empty() ? skippedBad : skippedNonImage) + ")");
    throw IoError(dir + ": directory holds no readable DICOM series");
  }

  // Choose the group: the named file's, else the series the user picked, else the largest.
  const Group* chosen = nullptr;
  if (!named.empty()) {
    chosen = &groups.at(groupKey(namedHeader));
  } else {
    for (const auto& [k, g] : groups) {
      if (!opt.dicomSeriesUid.empty() && g.slices.front().seriesUid.rfind(opt.dicomSeriesUid, 0) != 0) continue;
      if (!chosen || g.slices.size() > chosen->slices.size()) chosen = &g;
    }
    if (!chosen) throw IoError(dir + ": no DICOM series with UID '" + opt.dicomSeriesUid + "'");
  }
  const DicomHeader& first = chosen->slices.front();
  for (const auto& [k, g] : groups) {
    if (&g == chosen) continue;
    const DicomHeader& o = g.slices.front();
    if (o.seriesUid == first.seriesUid)
      info.notes.push_back("series " + o.seriesUid + " also holds " + std::to_string(g.slices.size()) + " " +
                           orientationWord(o) + " slice(s) of another orientation or size, not stacked with these (" +
                           "name one of them to read them, e.g. " + o.file + ")");
    else
      info.notes.push_back("other DICOM series in folder: " + o.seriesUid + " (" + std::to_string(g.slices.size()) +
                           " files)");
  }
  if (!skippedNonImage.empty())
    info.notes.push_back("skipped " + std::to_string(skippedNonImage.size()) +
                         " non-image DICOM object(s): " + listSome(skippedNonImage));
  if (!skippedBad.empty())
    info.notes.push_back("skipped " + std::to_string(skippedBad.size()) +
                         " unreadable DICOM file(s): " + listSome(skippedBad));

  // Copies of one image (same SOPInstanceUID, e.g. one slice saved in several transfer
  // syntaxes) count once: the named file, else the first by name.
  std::vector<DicomHeader> slices = uniqueSlices(*chosen, named, namedHeader, info);
  const int64_t nx = first.cols, ny = first.rows, nz = static_cast<int64_t>(slices.size());
  const Stack st = orderStack(first, slices, dir, named, info);
  const Mat3& dir3 = st.dir3;
  const Vec3 &spacing = st.spacing, &origin = st.origin;
  const std::vector<Vec3>& shift = st.shift;
  const bool tilted = st.tilted;

  // Consistent pixel format across the slices (rescale may differ per slice).
  bool integral = true, sameRescale = true;
  for (const auto& s : slices) {
    if (s.bitsAllocated != first.bitsAllocated || s.pixelRep != first.pixelRep || s.photometric != first.photometric)
      throw IoError(s.file + ": pixel format or photometric interpretation differs from " + first.file +
                    " in the same series");
    integral = integral && s.slope == std::nearbyint(s.slope) && s.intercept == std::nearbyint(s.intercept);
    sameRescale = sameRescale && s.slope == first.slope && s.intercept == first.intercept;
  }

  Geometry g;
  g.dims = {nx, ny, nz};
  g.spacing = spacing;
  g.origin = origin;
  g.direction = dir3;
  checkAllocation(g.dims, sizeof(float), dir);
  uint64_t onDisk = 0;
  for (const auto& s : slices) onDisk += static_cast<uint64_t>(fs::file_size(s.file, ec));
  checkDataCanHold(checkedMul(storedBytes(first), static_cast<uint64_t>(nz), dir, "series size"), onDisk,
                   kDeflateExpansion, dir);
  VolumeF32 vol(g);
  std::vector<std::string> decoderNotes;
  for (int64_t k = 0; k < nz; ++k) {
    progress.check();
    if (globalCancelRequested()) throw Cancelled();
    readSlice(slices[static_cast<size_t>(k)], vol.data() + k * nx * ny, decoderNotes);
  }
  if (tilted) {
    float fill = std::numeric_limits<float>::max();
    for (float v : vol.voxels()) fill = std::min(fill, v);
    std::vector<float> tmp;
    for (int64_t k = 1; k < nz; ++k) {
      progress.check();
      // Output voxel (i, j) of slice k lies at pixel (i, j) - offset of that slice's own grid.
      shiftSlice(vol.data() + k * nx * ny, nx, ny, -shift[static_cast<size_t>(k)][0], -shift[static_cast<size_t>(k)][1],
                 fill, tmp);
      if (integral)
        for (int64_t i = 0; i < nx * ny; ++i) vol.data()[k * nx * ny + i] = std::nearbyint(vol.data()[k * nx * ny + i]);
    }
  }
  for (const auto& l : decoderNotes) info.notes.push_back("DICOM decoder: " + l);

  info.notes.insert(info.notes.begin(), "DICOM series " + first.seriesUid + " (" + std::to_string(nz) + " " +
                                            orientationWord(first) + " slice(s)" +
                                            (named.empty() ? std::string() : ", the series of " + named) + ")");
  info.sourceType = storedType(first, sameRescale, info);
  AnyVolume out = std::move(vol);
  if (integral) out = narrowIntegral(std::move(out), info);
  return out;
}

}  // namespace vs::io_detail
