#pragma once
// Turns the signals that ask a process to end into a stop flag, so every command that drives
// the display leaves through its normal path: zero published, LCM log closed.
//
//   StopSignals signals;                      // SIGINT, SIGTERM, SIGHUP, SIGQUIT
//   while (!signals.flag().load()) ...        // or hand &signals.flag() to the loop
//   return signals.ExitCode(0);               // 128 + signal if one arrived
//
// Only one StopSignals may exist at a time (the handler has one flag to set). SIGKILL cannot
// be caught: the leader-side driver's own watchdog covers that case (display/README.md).

#include <atomic>
#include <csignal>

namespace sedbridge::app {

class StopSignals {
 public:
  /// Installs the handlers; the previous dispositions are restored by the destructor.
  /// Throws std::logic_error if another StopSignals is alive.
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// Set (and never cleared) by the first of the signals, or by RequestStop().
  const std::atomic<bool>& flag() const;
  /// For a duration timer or an error path: same effect as a signal, without a signal number.
  void RequestStop();
  /// The signal that stopped the process, 0 if none.
  int signal_number() const;
  /// 128 + signal_number() when a signal arrived (the shell's convention), else `normal`.
  int ExitCode(int normal) const;

  /// The signals handled, for messages and tests.
  static constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

 private:
  struct sigaction previous_[4];
};

/// "SIGINT", "SIGTERM", ... ("signal N" for others).
const char* SignalName(int signal_number);

}  // namespace sedbridge::app
