// Hand-written distributions over std::mt19937_64 so phantoms are identical with any
// standard library (std::normal_distribution & co. are implementation-defined).
#include <cmath>

#include "phantom/phantom.h"

namespace vs {

double PhantomRng::uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

int64_t PhantomRng::integer(int64_t lo, int64_t hi) {
  VS_REQUIRE(lo <= hi, "PhantomRng::integer: lo > hi");
  const uint64_t n = static_cast<uint64_t>(hi - lo) + 1;
  if (n == 0) return static_cast<int64_t>(engine_());  // the full 64-bit range
  // Rejection sampling removes the modulo bias; the result is fully specified.
  const uint64_t limit = UINT64_MAX - UINT64_MAX % n;
  uint64_t r;
  do r = engine_();
  while (r >= limit);
  return lo + static_cast<int64_t>(r % n);
}

double PhantomRng::normal() {
  if (hasSpare_) {
    hasSpare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double t = 2.0 * M_PI * u2;
  spare_ = r * std::sin(t);
  hasSpare_ = true;
  return r * std::cos(t);
}

uint64_t PhantomRng::derive(uint64_t seed, uint64_t salt) {
  uint64_t z = seed ^ (salt * 0x9E3779B97F4A7C15ull);
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace vs
