// The k-th smallest of a block's samples without std::nth_element's branches (session 50 speed7). A block's samples
// are noise around its background, so nearly every compare of nth_element's introselect goes either way at random and
// mispredicts about half the time (perf: its selections were ~16 % of the airway trace's cycles); the partition below
// stores both sides unconditionally and counts instead of branching.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace vs {

// True where v[0..n) holds a NaN or a -0. Elsewhere the k-th smallest by < is one value with one bit pattern (equal
// floats other than +-0 have equal bits), so any exact selection gives nth_element's float; there it need not (a NaN
// has no place in <'s order; which of +-0 nth_element leaves depends on the samples' order) and the callers keep
// nth_element. A property of the values, not their order: every call on the same samples takes the same path.
inline bool orderNeedsNthElement(const float* v, size_t n) {
  bool odd = false;
  size_t i = 0;
#if defined(__SSE2__)
  // Four at a time: -0's bits, or a magnitude's bits above infinity's (a NaN; as int32 both sides are positive).
  const __m128i negZero = _mm_set1_epi32(static_cast<int>(0x80000000u)), inf = _mm_set1_epi32(0x7f800000),
                magnitude = _mm_set1_epi32(0x7fffffff);
  __m128i any = _mm_setzero_si128();
  for (; i + 4 <= n; i += 4) {
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + i));
    any =
        _mm_or_si128(any, _mm_or_si128(_mm_cmpeq_epi32(b, negZero), _mm_cmpgt_epi32(_mm_and_si128(b, magnitude), inf)));
  }
  odd = _mm_movemask_epi8(any) != 0;
#endif
  for (; i < n; ++i) {
    uint32_t b;
    std::memcpy(&b, v + i, sizeof b);
    odd |= (b == 0x80000000u) | ((b & 0x7fffffffu) > 0x7f800000u);
  }
  return odd;
}

// As std::nth_element(v + lo, v + k, v + hi) on values without NaN: afterwards v[k] is the k-th smallest of
// v[lo..hi) (k - lo values before it), none before it larger and none after it smaller. Quickselect around the median
// of the first, middle and last values: one branchless pass puts the values < p first; only where none is (p the
// range's smallest) and k lies beyond, a second pass puts those equal to p next (a block of one repeated value - a
// constant region - ends in one round).
inline void selectKth(float* v, size_t lo, size_t k, size_t hi) {
  while (hi - lo > 8) {
    const float a = v[lo], b = v[lo + (hi - lo) / 2], c = v[hi - 1];
    const float p = std::max(std::min(a, b), std::min(std::max(a, b), c));  // one of the three: in the range
    size_t less = lo;                                                       // v[lo..less) < p
    for (size_t j = lo; j < hi; ++j) {
      const float x = v[j];
      v[j] = v[less];
      v[less] = x;
      less += x < p;
    }
    if (k < less) {
      hi = less;  // < hi: p itself is not < p
      continue;
    }
    if (less > lo) {
      lo = less;  // v[lo..less) < p <= v[less..hi)
      continue;
    }
    size_t notAbove = less;  // v[less..notAbove) == p
    for (size_t j = less; j < hi; ++j) {
      const float x = v[j];
      v[j] = v[notAbove];
      v[notAbove] = x;
      notAbove += !(p < x);
    }
    if (k < notAbove) return;
    lo = notAbove;  // > less: p is in it
  }
  for (size_t i = lo + 1; i < hi; ++i) {  // the last few: insertion sort
    const float x = v[i];
    size_t j = i;
    for (; j > lo && x < v[j - 1]; --j) v[j] = v[j - 1];
    v[j] = x;
  }
}

}  // namespace vs
