#include "io/dicom_parse.h"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "io/io_comp.h"
#include "util/error.h"

namespace vs::io_detail {

namespace {

constexpr uint32_t kUndefined = 0xFFFFFFFFu;
constexpr int kMaxDepth = 32;

const char* const kLongVrs[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "UC", "UN", "UR", "UT", "SV", "UV"};

bool isVr(const char* p) { return p[0] >= 'A' && p[0] <= 'Z' && p[1] >= 'A' && p[1] <= 'Z'; }

bool longVr(const char* p) {
  for (const char* v : kLongVrs)
    if (p[0] == v[0] && p[1] == v[1]) return true;
  return false;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  size_t b = 0;
  while (b < s.size() && s[b] == ' ') ++b;
  return s.substr(b);
}

// Backslash-separated decimal strings; false unless exactly `n` finite numbers.
bool parseDs(const std::string& v, double* out, int n) {
  std::string s = v;
  int k = 0;
  size_t pos = 0;
  while (k < n) {
    const size_t e = s.find('\\', pos);
    const std::string part = trim(s.substr(pos, e == std::string::npos ? std::string::npos : e - pos));
    if (part.empty()) return false;
    char* end = nullptr;
    const double d = std::strtod(part.c_str(), &end);
    if (end == part.c_str() || *end != '\0' || !std::isfinite(d)) return false;
    out[k++] = d;
    if (e == std::string::npos) break;
    pos = e + 1;
  }
  return k == n;
}

class Parser {
 public:
  Parser(const std::string& d, const std::string& name, DicomHeader& h) : d_(d), name_(name), h_(h) {}

  [[noreturn]] void fail(const std::string& why) const { throw IoError(name_ + ": corrupt DICOM: " + why); }

  uint16_t u16(uint64_t at, bool be) const {
    if (at + 2 > d_.size()) fail("element runs past the end of the file");
    const auto* p = reinterpret_cast<const unsigned char*>(d_.data() + at);
    return be ? static_cast<uint16_t>(p[0] << 8 | p[1]) : static_cast<uint16_t>(p[1] << 8 | p[0]);
  }
  uint32_t u32(uint64_t at, bool be) const {
    if (at + 4 > d_.size()) fail("element runs past the end of the file");
    const auto* p = reinterpret_cast<const unsigned char*>(d_.data() + at);
    return be ? (uint32_t{p[0]} << 24 | uint32_t{p[1]} << 16 | uint32_t{p[2]} << 8 | p[3])
              : (uint32_t{p[3]} << 24 | uint32_t{p[2]} << 16 | uint32_t{p[1]} << 8 | p[0]);
  }

  struct Elem {
    uint16_t group = 0, element = 0;
    char vr[3] = {0, 0, 0};
    uint32_t length = 0;
    uint64_t value = 0;  // offset of the value
  };

  // Reads one element header at `at`.
  Elem header(uint64_t at, bool implicit, bool be) const {
    Elem e;
    e.group = u16(at, be);
    e.element = u16(at + 2, be);
    if (e.group == 0xFFFE) {  // item / delimiters: always tag + 4-byte length
      e.length = u32(at + 4, be);
      e.value = at + 8;
      return e;
    }
    if (implicit) {
      e.length = u32(at + 4, be);
      e.value = at + 8;
      return e;
    }
    if (at + 6 > d_.size()) fail("element runs past the end of the file");
    const char* vr = d_.data() + at + 4;
    if (!isVr(vr)) fail("invalid value representation at byte " + std::to_string(at + 4));
    e.vr[0] = vr[0];
    e.vr[1] = vr[1];
    if (longVr(vr)) {
      e.length = u32(at + 8, be);
      e.value = at + 12;
    } else {
      e.length = u16(at + 6, be);
      e.value = at + 8;
    }
    return e;
  }

  // Skips an undefined-length sequence or item list starting at `at` (after the element
  // header); returns the offset after its delimiter.
  uint64_t skipUndefined(uint64_t at, bool implicit, bool be, int depth) const {
    if (depth > kMaxDepth) fail("sequences nested too deeply");
    while (true) {
      if (at + 8 > d_.size()) fail("sequence without end");
      const uint16_t g = u16(at, be), el = u16(at + 2, be);
      const uint32_t len = u32(at + 4, be);
      if (g == 0xFFFE && el == 0xE0DD) return at + 8;  // sequence delimiter
      if (g != 0xFFFE || el != 0xE000) fail("malformed sequence item at byte " + std::to_string(at));
      at += 8;
      if (len == kUndefined) {
        at = skipItemElements(at, implicit, be, depth + 1);
      } else {
        if (at + len > d_.size()) fail("sequence item runs past the end of the file");
        at += len;
      }
    }
  }

