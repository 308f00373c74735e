#include "lcm/lcm_channels.h"

#include <stdexcept>

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
  for (const std::string* c : {&tactile_scan, &sed, &command, &status, &sa1_rate, &contact})
    if (!IsUpperSnake(*c))
      throw std::invalid_argument("LCM channel '" + *c + "' is not UPPER_SNAKE");
}

LcmSettings ParseLcmSettings(config::MapReader& r) {
  LcmSettings s;
  s.url = r.Optional<std::string>("url", s.url);
  s.log_path = r.Optional<std::string>("log", "");
  s.auth_key_file = r.Optional<std::string>("auth_key_file", "");
  if (r.Has("channels")) {
    config::MapReader c = r.Child("channels");
    auto read = [&c](const char* key, std::string& out) {
      if (!c.Has(key)) {
        c.Optional<std::string>(key, out);
        return;
      }
      YAML::Node v = c.Node(key);
      out = config::As<std::string>(v, c.file(), key);
      if (!IsUpperSnake(out)) c.Fail(v, "channel '" + out + "' must be UPPER_SNAKE");
    };
    read("tactile_scan", s.channels.tactile_scan);
    read("sed", s.channels.sed);
    read("command", s.channels.command);
    read("status", s.channels.status);
    read("sa1_rate", s.channels.sa1_rate);
    read("contact", s.channels.contact);
    c.Finish();
  }
  r.Finish();
  return s;
}

}  // namespace sedbridge::lcm_io
