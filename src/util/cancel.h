// Process-wide cancellation for Ctrl-C / SIGTERM. A signal handler may only touch
// lock-free atomics, so it sets one flag here; every vs::Progress polls it (see
// Progress::cancelled), so a long operation stops at its next report/check and unwinds
// through vs::Cancelled, removing its temporaries on the way.
// Temporaries being written are also listed in a fixed table the handler can read, so a
// second signal (the user insisting) can unlink them with async-signal-safe calls and exit
// at once.
#pragma once

#include <cstddef>

namespace vs {

// Async-signal-safe.
void requestGlobalCancel() noexcept;
bool globalCancelRequested() noexcept;
// For tests and for a front end that keeps running after a cancelled operation.
void clearGlobalCancel() noexcept;

// Registers a temporary file path for emergency removal; returns a slot (or -1 when the
// table is full, in which case only the normal unwinding removes it).
int registerTemporary(const char* path) noexcept;
void unregisterTemporary(int slot) noexcept;
// Async-signal-safe: unlink(2) every registered temporary. Returns how many were removed.
size_t unlinkRegisteredTemporaries() noexcept;
// Not signal-safe (call from a thread): unlinks every registered temporary and, when it sits
// in a private temporary folder (".vs_out_*", ".vs_tmp_*"), that folder with what it holds.
void removeRegisteredTemporaries() noexcept;

}  // namespace vs
