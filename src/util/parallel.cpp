#include "util/parallel.h"

#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <mutex>
#include <string>
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

namespace {

// Tasks in the running state, system-wide (the caller included), or -1 when unknown.
int runnableTasks() {
  std::ifstream stat("/proc/stat");
  std::string line;
  while (std::getline(stat, line))
    if (line.rfind("procs_running ", 0) == 0) return std::atoi(line.c_str() + std::strlen("procs_running "));
  return -1;
}

int allowedCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return 1;
  return CPU_COUNT(&set);
}

}  // namespace

bool secondCoreIdle() {
  if (const char* env = std::getenv("VS_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n >= 2;
  }
  const int cpus = std::min<int>(allowedCpus(), static_cast<int>(std::thread::hardware_concurrency()));
  if (cpus < 2) return false;
  // Five samples, one busy one forgiven: a task that runs for a moment (a kernel worker, the shell
  // that started us) made one sample in three say "busy" often enough to send a fresh process's map
  // to one thread now and then, the largest part of the full map's run-to-run spread.
  int busy = 0;
  for (int sample = 0; sample < 5; ++sample) {
    if (sample > 0) std::this_thread::sleep_for(std::chrono::microseconds(500));
    const int running = runnableTasks();
    if (running < 1) return false;
    if (running > cpus - 1 && ++busy > 1) return false;
  }
  return true;
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