  // Elements of an undefined-length item, up to its item delimiter.
  uint64_t skipItemElements(uint64_t at, bool implicit, bool be, int depth) const {
    if (depth > kMaxDepth) fail("sequences nested too deeply");
    while (true) {
      if (at + 8 > d_.size()) fail("item without end");
      if (u16(at, be) == 0xFFFE && u16(at + 2, be) == 0xE00D) return at + 8;
      const Elem e = header(at, implicit, be);
      at = skipValue(e, implicit, be, depth);
    }
  }

  uint64_t skipValue(const Elem& e, bool implicit, bool be, int depth) const {
    if (e.length == kUndefined) {
      // SQ, UN or implicit-VR sequences; UN of undefined length holds implicit VR LE.
      const bool un = e.vr[0] == 'U' && e.vr[1] == 'N';
      return skipUndefined(e.value, implicit || un, un ? false : be, depth + 1);
    }
    if (e.value + e.length > d_.size()) fail("element runs past the end of the file");
    return e.value + e.length;
  }

  std::string str(const Elem& e) const {
    if (e.value + e.length > d_.size()) fail("element runs past the end of the file");
    return trim(d_.substr(static_cast<size_t>(e.value), std::min<uint32_t>(e.length, 1024)));
  }
  int us(const Elem& e, bool be) const {
    if (e.length < 2) return 0;
    return u16(e.value, be);
  }

  // Parses the data set from `at` (top level). Stops at the pixel data.
  void dataSet(uint64_t at, bool implicit, bool be) {
    while (at + 8 <= d_.size()) {
      const Elem e = header(at, implicit, be);
      const uint32_t tag = uint32_t{e.group} << 16 | e.element;
      if (e.group == 0xFFFE) fail("unexpected item at the top level (byte " + std::to_string(at) + ")");
      if (tag == 0x7FE00010u) {
        h_.hasPixelData = true;
        h_.pixelOffset = e.value;
        if (e.length == kUndefined) {
          h_.encapsulated = true;
          h_.pixelLength = d_.size() - e.value;
        } else {
          h_.pixelLength = e.length;
        }
        return;
      }
      if (tag == 0x7FE00008u || tag == 0x7FE00009u) h_.floatPixelData = true;
      if (tag == 0x52009229u || tag == 0x52009230u) h_.enhanced = true;
      if (tag == 0x00041220u) h_.isDicomdir = true;
      if (e.length != kUndefined && e.value + e.length > d_.size())
        fail("element (" + hex(e.group) + "," + hex(e.element) + ") runs past the end of the file");
      if (e.length != kUndefined) take(tag, e, be);
      at = skipValue(e, implicit, be, 0);
    }
  }

  static std::string hex(uint16_t v) {
    char b[8];
    std::snprintf(b, sizeof b, "%04X", v);
    return b;
  }

  void take(uint32_t tag, const Elem& e, bool be) {
    double v[6];
    switch (tag) {
      case 0x00080016u:
        h_.sopClass = str(e);
        break;
      case 0x00080018u:
        h_.sopInstance = str(e);
        break;
      case 0x00080060u:
        h_.modality = str(e);
        break;
      case 0x0020000Eu:
        h_.seriesUid = str(e);
        break;
      case 0x00200013u:
        if (parseDs(str(e), v, 1)) h_.hasInstance = true, h_.instanceNumber = static_cast<int64_t>(v[0]);
        break;
      case 0x00200032u:
        h_.hasIpp = parseDs(str(e), h_.ipp, 3);
        break;
      case 0x00200037u:
        h_.hasIop = parseDs(str(e), h_.iop, 6);
        break;
      case 0x00280002u:
        h_.samples = us(e, be);
        break;
      case 0x00280004u:
        h_.photometric = str(e);
        break;
      case 0x00280008u:
        if (parseDs(str(e), v, 1)) h_.frames = static_cast<int64_t>(v[0]);
        break;
      case 0x00280010u:
        h_.rows = us(e, be);
        break;
      case 0x00280011u:
        h_.cols = us(e, be);
        break;
      case 0x00280030u:
        h_.hasPixelSpacing = parseDs(str(e), h_.pixelSpacing, 2);
        break;
      case 0x00181164u:
        h_.hasImagerSpacing = parseDs(str(e), h_.imagerSpacing, 2);
        break;
      case 0x00280100u:
        h_.bitsAllocated = us(e, be);
        break;
      case 0x00280101u:
        h_.bitsStored = us(e, be);
        break;
      case 0x00280102u:
        h_.highBit = us(e, be);
        break;
      case 0x00280103u:
        h_.pixelRep = us(e, be);
        break;
      case 0x00281052u:
        if (parseDs(str(e), v, 1)) h_.intercept = v[0], h_.hasRescale = true;
        break;
      case 0x00281053u:
        if (parseDs(str(e), v, 1)) h_.slope = v[0], h_.hasRescale = true;
        break;
      case 0x00180050u:
        if (parseDs(str(e), v, 1)) h_.sliceThickness = v[0];
        break;
      case 0x00180088u:
        if (parseDs(str(e), v, 1)) h_.spacingBetweenSlices = v[0];
        break;
      default:
        break;
    }
  }

