#include "util/parallel.h"

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace vs {

int workerCount() {
  if (const char* env = std::getenv("VS_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n;
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

void parallelFor(int64_t begin, int64_t end, const std::function<void(int64_t, int64_t)>& body, int64_t grain) {
  const int64_t n = end - begin;
  if (n <= 0) return;
  const int64_t maxThreads = std::max<int64_t>(1, n / std::max<int64_t>(1, grain));
  const int threads = static_cast<int>(std::min<int64_t>(workerCount(), maxThreads));
  if (threads <= 1) {
    body(begin, end);
    return;
  }
  std::exception_ptr error;
  std::mutex errorMutex;
  std::vector<std::thread> pool;
  pool.reserve(threads);
  for (int t = 0; t < threads; ++t) {
    const int64_t b = begin + n * t / threads;
    const int64_t e = begin + n * (t + 1) / threads;
    pool.emplace_back([&, b, e] {
      try {
        body(b, e);
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (!error) error = std::current_exception();
      }
    });
  }
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace vs
