#include "host/cli/stop_signals.h"

#include <iterator>

namespace wp {

namespace {

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
volatile std::sig_atomic_t g_armed = 0;
volatile std::sig_atomic_t g_received = 0;
struct sigaction g_previous[std::size(kSignals)];

// Async-signal-safe: it only writes sig_atomic_t flags, or re-raises with the default action.
extern "C" void on_stop_signal(int sig) {
  if (g_armed && g_received == 0) {
    g_received = sig;
    return;
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);  // delivered when the handler returns
}

}  // namespace

StopSignals::StopSignals() {
  g_armed = 0;
  g_received = 0;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  action.sa_flags = SA_RESTART;  // the OpenCL runtime's blocking calls go on
  sigemptyset(&action.sa_mask);
  for (const int sig : kSignals) sigaddset(&action.sa_mask, sig);  // one handler at a time
  for (std::size_t i = 0; i < std::size(kSignals); ++i)
    sigaction(kSignals[i], &action, &g_previous[i]);
}

StopSignals::~StopSignals() {
  for (std::size_t i = 0; i < std::size(kSignals); ++i)
    sigaction(kSignals[i], &g_previous[i], nullptr);
  g_armed = 0;
}

void StopSignals::arm() {
  g_armed = 1;
}

int StopSignals::received() const {
  return g_received;
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

}  // namespace wp
