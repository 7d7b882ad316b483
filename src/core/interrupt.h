// Cooperative interruption. SIGINT (Ctrl-C) and SIGTERM only raise a flag; the render loops poll
// it between small units of work (core/budget.h), so the image reached so far is still
// consistent and can be written (marked partial) before the program exits non-zero.
#pragma once

#include <exception>

namespace pl {

// Thrown where an interrupted computation has no partial result worth keeping.
struct Interrupted : std::exception {
  const char* what() const noexcept override { return "interrupted"; }
};

// Installs the SIGINT/SIGTERM handlers. Until setInterruptCooperative(true) (while a scene loads,
// when there is nothing to save) a signal ends the process at once with exit status 128 +
// signal. After it, a signal raises the flag that every render loop polls (core/budget.h), and
// the loops stop within a pixel, a chunk of photon paths or a slice of the kd-tree build; a
// second signal while the first is being honoured ends the process at once, for a user who does
// not want to wait.
void installInterruptHandlers();
void setInterruptCooperative(bool cooperative);

void requestInterrupt();      // what the handlers call; tests call it directly
bool interruptRequested();
int interruptSignal();        // the signal received, or 0 (e.g. requested by a test)
void clearInterrupt();

}  // namespace pl
