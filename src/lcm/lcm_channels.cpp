#include "lcm/lcm_channels.h"

#include <stdexcept>

#include "common/yaml_read_archive.h"

namespace sedbridge::lcm_io {

bool IsUpperSnake(const std::string& name) {
  if (name.empty() || !(name[0] >= 'A' && name[0] <= 'Z') || name.back() == '_') return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok || (c == '_' && name[i - 1] == '_')) return false;
  }
  return true;
}

void LcmChannels::Validate() const {
  for (const std::string* c : {&tactile_scan, &sed, &command, &status, &sa1_rate, &contact, &rendering})
    if (!IsUpperSnake(*c))
      throw std::invalid_argument("LCM channel '" + *c + "' is not UPPER_SNAKE");
}

void CheckChannelNames(const config::MapReader& lcm_section) {
  const YAML::Node channels = lcm_section.node()["channels"];
  if (!channels) return;
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    const std::string name = config::As<std::string>(it->second, lcm_section.file(), it->first.Scalar());
    if (!IsUpperSnake(name)) lcm_section.Fail(it->second, "channel '" + name + "' must be UPPER_SNAKE");
  }
}

LcmSettings ParseLcmSettings(config::MapReader& r) {
  LcmSettings s;
  config::ReadYaml(r, &s);
  CheckChannelNames(r);
  return s;
}

}  // namespace sedbridge::lcm_io
