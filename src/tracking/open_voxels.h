// The box searches' heap of open voxels (box_search.cpp's boxPath, box_rounds.cpp's BoxRounds).
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace vs::retrace::detail {

// The open voxels of a box search: a 4-ary heap ordered by (distance, box index), one entry per voxel, its place
// kept so that a shorter distance moves the entry up instead of adding another (session 39 cache702). The order is
// the one the lazy std::priority_queue of (distance, index) pairs popped its live entries in - a total order, ties
// broken by the index - so every voxel is settled in the same order as before and every route is the same.
class OpenVoxels {
 public:
  explicit OpenVoxels(int64_t n) : place_(static_cast<size_t>(n), -1) {}
  bool empty() const { return heap_.empty(); }
  std::pair<double, int32_t> top() const { return heap_.front(); }
  void pop() {
    place_[static_cast<size_t>(heap_.front().second)] = -1;
    const Item last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) down(0, last);
  }
  // Opens voxel i at distance d, or moves its entry up to d (lower than the entry's).
  void set(int32_t i, double d) {
    const int32_t at = place_[static_cast<size_t>(i)];
    if (at >= 0) return up(static_cast<size_t>(at), {d, i});
    ++entries_;
    heap_.emplace_back(d, i);
    up(heap_.size() - 1, {d, i});
  }
  int64_t entries() const { return entries_; }

 private:
  using Item = std::pair<double, int32_t>;
  static bool before(const Item& a, const Item& b) {
    return a.first < b.first || (a.first == b.first && a.second < b.second);
  }
  void put(size_t k, const Item& it) {
    heap_[k] = it;
    place_[static_cast<size_t>(it.second)] = static_cast<int32_t>(k);
  }
  void up(size_t k, const Item& it) {
    for (; k > 0 && before(it, heap_[(k - 1) / 4]); k = (k - 1) / 4) put(k, heap_[(k - 1) / 4]);
    put(k, it);
  }
  void down(size_t k, const Item& it) {
    for (size_t first = 4 * k + 1; first < heap_.size(); first = 4 * k + 1) {
      size_t best = first;
      for (size_t c = first + 1; c < std::min(first + 4, heap_.size()); ++c)
        if (before(heap_[c], heap_[best])) best = c;
      if (!before(heap_[best], it)) break;
      put(k, heap_[best]);
      k = best;
    }
    put(k, it);
  }
  std::vector<Item> heap_;
  std::vector<int32_t> place_;  // each voxel's entry in heap_, -1: none
  int64_t entries_ = 0;
};

}  // namespace vs::retrace::detail
