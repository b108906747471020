// Minimal parallel loop over an index range with std::thread (no extra dependency).
// Work is split into contiguous chunks, one per hardware thread, which suits our
// slice- or row-wise loops over volumes. Exceptions from workers are rethrown.
#pragma once

#include <cstdint>
#include <functional>

namespace vs {

// Number of worker threads used by parallelFor (hardware_concurrency, at least 1;
// the VS_THREADS environment variable overrides it).
int workerCount();

// Calls body(begin, end) on disjoint sub-ranges of [begin, end) covering it, in parallel.
// grain: smallest chunk worth a thread.
void parallelFor(int64_t begin, int64_t end, const std::function<void(int64_t, int64_t)>& body, int64_t grain = 1);

}  // namespace vs
