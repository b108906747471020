#include "util/text.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace vs {

std::string numberText(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string indexText(const std::array<int64_t, 3>& v) {
  // snprintf, not `"(" + std::to_string(...)`: GCC 12 warns -Wrestrict inside libstdc++ for the latter (bug 105329).
  char b[72];
  std::snprintf(b, sizeof b, "(%lld,%lld,%lld)", static_cast<long long>(v[0]), static_cast<long long>(v[1]),
                static_cast<long long>(v[2]));
  return b;
}

std::string fixedText(double v, int decimals) {
  char b[400];  // %.Nf of 1e308 needs 309 digits before the point
  std::snprintf(b, sizeof b, "%.*f", decimals < 0 ? 0 : decimals > 30 ? 30 : decimals, v);
  return b;
}

std::vector<std::string> splitText(const std::string& s, char sep) {
  std::vector<std::string> parts;
  size_t b = 0;
  while (true) {
    const size_t e = s.find(sep, b);
    parts.push_back(s.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return parts;
}

std::string trimmedText(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

namespace {
template <class T>
bool parseWhole(const std::string& text, T& out) {
  const std::string t = trimmedText(text);
  if (t.empty()) return false;
  const char* b = t.data();
  if (*b == '+') ++b;  // from_chars refuses a leading '+'
  const auto r = std::from_chars(b, t.data() + t.size(), out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}
}  // namespace

bool parseNumber(const std::string& text, double& out) { return parseWhole(text, out) && std::isfinite(out); }

bool parseInteger(const std::string& text, int64_t& out) { return parseWhole(text, out); }

}  // namespace vs
