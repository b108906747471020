#include "util/progress.h"

#include "util/error.h"

namespace vs {

void Progress::report(double fraction, const std::string& stage) const {
  check();
  if (callback_) {
    std::lock_guard<std::mutex> lock(mutex_);
    callback_(fraction, stage);
  }
}

void Progress::check() const {
  if (cancelled()) throw Cancelled();
}

Progress& Progress::none() {
  static Progress inert{Inert{}};
  return inert;
}

}  // namespace vs
