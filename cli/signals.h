// Ctrl-C and SIGTERM for the command line: the first signal asks every running operation
// to stop (vs::requestGlobalCancel, polled by vs::Progress); the command unwinds through
// vs::Cancelled, its temporaries are removed, and main exits with status 130. A second
// signal (the operation did not reach a check point soon enough) unlinks the registered
// temporaries and exits 130 at once; so does a watchdog thread one second after the first
// signal if the command is still running (a step that never polls).
#pragma once

namespace vs::cli {

void installSignalHandlers();

}  // namespace vs::cli
