#pragma once
// Plays LCM event logs into a ViewState on the logs' own clock: play, pause, seek, speed.
// Several logs play as one, their events merged by time (a hand's replay writes one log a
// finger, on the one clock of the CAN log it replayed). The events of the bridge's channels
// are read into memory once (a session's log is small next to the machine), so a seek
// backwards replays from the start without reopening the files.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "view/view_state.h"

namespace sedbridge::view {

class LogPlayer {
 public:
  /// Which channels to read (ViewState::Classify: every finger's).
  using ChannelFilter = std::function<bool(const std::string& channel)>;
  /// Reads the events of the channels `keep` takes from `paths`. Throws std::runtime_error when
  /// a log cannot be opened or none holds any of them.
  LogPlayer(const std::vector<std::string>& paths, const ChannelFilter& keep);

  double duration_s() const { return duration_s_; }
  double position_s() const { return position_s_; }
  bool playing() const { return playing_; }
  double speed() const { return speed_; }
  std::size_t num_events() const { return events_.size(); }

  void SetPlaying(bool playing) { playing_ = playing; }
  /// Speed factor on the log's clock, clamped to [0.01, 100].
  void SetSpeed(double speed);
  /// Moves to `t_s` (clamped to the log) and brings `state` to what it was then.
  void Seek(double t_s, ViewState* state);
  /// Moves forward by `wall_s` * speed while playing, feeding the events passed; stops
  /// (pauses) at the end.
  void Advance(double wall_s, ViewState* state);
  /// The largest max_sed_Pa of the log's SED events on the channels `is_sed` takes [Pa]; 0
  /// when none.
  double LargestSed_Pa(const ChannelFilter& is_sed) const;
  /// The model_id of the first SED field on each channel `is_sed` takes, without repeats.
  std::vector<std::string> SedModels(const ChannelFilter& is_sed) const;

 private:
  struct Event {
    int64_t utime;
    std::string channel;
    std::vector<uint8_t> data;
  };
  void FeedUpTo(double t_s, ViewState* state);
  std::vector<Event> events_;
  std::size_t next_ = 0;  ///< first event not yet fed
  int64_t start_utime_ = 0;
  double duration_s_ = 0, position_s_ = 0, speed_ = 1;
  bool playing_ = false;
};

}  // namespace sedbridge::view
