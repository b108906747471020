// A block's samples for the local background (auto_cost.h: sampleBlock), its value, cap and spread from them, the
// filters over a scale's blocks (borrowBackground, neighbourFilter), and the blocks away from the root's structure
// sampled while the connect flood runs (BackgroundPresample).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <vector>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include "tracking/auto_cost.h"
#include "tracking/block_filters.h"
#include "tracking/block_select.h"
#include "util/parallel.h"

namespace vs {

namespace {

// sampleBlock with its polarity and which masks it reads fixed at compile time (session 47 speed2: the per-sample tests
// of `bright`, `up` and `bm` were a third of its instructions; the same samples in the same order).
template <bool Bright, bool HasUp, bool HasMask>
void sampleBlockAs(const VolumeF32& vol, const int64_t lo[3], const int64_t blockVoxels[3], const int64_t step[3],
                   float edge, const uint8_t* up, float hiUp, const uint8_t* bm, BlockSamples& s) {
  constexpr bool bright = Bright;
  if constexpr (!HasUp) up = nullptr;
  if constexpr (!HasMask) bm = nullptr;
  const Geometry& g = vol.geometry();
  int64_t hi[3], count[3];
  for (int a = 0; a < 3; ++a) {
    hi[a] = std::min(g.dims[a], lo[a] + blockVoxels[a]);
    count[a] = (hi[a] - lo[a] + step[a] - 1) / step[a];
  }
  const auto cap = static_cast<size_t>(count[0] * count[1] * count[2]);
  s.vals.resize(cap);
  s.diffs.resize(cap);
  s.valIn.resize(bm ? cap : 0);
  s.diffIn.resize(bm ? cap : 0);
  s.deepVals.clear();
  s.sampled = cap;
  const float* data = vol.data();
  // The outputs' storage held aside: a byte stored through valIn / diffIn may alias any object, so the vectors' own
  // pointers would be read again per sample.
  float *vals = s.vals.data(), *diffs = s.diffs.data();
  uint8_t *valIn = s.valIn.data(), *diffIn = s.diffIn.data();
  size_t nv = 0, nd = 0, inStructure = 0;
  for (int64_t z = lo[2]; z < hi[2]; z += step[2]) {
    // A block's row is a line or two, the next sampled row often another page: the slab's rows are
    // asked for at once (their misses overlap).
    for (int64_t y = lo[1]; y < hi[1]; y += step[1]) {
      const int64_t i = g.linear(lo[0], y, z);
      __builtin_prefetch(data + i);
      __builtin_prefetch(data + g.linear(hi[0] - 1, y, z));
      if constexpr (HasUp) __builtin_prefetch(up + i);
      if constexpr (HasMask) __builtin_prefetch(bm + i);
    }
    // Only the volume's last x has no next voxel: the rows' samples before it test nothing for it (the same samples).
    const int64_t lastX = g.dims[0] - 1;
    for (int64_t y = lo[1]; y < hi[1]; y += step[1]) {
      const int64_t row = g.linear(0, y, z);
      const auto sampleAt = [&]<bool HasNext>(int64_t x) {
        const int64_t i = row + x;
        const int64_t j = HasNext ? i + 1 : i;
        const float v = data[i], w = data[j];
        // Bone or metal and their shell (beyond the upper edge) are no background either.
        const bool keep = (bright ? v < edge : v > edge) && !(HasUp && (up[i] || (bright ? v > hiUp : v < hiUp)));
        // Neighbour differences: noise and texture (lung parenchyma), not the block's slow trends or
        // its few edges (the median of them).
        const bool pair = keep && HasNext && (bright ? w < edge : w > edge);
        vals[nv] = v;
        diffs[nd] = std::abs(w - v);
        if constexpr (HasMask) {
          const uint8_t m = bm[i];
          inStructure += m >= 2;
          if (m == 3) s.deepVals.push_back(v);
          valIn[nv] = m != 0;
          diffIn[nd] = m != 0 || bm[j] != 0;
        }
        nv += keep;
        nd += pair;
      };
      int64_t x = lo[0];
      for (const int64_t end = std::min(hi[0], lastX); x < end; x += step[0]) sampleAt.template operator()<true>(x);
      if (x < hi[0]) sampleAt.template operator()<false>(x);  // x is the last voxel of the row
    }
  }
  s.inStructure = inStructure;
  s.vals.resize(nv);
  s.diffs.resize(nd);
  if (bm) s.valIn.resize(nv);
  if (bm) s.diffIn.resize(nd);
}

}  // namespace

void sampleBlock(const VolumeF32& vol, const int64_t lo[3], const int64_t blockVoxels[3], const int64_t step[3],
                 bool bright, float edge, const uint8_t* up, float hiUp, const uint8_t* bm, BlockSamples& s) {
  const auto as = [&]<bool Bright>() {
    if (up && bm) return sampleBlockAs<Bright, true, true>(vol, lo, blockVoxels, step, edge, up, hiUp, bm, s);
    if (up) return sampleBlockAs<Bright, true, false>(vol, lo, blockVoxels, step, edge, up, hiUp, bm, s);
    if (bm) return sampleBlockAs<Bright, false, true>(vol, lo, blockVoxels, step, edge, up, hiUp, bm, s);
    sampleBlockAs<Bright, false, false>(vol, lo, blockVoxels, step, edge, up, hiUp, bm, s);
  };
  if (bright) return as.template operator()<true>();
  as.template operator()<false>();
}

BlockGrid blockGrid(const Geometry& g, double blockMm) {
  BlockGrid bg;
  for (int a = 0; a < 3; ++a) {
    // At least 2 voxels: a block of one voxel is that voxel, not its background.
    bg.blockVoxels[a] = std::clamp<int64_t>(std::max<int64_t>(2, std::lround(blockMm / g.spacing[a])), 1, g.dims[a]);
    bg.blocks[a] = (g.dims[a] + bg.blockVoxels[a] - 1) / bg.blockVoxels[a];
  }
  return bg;
}

void blockSampleSteps(const BlockGrid& bg, int64_t step[3]) {
  for (int a = 0; a < 3; ++a) step[a] = std::max<int64_t>(1, bg.blockVoxels[a] / 8);  // at most ~8^3 samples per block
}

namespace {

// Where the p-th percentile of n values lies once they are ordered.
size_t percentileIndex(size_t n, double p) {
  return static_cast<size_t>(std::lround(p / 100.0 * static_cast<double>(n - 1)));
}

// The k-th smallest of `vals`, where an earlier selection has already put the values at each of `pivots` in place:
// every value before a pivot is <= it, every value after >= it, so the k-th smallest of the whole lies between the
// pivots around k and is the same value a search of the whole finds - only that stretch is searched.
float kthBetweenPivots(std::vector<float>& vals, size_t k, std::initializer_list<size_t> pivots) {
  size_t lo = 0, hi = vals.size();
  for (size_t q : pivots) {
    if (q == k) return vals[k];
    if (q < k) lo = std::max(lo, q + 1);
    if (q > k) hi = std::min(hi, q);
  }
  const auto at = [&](size_t i) { return vals.begin() + static_cast<std::ptrdiff_t>(i); };
  if (orderNeedsNthElement(vals.data(), vals.size()))
    std::nth_element(at(lo), at(k), at(hi));
  else
    selectKth(vals.data(), lo, k, hi);  // the same float, and the same partition around k the next call reads
  return vals[k];
}

// The smallest (Min) or largest of v[0..n), n >= 1, four lanes at a time (SSE where there is; the same value as one
// scan: the values hold no NaN - sampleBlock keeps only values on the background's side of the edge - and which of +-0
// is kept does not change a bound read by value).
template <bool Min>
float extremeOf(const float* v, size_t n) {
  size_t i = 0;
  float m = v[0];
#if defined(__SSE__)
  if (n >= 4) {
    __m128 lanes = _mm_loadu_ps(v);
    for (i = 4; i + 4 <= n; i += 4)
      lanes = Min ? _mm_min_ps(lanes, _mm_loadu_ps(v + i)) : _mm_max_ps(lanes, _mm_loadu_ps(v + i));
    float lane[4];
    _mm_storeu_ps(lane, lanes);
    for (const float x : lane) m = (Min ? x < m : m < x) ? x : m;
  }
#endif
  for (; i < n; ++i) m = (Min ? v[i] < m : m < v[i]) ? v[i] : m;
  return m;
}

}  // namespace

// The percentile-th of `vals` counted as `p` (bright: 100 - percentile), or NaN with fewer than
// min(8, half the block's samples) values (a block of lumen).
float blockPercentile(std::vector<float>& vals, size_t sampled, double p) {
  if (vals.empty() || vals.size() < std::min<size_t>(8, (sampled + 1) / 2))
    return std::numeric_limits<float>::quiet_NaN();
  return kthBetweenPivots(vals, percentileIndex(vals.size(), p), {});
}

// The block's value r (its percentile p counted as in blockPercentile) no farther towards the lumen than its
// background side's quartile q (the percentile counted from the other side) plus the larger of k times q's distance
// to the tail (the percentile / 5 from that side) and `floorWidth` (k root noise spreads: a flat or quantised tail).
// Gaussian noise: r lies 1.35 noise spreads beyond q, the cap 4.8 (k 5): no change; only where lumen fills the block
// beyond the percentile.
void capAtBackgroundTail(std::vector<float>& vals, double p, double percentile, bool bright, double floorWidth,
                         double k, float& r) {
  // With 8 values or more blockPercentile's "a block of lumen" (NaN) never holds for q or the tail.
  if (std::isnan(r) || vals.size() < 8) return;
  // `vals` as blockPercentile(vals, sampled, p) left them: in place at r's index. q and the tail are searched beside
  // it (session 46 speed: the same order statistics as two whole searches, a third of the block's selection work).
  const size_t n = vals.size(), kr = percentileIndex(n, p), kq = percentileIndex(n, 100.0 - p);
  // The cap is never nearer the lumen than the background side's extreme value plus floorWidth (q lies within the
  // values, the width is at least floorWidth, and adding and rounding to float keep the order): a value r within that
  // reach is not capped, whatever q and the tail are (session 48 speed4: most blocks, their two selections skipped).
  // The extreme lies on the background's side of r's pivot. A NaN floorWidth never skips.
  const auto noCapWithin = [&](float farthest) {
    return bright ? r <= static_cast<float>(farthest + floorWidth) : r >= static_cast<float>(farthest - floorWidth);
  };
  if (noCapWithin(bright ? extremeOf<true>(vals.data(), kr + 1) : extremeOf<false>(vals.data() + kr, n - kr))) return;
  const float q = kthBetweenPivots(vals, kq, {kr});
  if (noCapWithin(q)) return;  // the same bound from q itself: the tail's selection skipped
  const float tail =
      kthBetweenPivots(vals, percentileIndex(n, bright ? percentile / 5 : 100.0 - percentile / 5), {kr, kq});
  const double width = std::max(k * std::abs(double(q) - double(tail)), floorWidth);
  const float cap = static_cast<float>(bright ? q + width : q - width);
  if (bright ? r > cap : r < cap) r = cap;
}

float blockSpread(std::vector<float>& diffs, float raw, size_t nVals) {
  if (std::isnan(raw) || diffs.size() * 2 < nVals) return -1;
  const size_t mid = diffs.size() / 2;
  if (orderNeedsNthElement(diffs.data(), diffs.size()))
    std::nth_element(diffs.begin(), diffs.begin() + static_cast<std::ptrdiff_t>(mid), diffs.end());
  else
    selectKth(diffs.data(), 0, mid, diffs.size());
  return 1.4826f * diffs[mid] / std::sqrt(2.0f);
}

PlainBlock plainBlock(const VolumeF32& vol, const BlockGrid& bg, int64_t b, bool bright, float edge, const uint8_t* up,
                      float hiUp, double percentile, double tailCap, double tailFloor, BlockSamples& sample) {
  int64_t step[3];
  blockSampleSteps(bg, step);
  const int64_t lo[3] = {(b % bg.blocks[0]) * bg.blockVoxels[0],
                         ((b / bg.blocks[0]) % bg.blocks[1]) * bg.blockVoxels[1],
                         (b / (bg.blocks[0] * bg.blocks[1])) * bg.blockVoxels[2]};
  sampleBlock(vol, lo, bg.blockVoxels.data(), step, bright, edge, up, hiUp, nullptr, sample);
  const double p = bright ? 100.0 - percentile : percentile;
  const size_t nVals = sample.vals.size();
  PlainBlock out;
  out.raw = out.uncapped = blockPercentile(sample.vals, sample.sampled, p);
  out.spread = blockSpread(sample.diffs, out.raw, nVals);
  // Beside no wide lumen, a block that other tubes fill beyond the percentile (two thin vessels side by side in
  // coarse slices) has its percentile in their partial-volume walls: capped at tailCap widths of its background
  // side's tail (that quartile against the 5th percentile, at least tailFloor) beyond that quartile
  // (docs/notes/tracking.md, session 17 par1).
  if (tailCap > 0) capAtBackgroundTail(sample.vals, p, percentile, bright, tailFloor, tailCap, out.raw);
  return out;
}

// Blocks without background of their own (NaN) borrow, wave by wave (26-neighbours), the most
// lumen-like value of their neighbours that have one; the window's far edge where none has any.
void borrowBackground(const BlockGrid& bg, std::vector<float>& raw, float edge, bool bright) {
  std::vector<float> next = raw;
  for (bool changed = true; changed;) {
    changed = false;
    for (int64_t k = 0; k < bg.blocks[2]; ++k)
      for (int64_t j = 0; j < bg.blocks[1]; ++j)
        for (int64_t i = 0; i < bg.blocks[0]; ++i) {
          const size_t at = static_cast<size_t>((k * bg.blocks[1] + j) * bg.blocks[0] + i);
          if (!std::isnan(raw[at])) continue;
          float best = std::numeric_limits<float>::quiet_NaN();
          for (int64_t c = std::max<int64_t>(0, k - 1); c <= std::min(bg.blocks[2] - 1, k + 1); ++c)
            for (int64_t b = std::max<int64_t>(0, j - 1); b <= std::min(bg.blocks[1] - 1, j + 1); ++b)
              for (int64_t a = std::max<int64_t>(0, i - 1); a <= std::min(bg.blocks[0] - 1, i + 1); ++a) {
                const float v = raw[static_cast<size_t>((c * bg.blocks[1] + b) * bg.blocks[0] + a)];
                if (!std::isnan(v) && (std::isnan(best) || (bright ? v > best : v < best))) best = v;
              }
          if (!std::isnan(best)) {
            next[at] = best;
            changed = true;
          }
        }
    raw = next;
  }
  for (float& v : raw)
    if (std::isnan(v)) v = edge;
}

// The most lumen-like of each block and its 26 neighbours (a vessel beside a brighter region or tissue at
// the skin is not measured against air; their median was tried: it reached the carotid MRA's dim targets
// but made chest CTA lung parenchyma beside airways lumen - docs/notes), and the median spread of those
// that have one (rawSpread < 0: none).
void neighbourFilter(BlockGrid& bg, const std::vector<float>& raw, const std::vector<float>* rawSpread, bool bright) {
  bg.value.resize(raw.size());
  bg.spread.assign(raw.size(), 0);
  const int64_t ni = bg.blocks[0], nj = bg.blocks[1], nk = bg.blocks[2];
  const float* rawAt = raw.data();
  const float* spreadAt = rawSpread ? rawSpread->data() : nullptr;
  float* valueOut = bg.value.data();
  float* spreadOut = bg.spread.data();
  // The 27 neighbours' offsets in the loops' order (c, then b, then a): a block away from the grid's faces reads them
  // without the per-neighbour bounds (session 48 speed5: the same reads in the same order).
  int64_t offset[27];
  for (int64_t c = -1, o = 0; c <= 1; ++c)
    for (int64_t b = -1; b <= 1; ++b)
      for (int64_t a = -1; a <= 1; ++a) offset[o++] = (c * nj + b) * ni + a;
  // Each block reads only the raw fields, in the same order as one thread did: the block layers split among threads
  // give the same values (session 47 speed2; the first most lumen-like, the same median).
  parallelFor(0, nk, [&](int64_t k0, int64_t k1) {
    float nearSpread[27];
    float best = 0;
    bool first = true;
    size_t spreads = 0;
    // max_element / min_element: the first of the most lumen-like (a later equal one does not replace it)
    const auto take = [&](int64_t n) {
      const float r = rawAt[n];
      if (first || (bright ? best < r : r < best)) best = r;
      first = false;
      if (spreadAt && spreadAt[n] >= 0) nearSpread[spreads++] = spreadAt[n];
    };
    for (int64_t k = k0; k < k1; ++k)
      for (int64_t j = 0; j < nj; ++j)
        for (int64_t i = 0; i < ni; ++i) {
          best = 0;
          first = true;
          spreads = 0;
          const int64_t at = (k * nj + j) * ni + i;
          if (k > 0 && j > 0 && i > 0 && k < nk - 1 && j < nj - 1 && i < ni - 1) {
            for (const int64_t o : offset) take(at + o);
          } else {
            for (int64_t c = std::max<int64_t>(0, k - 1); c <= std::min(nk - 1, k + 1); ++c)
              for (int64_t b = std::max<int64_t>(0, j - 1); b <= std::min(nj - 1, j + 1); ++b)
                for (int64_t a = std::max<int64_t>(0, i - 1); a <= std::min(ni - 1, i + 1); ++a)
                  take((c * nj + b) * ni + a);
          }
          valueOut[at] = best;
          if (spreads > 0) {
            if (orderNeedsNthElement(nearSpread, spreads))
              std::nth_element(nearSpread, nearSpread + spreads / 2, nearSpread + spreads);
            else
              selectKth(nearSpread, 0, spreads / 2, spreads);
            spreadOut[at] = nearSpread[spreads / 2];
          }
        }
  });
}

BackgroundPresample::BackgroundPresample(const VolumeF32& vol, const LumenEstimate& e, double blockMm,
                                         double percentile, int scales, const std::vector<uint8_t>* upper)
    : vol_(vol),
      bright_(e.polarity == TubePolarity::Bright),
      upper_(upper && e.hasUpperEdge()),
      edge_(static_cast<float>(bright_ ? e.windowLo : e.windowHi)),
      hiUp_(static_cast<float>(e.upperHi)),
      blockMm_(blockMm),
      percentile_(percentile),
      tailCap_(e.localTailCap),
      tailFloor_(e.localTailCap * e.spread),
      shell_(upper) {
  first_.push_back(0);
  for (int k = 0; k < scales; ++k) {
    grids_.push_back(blockGrid(vol.geometry(), blockMm / (1 << k)));
    const BlockGrid& bg = grids_.back();
    const int64_t nb = bg.blocks[0] * bg.blocks[1] * bg.blocks[2];
    blocks.emplace_back(static_cast<size_t>(nb));
    first_.push_back(first_.back() + nb);
  }
}

// blockBackground's steps for a block without the structure's mask: its samples, their percentile and spread.
void BackgroundPresample::work() {
  const int64_t total = first_.back(), chunk = 16;
  const uint8_t* up = upper_ ? shell_->data() : nullptr;
  BlockSamples sample;
  for (int64_t c = next_.fetch_add(chunk); c < total; c = next_.fetch_add(chunk))
    for (int64_t n = c; n < std::min(total, c + chunk); ++n) {
      const size_t k = static_cast<size_t>(std::upper_bound(first_.begin(), first_.end(), n) - first_.begin() - 1);
      const int64_t b = n - first_[k];
      blocks[k][static_cast<size_t>(b)] =
          plainBlock(vol_, grids_[k], b, bright_, edge_, up, hiUp_, percentile_, tailCap_, tailFloor_, sample);
    }
}

bool BackgroundPresample::matches(const LumenEstimate& e, double blockMm, double percentile, int scales,
                                  const std::vector<uint8_t>* upper) const {
  const bool bright = e.polarity == TubePolarity::Bright;
  return bright == bright_ && (upper && e.hasUpperEdge()) == upper_ && (!upper_ || upper == shell_) &&
         static_cast<float>(bright ? e.windowLo : e.windowHi) == edge_ && static_cast<float>(e.upperHi) == hiUp_ &&
         blockMm == blockMm_ && percentile == percentile_ && e.localTailCap == tailCap_ &&
         e.localTailCap * e.spread == tailFloor_ && static_cast<size_t>(scales) == grids_.size() &&
         next_.load() >= first_.back();
}

// Every worker but this thread's (which runs the flood, then joins them): each block's value is a function of the
// block alone, written to its own slot, so any number of threads claiming blocks give the same blocks (on 2 cores the
// one helper as before; with more, the presample no longer outlasts the serial flood).
void BackgroundPresample::startHelper() {
  const int helpers = workerCount() - 1;
  if (helpers < 1) return;
  errors_.resize(static_cast<size_t>(helpers));
  helpers_.reserve(static_cast<size_t>(helpers));
  for (int h = 0; h < helpers; ++h)
    helpers_.emplace_back([this, h] {
      try {
        work();
      } catch (...) {
        errors_[static_cast<size_t>(h)] = std::current_exception();
        next_.store(first_.back());  // the others claim no more
      }
    });
}

void BackgroundPresample::finish() {
  work();
  for (std::thread& t : helpers_)
    if (t.joinable()) t.join();
  for (const std::exception_ptr& error : errors_)
    if (error) std::rethrow_exception(error);
}

void BackgroundPresample::stop() {
  next_.store(first_.back());
  for (std::thread& t : helpers_)
    if (t.joinable()) t.join();
}

}  // namespace vs
