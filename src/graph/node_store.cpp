#include "graph/node_store.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <mutex>
#include <vector>

namespace vs::engine {

namespace {

// Released record mappings kept for the next search (issue 25: the kernel's zeroing of fresh
// pages on first touch made identical searches vary 2-4x in time). At most kPoolSlots mappings
// and poolCap() bytes are held; a search takes a pooled mapping of at least the size it needs
// and at most twice it. The records need no zeroing: chunks are filled lazily before use.
constexpr size_t kPoolSlots = 2;
struct Pool {
  std::mutex m;
  std::vector<std::pair<void*, size_t>> maps;
  size_t bytes = 0;
};
Pool& pool() {
  static Pool* p = new Pool;  // never destroyed: searches may end during static destruction
  return *p;
}
size_t poolCap() {
  static const size_t cap = [] {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    const size_t phys = pages > 0 && page > 0 ? size_t(pages) * size_t(page) : size_t(8) << 30;
    return std::min(size_t(1) << 30, phys / 8);
  }();
  return cap;
}

}  // namespace

void RecordStore::release() {
  if (mapped) {
    Pool& pl = pool();
    std::lock_guard lock(pl.m);
    if (pl.maps.size() < kPoolSlots && pl.bytes + bytes <= poolCap()) {
      pl.maps.emplace_back(p, bytes);
      pl.bytes += bytes;
    } else {
      munmap(p, bytes);
    }
  } else {
    delete[] p;
  }
  p = nullptr;
  mapped = false;
}

void RecordStore::allocate(size_t n) {
  release();
  bytes = n * sizeof(NodeRec);
  if (bytes >= (size_t(4) << 20)) {
    {
      Pool& pl = pool();
      std::lock_guard lock(pl.m);
      for (size_t i = 0; i < pl.maps.size(); ++i)
        if (pl.maps[i].second >= bytes && pl.maps[i].second / 2 <= bytes) {
          p = static_cast<NodeRec*>(pl.maps[i].first);
          bytes = pl.maps[i].second;
          pl.bytes -= bytes;
          pl.maps.erase(pl.maps.begin() + long(i));
          mapped = true;
          return;
        }
    }
    void* m = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m != MAP_FAILED) {
#ifdef MADV_HUGEPAGE
      madvise(m, bytes, MADV_HUGEPAGE);
#endif
      p = static_cast<NodeRec*>(m);
      mapped = true;
      return;
    }
  }
  p = new NodeRec[n];
}

}  // namespace vs::engine
