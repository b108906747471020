// std::llround without the library call (session 45 speedE): the hot voxel tests' rounding of a continuous index.
#pragma once

#include <cmath>
#include <cstdint>

namespace vs {

// std::llround(x) - the nearest integer, halves away from zero - formed inline where |x| < 2^52: the conversion
// truncates towards zero, x minus the truncation is exact there (|x - t| < 1, t zero or of x's sign and binade), and
// a remainder of at least a half rounds away. NaN, the infinities and |x| >= 2^52 are std::llround's own. The contact
// walks' lumen test called std::llround three times per sample (6 % of the carotid trace's instructions). The
// remainder's two tests are added as 0 / 1, not branched on: a branch there mispredicts about every other sample and
// made the walks slower than the library call.
inline int64_t roundHalfAway(double x) {
  if (!(std::abs(x) < 4503599627370496.0)) return std::llround(x);
  const int64_t t = static_cast<int64_t>(x);
  const double f = x - static_cast<double>(t);
  return t + static_cast<int64_t>(f >= 0.5) - static_cast<int64_t>(f <= -0.5);  // no branch: halves are common
}

}  // namespace vs
