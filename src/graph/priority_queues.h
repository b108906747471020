// Internal: the two priority queues of the shortest-path engine (not part of the public API).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <queue>
#include <vector>

namespace vs::detail {

// The fixed-point key floor(p * scale) that the radix and the bucket queue order by (p >= 0;
// priorities beyond 9e18 / scale, +inf included, share the key 2^63).
inline uint64_t fixedPointKey(double p, double scale) {
  const double s = p * scale;
  // The signed conversion is one instruction (the unsigned one is not).
  return s >= 9.0e18 ? (uint64_t(1) << 63) : static_cast<uint64_t>(static_cast<int64_t>(s));
}

// Monotone radix heap (Ahuja, Mehlhorn, Orlin, Tarjan 1990) over 64-bit fixed-point keys
// key = floor(priority * scale). Pushed keys must be >= the last extracted key (true for
// Dijkstra with non-negative edges); smaller keys are clamped to it. Bucket 0 holds the entries
// whose key equals the last extracted key; bucket i those differing from it first in bit i-1.
// Each entry moves at most 64 times, in practice O(log C) with C the key range of one edge.
class RadixQueue {
 public:
  explicit RadixQueue(double scale = 1, double = 0) : scale_(scale) {}
  void clear() {
    for (auto& b : buckets_) b.clear();
    last_ = 0;
    size_ = 0;
  }
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  uint64_t keyOf(double p) const { return fixedPointKey(p, scale_); }
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

// Monotone bucket queue (Dial 1969) over the same fixed-point keys as RadixQueue: a circular
// array of 2^b buckets of node ids, b such that every pushed key lies within the window
// [last extracted key, last + 2^b) (Dijkstra: a push is at most one edge, A*: two edges above
// the extracted key; `maxStep` below is that bound in cost units). Push and pop are O(1) (no
// redistribution moves, 4-byte entries); finding the next non-empty bucket scans an occupancy
// bitmap, O(key gap / 64). Used when the window needs at most kMaxBuckets buckets, else the
// radix heap (see shortest_path.cpp). Entries of one key come out in LIFO order, which lets the
// engine prefetch the neighbourhoods of the next few nodes (peekAhead).
class BucketQueue {
 public:
  static constexpr uint64_t kMaxBuckets = uint64_t(1) << 16;
  // Number of buckets needed for keys up to maxStep (cost units) above the extracted key.
  static uint64_t bucketsFor(double scale, double maxStep) {
    const double span = maxStep * scale;
    if (!(span >= 0) || span > double(kMaxBuckets)) return UINT64_MAX;
    uint64_t nb = 64;
    while (double(nb) < span + 4) nb <<= 1;
    return nb;
  }
  explicit BucketQueue(double scale = 1, double maxStep = 0) : scale_(scale) {
    uint64_t nb = bucketsFor(scale, maxStep);
    if (nb == UINT64_MAX) nb = kMaxBuckets * 2;  // callers check bucketsFor() first
    buckets_.resize(nb);
    bits_.assign(nb / 64, 0);
    mask_ = nb - 1;
  }
  void clear() {
    for (auto& b : buckets_) b.size = 0;
    std::fill(bits_.begin(), bits_.end(), 0);
    cur_ = 0;
    size_ = 0;
  }
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  uint64_t keyOf(double p) const { return fixedPointKey(p, scale_); }
  void push(double priority, uint32_t node) { pushKey(keyOf(priority), node); }
  [[gnu::always_inline]] void pushKey(uint64_t k, uint32_t node) {
    if (k < cur_) k = cur_;
    const size_t b = size_t(k & mask_);
    Bucket& v = buckets_[b];
    if (v.size == 0) bits_[b >> 6] |= uint64_t(1) << (b & 63);
    if (v.size == v.cap) [[unlikely]]
      v.grow();
    v.data[v.size++] = node;
    ++size_;
  }
  uint32_t peek() const { return peekAhead(0); }
  // The node that the (d+1)-th next pop() returns if it is known without work, else UINT32_MAX.
  uint32_t peekAhead(size_t d) const {
    const Bucket& v = buckets_[size_t(cur_ & mask_)];
    return v.size > d ? v.data[v.size - 1 - d] : UINT32_MAX;
  }
  bool sameKeyPending() const { return buckets_[size_t(cur_ & mask_)].size != 0; }
  [[gnu::always_inline]] uint32_t pop() {
    size_t b = size_t(cur_ & mask_);
    if (buckets_[b].size == 0) {  // next occupied bucket, cyclically (the queue is not empty)
      size_t w = b >> 6;
      uint64_t word = bits_[w] & (~uint64_t(0) << (b & 63));
      const size_t wmask = bits_.size() - 1;
      while (!word) {
        w = (w + 1) & wmask;
        word = bits_[w];
      }
      const size_t nb = (w << 6) + size_t(__builtin_ctzll(word));
      cur_ += (nb - b) & mask_;
      b = nb;
    }
    Bucket& v = buckets_[b];
    const uint32_t node = v.data[--v.size];
    if (v.size == 0) bits_[b >> 6] &= ~(uint64_t(1) << (b & 63));
    --size_;
    return node;
  }
  uint64_t lastKey() const { return cur_; }
  uint64_t window() const { return mask_ + 1; }  // keys a push may lie above the current one
  // Moves the window of an empty queue to start at `key` (the two-thread search restarts an
  // idle domain's queue where the offers it receives are).
  void rebase(uint64_t key) {
    if (size_ == 0) cur_ = key;
  }

 private:
  // A growable array with an inlinable push (std::vector's was not inlined in the hot loop).
  struct Bucket {
    std::unique_ptr<uint32_t[]> data;
    uint32_t size = 0, cap = 0;
    void grow() {
      const uint32_t nc = cap ? cap * 2 : 16;
      std::unique_ptr<uint32_t[]> d(new uint32_t[nc]);
      std::copy(data.get(), data.get() + size, d.get());
      data = std::move(d);
      cap = nc;
    }
  };
  std::vector<Bucket> buckets_;
  std::vector<uint64_t> bits_;
  uint64_t mask_ = 63;
  uint64_t cur_ = 0;
  size_t size_ = 0;
  double scale_ = 1;
};

// Reference: binary heap (std::priority_queue) of float64 priorities with lazy deletion.
class HeapQueue {
 public:
  explicit HeapQueue(double = 1, double = 0) {}
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
