#include "bridge/fingers.h"

#include <cctype>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <tuple>

#include "common/yaml_reader.h"

namespace sedbridge::bridge {
namespace {

// [A-Za-z][A-Za-z0-9]*(_[A-Za-z0-9]+)*: upper-cased it is an UPPER_SNAKE channel suffix.
bool IsFingerName(const std::string& name) {
  if (name.empty() || !std::isalpha(static_cast<unsigned char>(name.front())) || name.back() == '_') return false;
  for (size_t i = 0; i < name.size(); ++i) {
    const unsigned char ch = static_cast<unsigned char>(name[i]);
    if (!(std::isalnum(ch) || ch == '_') || (ch == '_' && name[i - 1] == '_')) return false;
  }
  return true;
}

std::string Hex(uint32_t id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%X", id);
  return buf;
}

lcm_io::LcmChannels Suffixed(lcm_io::LcmChannels c, const std::string& suffix) {
  for (std::string* channel : {&c.tactile_scan, &c.sed, &c.command, &c.status, &c.sa1_rate, &c.contact, &c.rendering})
    *channel += suffix;
  return c;
}

}  // namespace

std::string FingerChannelSuffix(const std::string& name) {
  std::string s = "_" + name;
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

void RequireOneFinger(const BridgeConfig& config, const std::string& command) {
  if (config.fingers.empty()) return;
  throw std::runtime_error(config.file + ": 'fingers:' lists " + std::to_string(config.fingers.size()) +
                           " fingers; `sedbridge " + command +
                           "` bridges one finger (a hand runs with `sedbridge replay` or `sedbridge run`)");
}

std::vector<Finger> FingersOf(const BridgeConfig& config) {
  if (config.fingers.empty()) return {Finger{kSingleFingerName, config}};
  std::vector<Finger> fingers;
  for (const FingerConfig& f : config.fingers) {
    Finger finger{f.name, config};
    BridgeConfig& c = finger.config;
    c.fingers.clear();
    if (f.sensor_profile) c.sensor_profile = *f.sensor_profile;
    if (f.can_interface) c.can_interface = *f.can_interface;
    if (f.model) c.model = *f.model;
    if (f.display_profile) c.display_profile = *f.display_profile;
    c.can_id_offset = f.can_id_offset;
    c.lcm.channels = Suffixed(c.lcm.channels, FingerChannelSuffix(f.name));
    fingers.push_back(std::move(finger));
  }
  return fingers;
}

sensors::SensorProfile ShiftCanIds(sensors::SensorProfile profile, int offset) {
  if (offset == 0) return profile;
  const int64_t max = profile.layout.extended_ids ? sensors::kCanExtIdMask : sensors::kCanStdIdMask;
  for (uint32_t& id : profile.layout.ids) {
    const int64_t moved = int64_t(id) + offset;
    if (moved < 0 || moved > max)
      throw std::invalid_argument("sensor.id_offset " + std::to_string(offset) + " moves CAN id " + Hex(id) +
                                  " of profile '" + profile.name + "' out of the " +
                                  (profile.layout.extended_ids ? "29" : "11") + "-bit range");
    id = static_cast<uint32_t>(moved);
  }
  return profile;
}

sensors::SensorProfile LoadFingerSensorProfile(const BridgeConfig& config) {
  return ShiftCanIds(sensors::LoadNamedSensorProfile(config.sensor_profile), config.can_id_offset);
}

void CheckFingers(const BridgeConfig& c, config::MapReader& root) {
  if (c.fingers.empty()) return;
  const YAML::Node list = root.node()["fingers"];
  if (int(c.fingers.size()) > kMaxFingers)
    root.Fail(list, "at most " + std::to_string(kMaxFingers) + " fingers (got " + std::to_string(c.fingers.size()) + ")");
  const std::vector<Finger> fingers = FingersOf(c);
  // (interface, extended, id) -> the finger that claimed it first.
  std::map<std::tuple<std::string, bool, uint32_t>, size_t> claimed;
  for (size_t i = 0; i < fingers.size(); ++i) {
    const YAML::Node entry = list[i];
    const std::string& name = fingers[i].name;
    if (!IsFingerName(name))
      root.Fail(entry["name"], "finger name '" + name + "' must be letters, digits and single '_' (a channel suffix)");
    for (size_t j = 0; j < i; ++j)
      if (fingers[j].name == name) root.Fail(entry["name"], "two fingers are named '" + name + "'");
    sensors::SensorProfile profile;
    try {
      profile = LoadFingerSensorProfile(fingers[i].config);
    } catch (const std::exception& e) {
      root.Fail(entry, "finger '" + name + "': its sensor profile: " + e.what());
    }
    const std::string& bus = fingers[i].config.can_interface;
    for (uint32_t id : profile.layout.ids) {
      const auto [it, fresh] = claimed.emplace(std::make_tuple(bus, profile.layout.extended_ids, id), i);
      if (!fresh)
        root.Fail(entry, "CAN id " + Hex(id) + " on " + bus + " is claimed by two fingers, '" +
                             fingers[it->second].name + "' and '" + name +
                             "' (give one of them its own interface or sensor.id_offset)");
    }
  }
}

}  // namespace sedbridge::bridge
