#include "sensors/frame_router.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace sedbridge::sensors {

void FrameRouter::Claim(int index, const std::string& name, const std::string& interface,
                        const SensorProfile& profile) {
  for (uint32_t id : profile.layout.ids) {
    const auto key = std::make_tuple(interface, profile.layout.extended_ids, id);
    const auto [it, fresh] = names_.emplace(key, name);
    if (!fresh) {
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%X", id);
      throw std::invalid_argument("CAN id " + std::string(hex) + " on " + interface + " is claimed by two sensors, '" +
                                  it->second + "' and '" + name + "'");
    }
    by_id_[key] = index;
  }
  std::vector<int>& on_bus = by_interface_[interface];
  if (std::find(on_bus.begin(), on_bus.end(), index) == on_bus.end()) on_bus.push_back(index);
}

const std::vector<int>& FrameRouter::Route(const Frame& frame) {
  routed_.clear();
  const std::string bus = frame.Interface();
  if (frame.error) {
    const auto it = by_interface_.find(bus);
    if (it != by_interface_.end()) routed_ = it->second;
  } else {
    const auto it = by_id_.find(std::make_tuple(bus, frame.extended, frame.id));
    if (it != by_id_.end()) routed_.push_back(it->second);
  }
  if (routed_.empty()) {
    // Bounded: a corrupt log cannot grow the map without end.
    const bool known = unclaimed_.count(bus) > 0 || unclaimed_.size() < kMaxInterfaces;
    ++unclaimed_[known ? bus : "other"];
  }
  return routed_;
}

int64_t FrameRouter::unclaimed_total() const {
  int64_t n = 0;
  for (const auto& [bus, count] : unclaimed_) n += count;
  return n;
}

}  // namespace sedbridge::sensors
