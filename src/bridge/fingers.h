#pragma once
// A hand: the fingers one bridge config describes (`fingers:`, config/bridge/README.md).
// Each finger is a BridgeConfig of its own (the bridge's keys with the finger's sensor, bus,
// ids, leader model and display put in), so every stage builds a finger as it builds today's
// one-finger bridge. A config without `fingers:` is one finger named "finger0" whose channels
// keep today's names; with a list, each finger's channels end in _<NAME> (lcm-spy shows one
// row per finger and channel, as Drake names a channel per instance).

#include <string>
#include <vector>

#include "bridge/bridge_config.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::config {
class MapReader;
}

namespace sedbridge::bridge {

/// Most fingers one bridge takes (a hand has five; more is a typo or a second hand).
inline constexpr int kMaxFingers = 16;
/// The name of the one finger of a config without `fingers:`.
inline constexpr char kSingleFingerName[] = "finger0";

struct Finger {
  std::string name;
  BridgeConfig config;  ///< the bridge's keys with the finger's own; its `fingers` empty
};

/// The fingers of `config`: one ("finger0", the config itself) without a list.
std::vector<Finger> FingersOf(const BridgeConfig& config);

/// Throws std::runtime_error, naming `command` and the file, when `config` has a `fingers:`
/// list: for the commands that bridge one finger (simulate, fidelity).
void RequireOneFinger(const BridgeConfig& config, const std::string& command);

/// `name` as a channel suffix: "_" + upper case ("index" -> "_INDEX").
std::string FingerChannelSuffix(const std::string& name);

/// `profile` with every CAN id moved by `offset` (FingerConfig::can_id_offset). Throws
/// std::invalid_argument when an id leaves the profile's 11- or 29-bit range.
sensors::SensorProfile ShiftCanIds(sensors::SensorProfile profile, int offset);

/// The finger's sensor profile: config.sensor_profile loaded, its ids moved by
/// config.can_id_offset.
sensors::SensorProfile LoadFingerSensorProfile(const BridgeConfig& config);

/// Load-time checks of the `fingers:` list of `c` read from `root` (the config's top
/// mapping): names (form, unique), at most kMaxFingers, every sensor profile loads, and no
/// CAN id on one interface claimed by two fingers. Throws config::ConfigError at the
/// offending entry's file:line:column, naming both fingers of a conflict.
void CheckFingers(const BridgeConfig& c, config::MapReader& root);

}  // namespace sedbridge::bridge
