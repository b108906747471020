// Whether a file's header states the orientation of its axes. Readers fall back to the
// identity direction (LPS) when it does not, which `info` must say rather than present as fact.
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>

#include "io/io_internal.h"

namespace vs::io_detail {

namespace {

// The first `max` bytes of a file, gunzipped when compressed (gzread reads plain files too).
std::string head(const std::string& path, size_t max) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) return {};
  std::string s(max, '\0');
  const int n = gzread(f, s.data(), static_cast<unsigned>(max));
  gzclose(f);
  s.resize(n > 0 ? static_cast<size_t>(n) : 0);
  return s;
}

std::string lowerCase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// True if some header line (before the first empty line) starts with one of the keys.
bool headerHasKey(const std::string& text, std::initializer_list<const char*> keys) {
  size_t pos = 0;
  while (pos < text.size()) {
    size_t e = text.find('\n', pos);
    if (e == std::string::npos) e = text.size();
    std::string line = lowerCase(text.substr(pos, e - pos));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;  // NRRD: end of the header
    const size_t b = line.find_first_not_of(" \t");
    if (b != std::string::npos)
      for (const char* k : keys)
        if (line.compare(b, std::strlen(k), k) == 0) return true;
    pos = e + 1;
  }
  return false;
}

}  // namespace

bool headerHasOrientation(const std::string& path, const std::string& format) {
  if (format == "dicom") return true;
  if (format == "nifti") {
    const std::string h = head(path, 540);
    if (h.size() < 348) return false;
    int32_t sizeofHdr;
    std::memcpy(&sizeofHdr, h.data(), 4);
    const bool swap = !(sizeofHdr == 348 || sizeofHdr == 540);
    if (swap) byteSwap(&sizeofHdr, 4, 1);
    if (sizeofHdr == 348) {
      int16_t q, s;
      std::memcpy(&q, h.data() + 252, 2);
      std::memcpy(&s, h.data() + 254, 2);
      if (swap) byteSwap(&q, 2, 1), byteSwap(&s, 2, 1);
      return q > 0 || s > 0;
    }
    if (sizeofHdr == 540 && h.size() >= 352) {
      int32_t q, s;
      std::memcpy(&q, h.data() + 344, 4);
      std::memcpy(&s, h.data() + 348, 4);
      if (swap) byteSwap(&q, 4, 1), byteSwap(&s, 4, 1);
      return q > 0 || s > 0;
    }
    return false;
  }
  if (format == "nrrd") return headerHasKey(head(path, 1 << 16), {"space:"});
  if (format == "metaimage")
    return headerHasKey(head(path, 1 << 16), {"transformmatrix", "orientation ", "orientation=", "rotation"});
  if (format == "vti") return head(path, 1 << 16).find("Direction=\"") != std::string::npos;
  return false;  // legacy VTK structured points, PNG, TIFF: no orientation in the format
}

}  // namespace vs::io_detail
