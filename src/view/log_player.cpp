#include "view/log_player.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "lcm/lcm_log_reader.h"
#include "sedbridge/lcmt_merkel_sed.hpp"

namespace sedbridge::view {

LogPlayer::LogPlayer(const std::vector<std::string>& paths, const ChannelFilter& keep) {
  for (const std::string& path : paths) {
    lcm_io::LcmLogReader reader(path);
    while (const lcm::LogEvent* e = reader.Next()) {
      if (e->datalen < 0 || !keep(e->channel)) continue;
      const auto* bytes = static_cast<const uint8_t*>(e->data);
      events_.push_back({e->timestamp, e->channel, std::vector<uint8_t>(bytes, bytes + e->datalen)});
    }
  }
  if (events_.empty())
    throw std::runtime_error((paths.size() == 1 ? paths[0] : std::to_string(paths.size()) + " logs") +
                             " hold no event of the bridge's channels");
  // lcm-logger writes in receive order; a hand-made log may not be sorted, and several logs
  // interleave.
  std::stable_sort(events_.begin(), events_.end(), [](const Event& a, const Event& b) { return a.utime < b.utime; });
  start_utime_ = events_.front().utime;
  duration_s_ = (events_.back().utime - start_utime_) * 1e-6;
}

void LogPlayer::SetSpeed(double speed) {
  if (std::isfinite(speed)) speed_ = std::clamp(speed, 0.01, 100.0);
}

void LogPlayer::FeedUpTo(double t_s, ViewState* state) {
  while (next_ < events_.size() && (events_[next_].utime - start_utime_) * 1e-6 <= t_s) {
    const Event& e = events_[next_++];
    state->OnEvent(e.channel, e.data.data(), e.data.size(), e.utime);
  }
}

void LogPlayer::Seek(double t_s, ViewState* state) {
  if (!std::isfinite(t_s)) return;
  t_s = std::clamp(t_s, 0.0, duration_s_);
  if (t_s < position_s_ || next_ == 0) {
    state->Reset();
    next_ = 0;
  }
  position_s_ = t_s;
  FeedUpTo(t_s, state);
}

void LogPlayer::Advance(double wall_s, ViewState* state) {
  if (!playing_) return;
  position_s_ = std::min(duration_s_, position_s_ + wall_s * speed_);
  FeedUpTo(position_s_, state);
  if (position_s_ >= duration_s_) playing_ = false;
}

double LogPlayer::LargestSed_Pa(const ChannelFilter& is_sed) const {
  double largest = 0;
  for (const Event& e : events_) {
    if (!is_sed(e.channel)) continue;
    lcmt_merkel_sed m;
    if (lcm_io::SafeDecode(e.data.data(), e.data.size(), &m) && std::isfinite(m.max_sed_Pa))
      largest = std::max(largest, double(m.max_sed_Pa));
  }
  return largest;
}

std::vector<std::string> LogPlayer::SedModels(const ChannelFilter& is_sed) const {
  std::set<std::string> seen_channels;
  std::vector<std::string> models;
  for (const Event& e : events_) {
    if (seen_channels.count(e.channel) || !is_sed(e.channel)) continue;
    lcmt_merkel_sed m;
    if (!lcm_io::SafeDecode(e.data.data(), e.data.size(), &m)) continue;
    seen_channels.insert(e.channel);
    if (std::find(models.begin(), models.end(), m.model_id) == models.end()) models.push_back(m.model_id);
  }
  return models;
}

}  // namespace sedbridge::view
