#pragma once
// Frames -> scans. Collects the frame slots of one scan, emits it when complete (stamped
// with the completing frame's receive time) or, marked partial, when its timeout passes or
// the next scan begins. Decodes, checks, calibrates (SI units) and tares; counts every kind
// of bad frame in BadFrameCounters.
//
// How a new scan is recognised
//   - With a scan_counter in the profile: a different counter value starts a new scan; a
//     counter that is behind (by less than half its range) marks a stale frame.
//   - Without one: a slot that already arrived in the current scan starts a new scan, unless
//     its payload is identical and it came within half a scan period (then it is a duplicate);
//     so does an idle gap of more than half a scan period since the scan's last frame.
//   Slots may arrive in any order within a scan (counted as `reordered`, still used).
//
// Calibration: value = (raw - baseline) * scale_per_count[axis] * taxel_gain[taxel], in the
// profile's unit, then converted to Pa (N is divided by the taxel area). The baseline is the
// profile's offset_counts until a tare has completed; a tare averages the raw readings of N
// consecutive "quiet" scans (complete, all taxels valid, every channel within
// quiet_tolerance_counts of the first of them).

#include <cstdint>
#include <string>
#include <vector>

#include "sensors/bad_frame_counters.h"
#include "sensors/can_frame.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"
#include "sensors/taxel_codec.h"

namespace sedbridge::sensors {

struct AssemblerOptions {
  /// Tare automatically from the first `tare_scans` quiet scans (0 = no automatic tare).
  int tare_scans = 0;
  /// Largest raw change still "quiet" during a tare [counts]; <= 0 picks 2% of the range.
  double quiet_tolerance_counts = 0;
  /// Only frames from this interface ("can0") are this sensor's; others are counted in
  /// other_interface and ignored. "" = any interface (one bus only, e.g. a SocketCAN socket
  /// bound to one interface).
  std::string interface;
};

class ScanAssembler {
 public:
  /// Keeps a copy of `profile` (which must pass ValidateProfile).
  explicit ScanAssembler(const SensorProfile& profile, AssemblerOptions options = {});

  /// Feeds one frame (any frame from the bus; foreign ones are counted and ignored). Scans
  /// finished by it (a partial one and/or a complete one) are appended to `out`.
  void Push(const Frame& frame, std::vector<Scan>* out);
  /// Emits the scan in progress as partial if it began more than the profile's
  /// partial_timeout before `now_utime`. Call it when the source times out.
  void Poll(int64_t now_utime, std::vector<Scan>* out);
  /// Emits the scan in progress, if any, as partial (end of a log).
  void Flush(std::vector<Scan>* out);

  /// Starts a tare over the next `scans` quiet scans (replaces the baseline when done).
  void RequestTare(int scans);
  bool tared() const { return tared_; }
  bool tare_in_progress() const { return tare_wanted_ > 0; }
  /// Current baseline per channel [counts].
  const std::vector<double>& baseline_counts() const { return baseline_; }

  const BadFrameCounters& counters() const { return counters_; }
  const SensorProfile& profile() const { return profile_; }
  const TaxelCodec& codec() const { return codec_; }

 private:
  void StartScan(const DecodedFrame& d, int64_t utime);
  void Emit(bool complete, std::vector<Scan>* out);
  void Calibrate(Scan* scan);
  void TrackBusState(const Frame& error_frame);
  void UpdateTare(const Scan& scan);

  SensorProfile profile_;
  TaxelCodec codec_;
  AssemblerOptions options_;
  int64_t half_period_us_;

  // Scan in progress.
  bool active_ = false;
  int64_t first_utime_ = 0, last_utime_ = 0, counter_ = -1;
  int received_ = 0, max_slot_ = -1;
  std::vector<uint8_t> slot_received_;
  // Last frame seen per slot (kept across scans, for duplicate detection).
  std::vector<Frame> slot_frame_;
  std::vector<uint8_t> slot_seen_;
  std::vector<int64_t> slot_counter_;

  // Latest raw reading per channel and whether one ever arrived.
  std::vector<int32_t> raw_;
  std::vector<uint8_t> raw_known_;
  std::vector<int32_t> previous_raw_;
  std::vector<int> same_count_;

  int64_t sequence_ = 0;
  bool have_last_counter_ = false;
  int64_t last_counter_ = 0;
  bool emitted_any_ = false;
  int64_t last_emitted_utime_ = 0;

  // Tare.
  std::vector<double> baseline_;
  bool tared_ = false;
  int tare_wanted_ = 0;
  int tare_collected_ = 0;
  std::vector<double> tare_sum_;
  std::vector<int32_t> tare_reference_;
  double quiet_tolerance_;

  BadFrameCounters counters_;
};

}  // namespace sedbridge::sensors
