// A monotone priority queue of (distance, id) pairs for Dijkstra's algorithm that pops in exactly the
// order of std::priority_queue<std::pair<double, int32_t>, ..., std::greater<>>: increasing distance,
// equal distances by increasing id. So a Dijkstra that breaks ties by the pop order (the first settled
// neighbour that reaches a node's distance becomes its predecessor) gives the same predecessors, bit for
// bit, with either queue.
//
// A radix heap (Ahuja, Mehlhorn, Orlin, Tarjan 1990) over the distance's own bits (a non-negative double's
// bit pattern orders as an unsigned integer; no quantisation): bucket 0 holds the entries whose key equals
// the last popped one, bucket i those that first differ from it in bit i-1. An entry only moves to lower
// buckets, appended at the back (sequential memory, no sift through a binary heap). Entries sharing the
// popped key are sorted by id before they are handed out.
//
// Not the engine's detail::RadixQueue (graph/priority_queues.h): that one orders fixed-point keys
// floor(distance * scale) and hands out equal keys last-in first-out, which changes the terminal scan's
// ties (its trees and terminals) with the scale; this one keeps the distances' own bits and the id order.
//
// Requirements (Dijkstra with positive edge lengths meets them): distances are >= 0 and not NaN, and every
// push after the first pop has a distance >= the last popped one.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace vs {

class ExactRadixQueue {
 public:
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  void clear() {
    for (auto& b : buckets_) b.clear();
    last_ = 0;
    size_ = 0;
    sorted0_ = true;
  }
  void push(double distance, int32_t id) {
    const uint64_t k = keyOf(distance);
    assert(k >= last_ && "ExactRadixQueue: a push below the last popped distance");
    const int b = bucketOf(k);
    buckets_[static_cast<size_t>(b)].push_back({k, id});
    if (b == 0) sorted0_ = false;
    ++size_;
  }
  // The smallest (distance, id); the queue must not be empty.
  std::pair<double, int32_t> pop() {
    auto& b0 = buckets_[0];
    if (b0.empty()) {
      size_t i = 1;
      while (buckets_[i].empty()) ++i;
      auto& src = buckets_[i];
      uint64_t m = src[0].key;
      for (const Entry& e : src) m = std::min(m, e.key);
      last_ = m;
      for (const Entry& e : src) buckets_[static_cast<size_t>(bucketOf(e.key))].push_back(e);
      src.clear();
      sorted0_ = false;
    }
    if (!sorted0_) {  // the entries sharing the key, largest id first (handed out from the back)
      if (b0.size() > 1) std::sort(b0.begin(), b0.end(), [](const Entry& a, const Entry& b) { return a.id > b.id; });
      sorted0_ = true;
    }
    const Entry e = b0.back();
    b0.pop_back();
    --size_;
    return {std::bit_cast<double>(e.key), e.id};
  }

 private:
  struct Entry {
    uint64_t key;
    int32_t id;
  };
  static uint64_t keyOf(double d) { return std::bit_cast<uint64_t>(d + 0.0); }  // -0 becomes +0
  int bucketOf(uint64_t k) const { return k == last_ ? 0 : 64 - std::countl_zero(k ^ last_); }
  std::array<std::vector<Entry>, 65> buckets_;
  uint64_t last_ = 0;
  size_t size_ = 0;
  bool sorted0_ = true;
};

}  // namespace vs
