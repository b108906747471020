#include "util/text.h"

#include <cstdio>

namespace vs {

std::string numberText(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string indexText(const std::array<int64_t, 3>& v) {
  return "(" + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]) + ")";
}

std::string fixedText(double v, int decimals) {
  char b[400];  // %.Nf of 1e308 needs 309 digits before the point
  std::snprintf(b, sizeof b, "%.*f", decimals < 0 ? 0 : decimals > 30 ? 30 : decimals, v);
  return b;
}

}  // namespace vs