  // File meta group (explicit VR LE) from `at`; returns the offset after it.
  uint64_t meta(uint64_t at, std::string& mediaSop) {
    while (at + 8 <= d_.size() && u16(at, false) == 0x0002) {
      const Elem e = header(at, false, false);
      if (e.length == kUndefined) fail("undefined length in the file meta header");
      if (e.value + e.length > d_.size()) fail("file meta header runs past the end of the file");
      if (e.element == 0x0010) h_.transferSyntax = str(e);
      if (e.element == 0x0002) mediaSop = str(e);
      at = e.value + e.length;
    }
    return at;
  }

 private:
  const std::string& d_;
  const std::string& name_;
  DicomHeader& h_;
};

std::string inflateRaw(const std::string& in, size_t from, const std::string& name) {
  z_stream zs{};
  if (inflateInit2(&zs, -MAX_WBITS) != Z_OK) throw IoError(name + ": cannot start zlib");
  std::string out;
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + from));
  zs.avail_in = static_cast<uInt>(in.size() - from);
  char buf[65536];
  int rc = Z_OK;
  while (rc == Z_OK) {
    zs.next_out = reinterpret_cast<Bytef*>(buf);
    zs.avail_out = sizeof buf;
    rc = inflate(&zs, Z_NO_FLUSH);
    out.append(buf, sizeof buf - zs.avail_out);
    if (out.size() > (in.size() + 1024) * 1040) rc = Z_DATA_ERROR;
    if (rc == Z_BUF_ERROR && zs.avail_in == 0) break;
  }
  inflateEnd(&zs);
  if (rc != Z_STREAM_END && rc != Z_BUF_ERROR) throw IoError(name + ": corrupt deflated DICOM data set");
  return out;
}

void parseInto(const std::string& data, const std::string& name, DicomHeader& h, std::string* inflated) {
  Parser p(data, name, h);
  uint64_t at = 0;
  std::string mediaSop;
  if (data.size() >= 132 && data.compare(128, 4, "DICM") == 0) {
    at = p.meta(132, mediaSop);
  } else if (data.size() >= 4 && data.compare(0, 4, "DICM") == 0) {
    at = p.meta(4, mediaSop);
  } else if (data.size() >= 8 && data[0] == 0x02 && data[1] == 0 && isVr(data.data() + 4)) {
    at = p.meta(0, mediaSop);
  }
  const std::string& ts = h.transferSyntax;
  bool implicit = false, be = false;
  if (ts.empty()) {
    // No meta header: guess from the first element (pydicom writes such files).
    if (at + 8 > data.size()) throw IoError(name + ": not a DICOM file (too short)");
    const uint16_t gle = p.u16(at, false), gbe = p.u16(at, true);
    if (gle == 0x0008 || (gle < 0x0100 && gle % 2 == 0 && gle != 0)) {
      implicit = !isVr(data.data() + at + 4);
    } else if (gbe == 0x0008) {
      be = true;
      implicit = !isVr(data.data() + at + 4);
    } else {
      throw IoError(name + ": not a DICOM file (no DICM marker, no recognisable data set)");
    }
  } else if (ts == "1.2.840.10008.1.2") {
    implicit = true;
  } else if (ts == "1.2.840.10008.1.2.2") {
    be = true;
  } else if (ts == "1.2.840.10008.1.2.1.99") {
    h.deflated = true;
  }
  h.implicitVr = implicit;
  h.bigEndian = be;
  if (h.deflated) {
    std::string body = inflateRaw(data, static_cast<size_t>(at), name);
    DicomHeader inner;
    inner.transferSyntax = "1.2.840.10008.1.2.1";
    Parser q(body, name, inner);
    q.dataSet(0, false, false);
    inner.transferSyntax = h.transferSyntax;
    inner.deflated = true;
    inner.file = h.file;
    h = inner;
    if (inflated) *inflated = std::move(body);
  } else {
    p.dataSet(at, implicit, be);
  }
  if (h.sopClass.empty()) h.sopClass = mediaSop;
  if (mediaSop == "1.2.840.10008.1.3.10") h.isDicomdir = true;
}

}  // namespace

