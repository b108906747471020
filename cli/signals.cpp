#include "signals.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

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

// The first signal asks every loop to stop at its next progress check; most commands unwind
// within milliseconds. A loop that never polls (inside ITK, VTK, a library call, or one we
// missed) must not make the first signal useless: one second after it, this thread removes
// the registered temporaries and ends the process with 130, as a second signal would.
void watchdog() {
  using namespace std::chrono_literals;
  while (!vs::globalCancelRequested()) std::this_thread::sleep_for(20ms);
  std::this_thread::sleep_for(800ms);
  vs::removeRegisteredTemporaries();
  static const char msg[] = "volscissors: cancelled (the running step did not stop within a second)\n";
  (void)!::write(STDERR_FILENO, msg, sizeof msg - 1);
  ::_exit(130);
}

}  // namespace

void installSignalHandlers() {
  std::thread(watchdog).detach();
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

}  // namespace vs::cli
