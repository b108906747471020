// Progress reporting and cancellation, one hook for every long operation.
// Operations call report() at coarse granularity (per slice or chunk, never per
// voxel); it is thread-safe and throws vs::Cancelled once cancel() was called.
#pragma once

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

#include "util/cancel.h"

namespace vs {

class Progress {
 public:
  // fraction in [0,1]; stage is a short human-readable label ("features", "search").
  using Callback = std::function<void(double fraction, const std::string& stage)>;

  Progress() = default;
  explicit Progress(Callback cb) : callback_(std::move(cb)) {}

  // Thread-safe; throws Cancelled if cancellation was requested.
  void report(double fraction, const std::string& stage = {}) const;
  // Throws Cancelled if cancellation was requested; cheap enough for inner loops every few thousand items.
  void check() const;
  // Requests cancellation; has no effect on Progress::none(), which is shared by every caller.
  void cancel() {
    if (!inert_) cancelled_.store(true, std::memory_order_relaxed);
  }
  // True once cancel() was called or the process was asked to stop (Ctrl-C, SIGTERM: util/cancel.h).
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed) || globalCancelRequested(); }

  // The default argument of every long operation: reports nothing and no caller can cancel it
  // (one shared instance, so cancel() on it is ignored rather than stopping every later caller);
  // a process-wide cancel (Ctrl-C) still stops it.
  static Progress& none();

 private:
  struct Inert {};
  explicit Progress(Inert) : inert_(true) {}

  Callback callback_;
  std::atomic<bool> cancelled_{false};
  const bool inert_ = false;
  mutable std::mutex mutex_;
};

}  // namespace vs
