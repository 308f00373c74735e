#include "app/stop_signals.h"

#include <cstdio>
#include <stdexcept>

namespace sedbridge::app {
namespace {

// Lock-free atomics and sig_atomic_t: the only state a handler may touch.
std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;
std::atomic<bool> g_installed{false};

extern "C" void OnStopSignal(int sig) {
  if (g_signal == 0) g_signal = sig;
  g_stop.store(true);
}

}  // namespace

StopSignals::StopSignals() {
  if (g_installed.exchange(true)) throw std::logic_error("StopSignals: only one may exist at a time");
  g_stop.store(false);
  g_signal = 0;
  struct sigaction sa {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  // SA_RESTART: a thread's read or poll must not fail with EINTR; every loop that watches
  // the flag waits with a bounded timeout instead.
  sa.sa_flags = SA_RESTART;
  for (int i = 0; i < 4; ++i) sigaction(kSignals[i], &sa, &previous_[i]);
}

StopSignals::~StopSignals() {
  for (int i = 0; i < 4; ++i) sigaction(kSignals[i], &previous_[i], nullptr);
  g_installed.store(false);
}

const std::atomic<bool>& StopSignals::flag() const { return g_stop; }
void StopSignals::RequestStop() { g_stop.store(true); }
int StopSignals::signal_number() const { return static_cast<int>(g_signal); }
int StopSignals::ExitCode(int normal) const { return g_signal ? 128 + static_cast<int>(g_signal) : normal; }

const char* SignalName(int signal_number) {
  switch (signal_number) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGQUIT: return "SIGQUIT";
    default: return "signal";
  }
}

}  // namespace sedbridge::app
