#pragma once
// What the view shows at one moment: per finger, the latest message of each bridge channel
// (decoded with the size-safe decoder: the bus and a log are untrusted input) and the
// timelines of force, peak Merkel SED and per-scan latency. Fed event by event, from a log or
// live. Fingers are found from the channel names: a one-finger bridge publishes the plain
// names (TACTILE_SCAN, ...: finger ""), a hand the names with _<FINGER> appended
// (TACTILE_SCAN_THUMB: finger "THUMB"; bridge/fingers.h).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lcm/lcm_channels.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_contact_estimate.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_display_rendering.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"
#include "sedbridge/lcmt_tactile_scan.hpp"

namespace sedbridge::view {

/// One timeline: time since the first event [s] and value, oldest first.
struct Series {
  std::vector<double> t_s, value;
  void Add(double t, double v);
};

/// The bridge's channels, one finger's worth.
enum class ChannelKind { kScan, kContact, kSed, kCommand, kSa1, kStatus, kRendering };

/// One finger's latest messages and timelines.
struct FingerState {
  std::string name;  ///< the channel suffix without its '_' ("THUMB"); "" for the plain names

  bool have_scan = false, have_contact = false, have_sed = false, have_command = false,
       have_sa1 = false, have_status = false, have_rendering = false;
  lcmt_tactile_scan scan;
  lcmt_contact_estimate contact;
  lcmt_merkel_sed sed;
  lcmt_display_command command;
  lcmt_sa1_rate_estimate sa1;
  lcmt_bridge_status status;
  lcmt_display_rendering rendering;  ///< target and delivered SED (inverse rendering only)

  Series force_N;      ///< contact estimate's normal force (+ the second contact's)
  Series peak_sed_Pa;  ///< max_sed_Pa of each SED field
  Series latency_ms;   ///< command utime - the utime of the scan behind it
};

class ViewState {
 public:
  /// Most fingers taken: more names on the bus are ignored (a hand has five; the bridge takes
  /// at most 16), so a bus with many made-up channels cannot grow the view without bound.
  static constexpr std::size_t kMaxFingers = 16;

  explicit ViewState(lcm_io::LcmChannels channels) : channels_(std::move(channels)) {}

  /// Whether `channel` is one of the bridge's (a base name, or a base name + "_" + an
  /// UPPER_SNAKE finger name); if so, its kind and finger name.
  bool Classify(const std::string& channel, ChannelKind* kind, std::string* finger) const;
  /// LCM subscription patterns (regular expressions) for every finger's channels.
  std::vector<std::string> SubscriptionPatterns() const;

  /// Feeds one event at `utime` (the log's or the receive clock) [us]. Other channels are
  /// ignored; returns false when the bytes do not decode as the channel's type (counted).
  bool OnEvent(const std::string& channel, const void* data, std::size_t size, int64_t utime);
  /// Forgets every message and timeline (a seek backwards replays from the start); the
  /// fingers found so far stay, so the page's panels do not come and go.
  void Reset();

  /// The fingers in the order their first message came; nullptr when `name` is not one.
  const FingerState* Finger(const std::string& name) const;
  std::vector<FingerState> fingers;

  int64_t events = 0;    ///< events of the bridge's channels taken
  int64_t rejected = 0;  ///< events whose bytes did not decode
  int64_t ignored_fingers = 0;  ///< events of fingers beyond kMaxFingers
  int64_t first_utime = 0, last_utime = 0;
  /// Bumped by every event taken: a frame is sent only when it changed.
  uint64_t version = 0;

 private:
  double SinceStart_s(int64_t utime) const { return (utime - first_utime) * 1e-6; }
  bool Take(FingerState& f, ChannelKind kind, const void* data, std::size_t size, int64_t utime);
  lcm_io::LcmChannels channels_;
};

}  // namespace sedbridge::view
