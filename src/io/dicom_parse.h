// A small DICOM data-set parser of our own (internal to src/io): reads the top-level
// attributes a volume needs (geometry, pixel format, rescale, series, SOP class) and where
// the pixel data lies, in every uncompressed transfer syntax (implicit/explicit VR little
// endian, explicit big endian, deflated) and the encapsulated ones (header only; the
// compressed frames are decoded by GDCM). Every length is checked against the bytes present,
// sequences are skipped (nesting bounded), nothing is allocated from a header field. It lets
// the reader validate a file (SOP class, pixel data present, one frame, grey) *before* GDCM
// sees it: GDCM asserts (abort) on some valid non-image objects such as RTDOSE or DICOMDIR.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vs::io_detail {

struct DicomHeader {
  std::string file;
  std::string transferSyntax;  // (0002,0010); "" when the file has no meta header
  std::string sopClass;        // (0008,0016), else (0002,0002)
  std::string sopInstance;     // (0008,0018)
  std::string modality;        // (0008,0060)
  std::string seriesUid;       // (0020,000E)
  std::string photometric;     // (0028,0004)
  bool bigEndian = false, implicitVr = false, deflated = false, encapsulated = false;
  bool hasPixelData = false;  // (7FE0,0010) at the top level
  bool floatPixelData = false;
  bool enhanced = false;  // per-frame / shared functional groups present (enhanced multi-frame)
  bool isDicomdir = false;
  int rows = 0, cols = 0, bitsAllocated = 0, bitsStored = 0, highBit = -1, pixelRep = 0, samples = 1;
  int64_t frames = 1;
  bool hasIpp = false, hasIop = false, hasPixelSpacing = false, hasImagerSpacing = false;
  double ipp[3] = {0, 0, 0};
  double iop[6] = {1, 0, 0, 0, 1, 0};
  double pixelSpacing[2] = {1, 1};   // (0028,0030): between rows (y), between columns (x)
  double imagerSpacing[2] = {1, 1};  // (0018,1164)
  bool hasRescale = false;
  double slope = 1, intercept = 0;
  bool hasInstance = false;
  int64_t instanceNumber = 0;
  double sliceThickness = 0, spacingBetweenSlices = 0;  // 0 = absent
  uint64_t pixelOffset = 0, pixelLength = 0;            // in the (inflated, for deflate) data
};

// True if the first bytes look like DICOM: "DICM" at 128, or a data set without preamble
// starting with a group 0002/0008 element (pydicom's no_meta files).
bool looksLikeDicom(const std::string& path);

// Parses `path`. Throws IoError naming the file and the reason. `bytes`, when given, receives
// the bytes the offsets refer to (the whole file, or the inflated data set for deflate);
// without it only the header part of the file is read.
DicomHeader parseDicomHeader(const std::string& path, std::string* bytes = nullptr);

// Parses a buffer (the fuzz target and tests); `name` names it in messages.
DicomHeader parseDicomBuffer(const std::string& data, const std::string& name);

// "" when the object is an image we can read as a slice; otherwise the reason it is not
// (e.g. "RT Dose (SOP class 1.2.840.10008.5.1.4.1.1.481.2), not an image series").
std::string dicomNotAnImage(const DicomHeader& h);

}  // namespace vs::io_detail
