#include "view/view_state.h"

#include <utility>

#include "display/command_authenticator.h"
#include "lcm/lcm_safe_decode.h"

namespace sedbridge::view {
namespace {

// A live timeline keeps at most this many points: the oldest half goes when it is full.
constexpr std::size_t kMaxSeriesPoints = 20000;

std::vector<std::pair<ChannelKind, const std::string*>> Bases(const lcm_io::LcmChannels& c) {
  return {{ChannelKind::kScan, &c.tactile_scan}, {ChannelKind::kContact, &c.contact}, {ChannelKind::kSed, &c.sed},
          {ChannelKind::kCommand, &c.command},   {ChannelKind::kSa1, &c.sa1_rate},    {ChannelKind::kStatus, &c.status},
          {ChannelKind::kRendering, &c.rendering}};
}

}  // namespace

void Series::Add(double t, double v) {
  if (t_s.size() >= kMaxSeriesPoints) {
    t_s.erase(t_s.begin(), t_s.begin() + kMaxSeriesPoints / 2);
    value.erase(value.begin(), value.begin() + kMaxSeriesPoints / 2);
  }
  t_s.push_back(t);
  value.push_back(v);
}

bool ViewState::Classify(const std::string& channel, ChannelKind* kind, std::string* finger) const {
  std::size_t best = 0;
  for (const auto& [k, base] : Bases(channels_)) {
    // The longest base that fits, should two configured names share a prefix.
    if (base->size() <= best || channel.compare(0, base->size(), *base) != 0) continue;
    if (channel.size() == base->size()) {
      *kind = k, *finger = "", best = base->size();
    } else if (channel[base->size()] == '_' && lcm_io::IsUpperSnake(channel.substr(base->size() + 1))) {
      *kind = k, *finger = channel.substr(base->size() + 1), best = base->size();
    }
  }
  return best > 0;
}

std::vector<std::string> ViewState::SubscriptionPatterns() const {
  std::vector<std::string> patterns;
  // LCM anchors a subscription's regular expression at both ends; Classify checks the rest.
  for (const auto& [k, base] : Bases(channels_)) patterns.push_back(*base + "(_[A-Z0-9_]+)?");
  return patterns;
}

const FingerState* ViewState::Finger(const std::string& name) const {
  for (const FingerState& f : fingers)
    if (f.name == name) return &f;
  return nullptr;
}

void ViewState::Reset() {
  // The messages stay as they are, hidden behind have_*: nothing reads them until replaced.
  for (FingerState& f : fingers) {
    f.have_scan = f.have_contact = f.have_sed = f.have_command = f.have_sa1 = f.have_status = f.have_rendering = false;
    f.force_N = f.peak_sed_Pa = f.latency_ms = Series{};
  }
  events = rejected = ignored_fingers = first_utime = last_utime = 0;
  ++version;
}

bool ViewState::OnEvent(const std::string& channel, const void* data, std::size_t size, int64_t utime) {
  ChannelKind kind;
  std::string name;
  if (!Classify(channel, &kind, &name)) return true;
  FingerState* f = nullptr;
  for (FingerState& g : fingers)
    if (g.name == name) f = &g;
  const bool added = f == nullptr;
  if (added) {
    if (fingers.size() >= kMaxFingers) {
      ++ignored_fingers;
      return true;
    }
    fingers.emplace_back().name = name;
    f = &fingers.back();
  }
  if (!Take(*f, kind, data, size, utime)) {
    if (added) fingers.pop_back();  // a finger is one that sent a message that decodes
    ++rejected;
    return false;
  }
  if (first_utime == 0) first_utime = utime;
  last_utime = utime;
  ++events;
  ++version;
  return true;
}

bool ViewState::Take(FingerState& f, ChannelKind kind, const void* data, std::size_t size, int64_t utime) {
  using lcm_io::SafeDecode;
  switch (kind) {
    case ChannelKind::kScan:
      if (!SafeDecode(data, size, &f.scan)) return false;
      return f.have_scan = true;
    case ChannelKind::kContact:
      if (!SafeDecode(data, size, &f.contact)) return false;
      f.have_contact = true;
      if (first_utime == 0) first_utime = utime;
      f.force_N.Add(SinceStart_s(utime), double(f.contact.normal_force_N) + double(f.contact.normal_force2_N));
      return true;
    case ChannelKind::kSed:
      if (!SafeDecode(data, size, &f.sed)) return false;
      f.have_sed = true;
      if (first_utime == 0) first_utime = utime;
      f.peak_sed_Pa.Add(SinceStart_s(utime), f.sed.max_sed_Pa);
      return true;
    case ChannelKind::kCommand:
      // A signed command is payload || HMAC tag; the view checks nothing, it only shows.
      if (!SafeDecode(data, size, &f.command) &&
          !(size > display::CommandAuthenticator::kTagBytes &&
            SafeDecode(data, size - display::CommandAuthenticator::kTagBytes, &f.command)))
        return false;
      f.have_command = true;
      if (first_utime == 0) first_utime = utime;
      if (f.command.source_scan_utime > 0 && !f.command.shutdown)
        f.latency_ms.Add(SinceStart_s(utime), (f.command.utime - f.command.source_scan_utime) * 1e-3);
      return true;
    case ChannelKind::kSa1:
      if (!SafeDecode(data, size, &f.sa1)) return false;
      return f.have_sa1 = true;
    case ChannelKind::kStatus:
      if (!SafeDecode(data, size, &f.status)) return false;
      return f.have_status = true;
    case ChannelKind::kRendering:
      if (!SafeDecode(data, size, &f.rendering)) return false;
      return f.have_rendering = true;
  }
  return false;
}

}  // namespace sedbridge::view