bool looksLikeDicom(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char b[132] = {};
  in.read(b, sizeof b);
  const auto n = in.gcount();
  if (n >= 132 && std::memcmp(b + 128, "DICM", 4) == 0) return true;
  if (n < 8) return false;
  const auto* u = reinterpret_cast<const unsigned char*>(b);
  const unsigned gle = u[0] | u[1] << 8, gbe = u[0] << 8 | u[1];
  const unsigned ele = u[2] | u[3] << 8;
  // A data set starting with (0002,xxxx) or (0008,xxxx) and a small element number.
  return ((gle == 0x0002 || gle == 0x0008) && ele < 0x0100) || (gbe == 0x0008 && (u[2] << 8 | u[3]) < 0x0100);
}

DicomHeader parseDicomBuffer(const std::string& data, const std::string& name) {
  DicomHeader h;
  h.file = name;
  parseInto(data, name, h, nullptr);
  return h;
}

DicomHeader parseDicomHeader(const std::string& path, std::string* bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open for reading");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0);
  if (size < 0) throw IoError(path + ": cannot read");
  // The header part first (most headers are a few KB); the whole file only when needed.
  std::string data;
  const std::streamoff first = bytes ? size : std::min<std::streamoff>(size, 1 << 20);
  data.resize(static_cast<size_t>(first));
  in.read(data.data(), first);
  if (in.gcount() != first) throw IoError(path + ": read error");
  DicomHeader h;
  h.file = path;
  try {
    std::string inflated;
    parseInto(data, path, h, &inflated);
    if (bytes) *bytes = h.deflated ? std::move(inflated) : std::move(data);
    return h;
  } catch (const IoError&) {
    if (first == size) throw;
  }
  // The header did not fit in the first megabyte: read everything.
  return parseDicomHeader(path, &data);
}

std::string dicomNotAnImage(const DicomHeader& h) {
  struct Known {
    const char* prefix;
    const char* what;
  };
  static const Known kNon[] = {
      {"1.2.840.10008.1.3.10", "a DICOMDIR (an index of a DICOM media, not an image)"},
      {"1.2.840.10008.5.1.4.1.1.481.2", "an RT Dose object (a dose grid, not an image series)"},
      {"1.2.840.10008.5.1.4.1.1.481.3", "an RT Structure Set (contours, not an image)"},
      {"1.2.840.10008.5.1.4.1.1.481.", "an RT object (plan, treatment record), not an image"},
      {"1.2.840.10008.5.1.4.1.1.66.4", "a Segmentation object (label frames, not an image series)"},
      {"1.2.840.10008.5.1.4.1.1.66", "a raw data / registration object, not an image"},
      {"1.2.840.10008.5.1.4.1.1.88.", "a Structured Report, not an image"},
      {"1.2.840.10008.5.1.4.1.1.9.", "a waveform (ECG, audio), not an image"},
      {"1.2.840.10008.5.1.4.1.1.11.", "a presentation state, not an image"},
      {"1.2.840.10008.5.1.4.1.1.104.", "an encapsulated document, not an image"},
      {"1.2.840.10008.5.1.4.1.1.67", "a real-world value map, not an image"},
  };
  if (h.isDicomdir) return "a DICOMDIR (an index of a DICOM media, not an image)";
  for (const auto& k : kNon)
    if (h.sopClass.rfind(k.prefix, 0) == 0) return std::string(k.what) + " (SOP class " + h.sopClass + ")";
  if (h.floatPixelData) return "floating-point pixel data (parametric map), not supported";
  if (!h.hasPixelData) return "no pixel data (SOP class " + (h.sopClass.empty() ? "?" : h.sopClass) + ")";
  return "";
}

}  // namespace vs::io_detail
