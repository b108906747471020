#include "graph/node_store.h"

#include <sys/mman.h>

namespace vs::engine {

void RecordStore::release() {
  if (mapped)
    munmap(p, bytes);
  else
    delete[] p;
  p = nullptr;
  mapped = false;
}

void RecordStore::allocate(size_t n) {
  release();
  bytes = n * sizeof(NodeRec);
  if (bytes >= (size_t(4) << 20)) {
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
