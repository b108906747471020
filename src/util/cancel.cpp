#include "util/cancel.h"

#include <unistd.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <string>

namespace vs {

namespace {

std::atomic<bool> gCancel{false};
static_assert(std::atomic<bool>::is_always_lock_free, "signal handlers need a lock-free flag");

// Fixed storage: no allocation, readable from a signal handler. A slot is claimed with a
// compare-exchange on `state` (0 free, 1 being written, 2 ready to read).
constexpr int kSlots = 64;
constexpr size_t kPathMax = 4096;
struct Slot {
  std::atomic<int> state{0};
  char path[kPathMax];
};
Slot gSlots[kSlots];

}  // namespace

void requestGlobalCancel() noexcept { gCancel.store(true, std::memory_order_relaxed); }
bool globalCancelRequested() noexcept { return gCancel.load(std::memory_order_relaxed); }
void clearGlobalCancel() noexcept { gCancel.store(false, std::memory_order_relaxed); }

int registerTemporary(const char* path) noexcept {
  const size_t n = std::strlen(path);
  if (n >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (gSlots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(gSlots[i].path, path, n + 1);
      gSlots[i].state.store(2, std::memory_order_release);
      return i;
    }
  }
  return -1;
}

void unregisterTemporary(int slot) noexcept {
  if (slot >= 0 && slot < kSlots) gSlots[slot].state.store(0, std::memory_order_release);
}

size_t unlinkRegisteredTemporaries() noexcept {
  size_t removed = 0;
  for (auto& s : gSlots)
    if (s.state.load(std::memory_order_acquire) == 2 && ::unlink(s.path) == 0) ++removed;
  return removed;
}

void removeRegisteredTemporaries() noexcept {
  namespace fs = std::filesystem;
  for (auto& s : gSlots) {
    if (s.state.load(std::memory_order_acquire) != 2) continue;
    std::error_code ec;
    const fs::path p(s.path);
    const std::string dir = p.parent_path().filename().string();
    if (dir.rfind(".vs_out_", 0) == 0 || dir.rfind(".vs_tmp_", 0) == 0)
      fs::remove_all(p.parent_path(), ec);
    else
      fs::remove(p, ec);
  }
}

}  // namespace vs
