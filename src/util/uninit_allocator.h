// An allocator whose resize leaves new elements uninitialised (no zero fill).
#pragma once

#include <memory>
#include <new>
#include <utility>

namespace vs {

// Leaves new elements uninitialised (a resize without a zero fill): the region's adjacency is written record by
// record on several threads, each first touching its own pages, and what lies beyond a record's count is never read.
template <class T>
struct UninitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitAllocator<U>;
  };
  UninitAllocator() = default;
  template <class U>
  explicit UninitAllocator(const UninitAllocator<U>&) {}
  template <class U>
  void construct(U* p) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
};

}  // namespace vs
