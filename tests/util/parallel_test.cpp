// util/parallel: parallelFor covers its range once; secondCoreIdle honours VS_THREADS both ways
// (the automatic two-thread full map asks it: issue 25).
#include "util/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace vs {
namespace {

// Sets VS_THREADS for one scope and restores what was there.
class ThreadsEnv {
 public:
  explicit ThreadsEnv(const char* value) {
    if (const char* old = std::getenv("VS_THREADS")) old_ = old;
    if (value)
      setenv("VS_THREADS", value, 1);
    else
      unsetenv("VS_THREADS");
  }
  ~ThreadsEnv() {
    if (old_)
      setenv("VS_THREADS", old_->c_str(), 1);
    else
      unsetenv("VS_THREADS");
  }

 private:
  std::optional<std::string> old_;
};

TEST(Parallel, ForCoversEachIndexOnce) {
  std::vector<std::atomic<int>> hits(1000);
  parallelFor(0, 1000, [&](int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) hits[size_t(i)]++;
  });
  for (const auto& h : hits) EXPECT_EQ(h.load(), 1);
}

TEST(Parallel, SecondCoreIdleFollowsVsThreads) {
  {
    ThreadsEnv one("1");
    EXPECT_FALSE(secondCoreIdle());
    EXPECT_EQ(workerCount(), 1);
  }
  {
    ThreadsEnv two("2");
    EXPECT_TRUE(secondCoreIdle());
    EXPECT_EQ(workerCount(), 2);
  }
}

TEST(Parallel, SecondCoreBusyWhileAnotherThreadSpinsOnEveryOtherCore) {
  ThreadsEnv automatic(nullptr);
  const unsigned cpus = std::thread::hardware_concurrency();
  if (cpus < 2) GTEST_SKIP() << "one CPU: never two threads";
  // With a spinning thread on every CPU but this one, no core is free besides the caller.
  std::atomic<bool> stop{false};
  std::vector<std::thread> spinners;
  for (unsigned i = 0; i + 1 < cpus; ++i)
    spinners.emplace_back([&] {
      while (!stop.load(std::memory_order_relaxed)) {
      }
    });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const bool idle = secondCoreIdle();
  stop = true;
  for (auto& t : spinners) t.join();
  EXPECT_FALSE(idle);
}

}  // namespace
}  // namespace vs
