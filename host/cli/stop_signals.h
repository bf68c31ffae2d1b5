// SIGINT, SIGTERM and SIGHUP during a render: before its sample passes they end the process at
// once (nothing has been written yet, and nothing would be lost but time); while the passes run,
// the first one is only recorded, so that the render stops at the end of the current pass and
// writes the image so far (and its checkpoint); a second one ends the process at once.
#pragma once

#include <csignal>

namespace wp {

class StopSignals {
 public:
  // Installs the handler for SIGINT, SIGTERM and SIGHUP, in its "end at once" mode.
  StopSignals();
  // Restores the handlers there were before.
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // From now on the first signal is recorded instead of ending the process.
  void arm();
  // The signal recorded since arm(), or 0.
  int received() const;
};

// "SIGINT", "SIGTERM", "SIGHUP", else "a signal".
const char* signal_name(int sig);

}  // namespace wp
