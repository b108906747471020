// Internal: the two priority queues of the shortest-path engine (not part of the public API).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <queue>
#include <vector>

namespace vs::detail {

// Monotone radix heap (Ahuja, Mehlhorn, Orlin, Tarjan 1990) over 64-bit fixed-point keys
// key = floor(priority * scale). Pushed keys must be >= the last extracted key (true for
// Dijkstra with non-negative edges); smaller keys are clamped to it. Bucket 0 holds the entries
// whose key equals the last extracted key; bucket i those differing from it first in bit i-1.
// Each entry moves at most 64 times, in practice O(log C) with C the key range of one edge.
class RadixQueue {
public:
  explicit RadixQueue(double scale = 1) : scale_(scale) {}
  void setScale(double s) { scale_ = s; }
  void clear() {
    for (auto& b : buckets_) b.clear();
    last_ = 0;
    size_ = 0;
  }
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  uint64_t keyOf(double p) const {
    const double s = p * scale_;
    return s >= 9.0e18 ? (uint64_t(1) << 63) : static_cast<uint64_t>(s);
  }
  // True when the two priorities map to different keys (old may be +inf).
  bool differentKey(double oldP, double newP) const { return !(oldP < 1e300) || keyOf(oldP) != keyOf(newP); }
  void push(double priority, uint32_t node) {
    uint64_t k = keyOf(priority);
    if (k < last_) k = last_;
    buckets_[bucketOf(k)].push_back({k, node});
    ++size_;
  }
  // The node pop() would return next if it is known without work, else UINT32_MAX (prefetch hint).
  uint32_t peek() const { return buckets_[0].empty() ? UINT32_MAX : buckets_[0].back().node; }
  // True if entries with the last extracted key remain (only meaningful after a pop).
  bool sameKeyPending() const { return !buckets_[0].empty(); }
  uint32_t pop() {
    if (buckets_[0].empty()) {
      int i = 1;
      while (buckets_[i].empty()) ++i;
      auto& src = buckets_[i];
      uint64_t m = src[0].key;
      for (const auto& e : src) m = e.key < m ? e.key : m;
      last_ = m;
      for (const auto& e : src) buckets_[bucketOf(e.key)].push_back(e);
      src.clear();
    }
    const Entry e = buckets_[0].back();
    buckets_[0].pop_back();
    --size_;
    return e.node;
  }
  uint64_t lastKey() const { return last_; }

private:
  struct Entry {
    uint64_t key;
    uint32_t node;
  };
  int bucketOf(uint64_t k) const { return k == last_ ? 0 : 64 - __builtin_clzll(k ^ last_); }
  std::array<std::vector<Entry>, 65> buckets_;
  uint64_t last_ = 0;
  size_t size_ = 0;
  double scale_ = 1;
};

// Reference: binary heap (std::priority_queue) of float64 priorities with lazy deletion.
class HeapQueue {
public:
  explicit HeapQueue(double = 1) {}
  void setScale(double) {}
  void clear() { heap_ = {}; }
  bool empty() const { return heap_.empty(); }
  size_t size() const { return heap_.size(); }
  bool differentKey(double, double) const { return true; }
  void push(double priority, uint32_t node) { heap_.push({priority, node}); }
  bool sameKeyPending() const { return false; }
  uint32_t peek() const { return heap_.empty() ? UINT32_MAX : heap_.top().node; }
  uint32_t pop() {
    const uint32_t n = heap_.top().node;
    heap_.pop();
    return n;
  }

private:
  struct Entry {
    double p;
    uint32_t node;
    bool operator>(const Entry& o) const { return p > o.p; }
  };
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap_;
};

}  // namespace vs::detail
