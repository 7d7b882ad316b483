// Cooperative interruption. SIGINT (Ctrl-C) and SIGTERM only raise a flag; the render loops poll
// it at sample-pass and photon-pass boundaries, so the image reached so far is still consistent
// and can be written (marked partial) before the program exits non-zero.
#pragma once

#include <exception>

namespace pl {

// Thrown where an interrupted computation has no partial result worth keeping.
struct Interrupted : std::exception {
  const char* what() const noexcept override { return "interrupted"; }
};

// Installs the SIGINT/SIGTERM handlers. A second signal while the first is being honoured ends
// the process at once (exit status 128 + signal), for a user who does not want to wait.
void installInterruptHandlers();

void requestInterrupt();      // what the handlers call; tests call it directly
bool interruptRequested();
int interruptSignal();        // the signal received, or 0 (e.g. requested by a test)
void clearInterrupt();

}  // namespace pl
