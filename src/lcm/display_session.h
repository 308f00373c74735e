#pragma once
// display::DisplayController wired to LCM: what the bridge's real-time loop owns on the leader side.
// Guarantees a zero command on the way out (Shutdown() or destruction).

#include <cstdint>

#include "common/stage_times.h"
#include "common/wall_clock.h"
#include "display/display_controller.h"
#include "display/sa1_rate_estimate.h"
#include "lcm/lcm_channels.h"
#include "lcm/lcm_publisher.h"

namespace sedbridge::lcm_io {

struct DisplaySessionOptions {
  bool publish_sed = true;        ///< also publish fields on channels.sed (for viewers, logs)
  /// At most this many SED fields per second on channels.sed (0 = every field). A Merkel
  /// layer of ~1000 vertices is ~16 kB a message; at a 1 kHz FE rate that would be 16 MB/s.
  double sed_max_rate_Hz = 50;
  bool publish_sa1_rate = false;  ///< also publish the SA1 rate ESTIMATE on channels.sa1_rate
  display::Sa1RateParams sa1;
  /// The controller's request source (display/command_request_source.h); empty: the curve.
  display::CommandRequestSource requests;
};

///   DisplaySession display(LoadDisplayProfile(path), settings);   // settings from `lcm:` YAML
///   each FE step:          display.OnSedField(field, WallClockUtime());
///   each idle period:      display.Tick(WallClockUtime());          // keeps the watchdog honest
///   on exit (or by dtor):  display.Shutdown(WallClockUtime());      // publishes all zeros
class DisplaySession {
 public:
  static constexpr int kShutdownRepeats = 3;

  /// Throws std::runtime_error (LCM/log cannot open), std::invalid_argument (bad limits or
  /// channel names).
  DisplaySession(display::DisplayProfile profile, const LcmSettings& settings,
                 DisplaySessionOptions options = {});
  ~DisplaySession();  ///< Shutdown(WallClockUtime()) unless already shut down; never throws
  DisplaySession(const DisplaySession&) = delete;
  DisplaySession& operator=(const DisplaySession&) = delete;

  const display::DisplayCommand& OnSedField(const display::SedField& field, int64_t now_utime);
  const display::DisplayCommand& Tick(int64_t now_utime);
  /// Publishes the all-zero shutdown command kShutdownRepeats times (consecutive sequence
  /// numbers, same utime); again if called twice.
  const display::DisplayCommand& Shutdown(int64_t now_utime);

  display::DisplayController& controller() { return controller_; }
  const display::DisplayController& controller() const { return controller_; }
  LcmPublisher& publisher() { return publisher_; }
  const LcmPublisher& publisher() const { return publisher_; }
  const display::DisplayCommand& last_command() const { return last_; }
  /// Wall time of the last OnSedField: mapping and safety limiter (kLimiter), LCM
  /// publishing of the field, command and SA1 rates (kPublish).
  const StageTimes& last_stage_ms() const { return stage_ms_; }

 private:
  display::DisplayController controller_;
  LcmPublisher publisher_;
  DisplaySessionOptions options_;
  display::DisplayCommand last_;
  StageTimes stage_ms_;
  bool shut_down_ = false;
  bool sed_published_ = false;
  int64_t last_sed_publish_utime_ = 0;
};

}  // namespace sedbridge::lcm_io
