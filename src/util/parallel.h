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

// Whether a second core is free right now for a two-thread search (issue 25): VS_THREADS=1 says
// no and VS_THREADS>=2 says yes; otherwise yes when this process may run on two or more CPUs and
// /proc/stat's count of runnable tasks, sampled five times half a millisecond apart, leaves a
// CPU free besides the caller in all but at most one sample. On the shared 2-core machine the two-thread map is 2x
// faster than one thread when the second core is idle and up to 2x slower when another process
// runs there (docs/notes/engine.md), so automatic means: two threads only on an idle core.
bool secondCoreIdle();

// Calls body(begin, end) on disjoint sub-ranges of [begin, end) covering it, in parallel.
// grain: smallest chunk worth a thread.
void parallelFor(int64_t begin, int64_t end, const std::function<void(int64_t, int64_t)>& body, int64_t grain = 1);

}  // namespace vs
