#include "signals.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>

#include "util/cancel.h"

namespace vs::cli {

namespace {

std::atomic<int> gSignals{0};

void onSignal(int) {
  // Only async-signal-safe calls here: atomics, write(2), unlink(2), _exit(2).
  if (gSignals.fetch_add(1) == 0) {
    vs::requestGlobalCancel();
    static const char msg[] = "\nvolscissors: cancelling (press Ctrl-C again to stop at once)\n";
    (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
    return;
  }
  vs::unlinkRegisteredTemporaries();
  static const char msg[] = "volscissors: cancelled\n";
  (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
  ::_exit(130);
}

}  // namespace

void installSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

}  // namespace vs::cli
