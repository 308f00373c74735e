#pragma once
// Parsing a display profile text in a test: the profile, or the error it gets.

#include <string>

#include "common/config_error.h"
#include "display/display_profile.h"

namespace sedbridge::display::profile_text {

/// The profile of `text`, named "p.yaml" in messages (throws config::ConfigError).
inline DisplayProfile Parse(const std::string& text) { return ParseDisplayProfile(text, "p.yaml"); }

/// The error a profile text gets, or "accepted".
inline std::string ParseMessage(const std::string& text) {
  try {
    Parse(text);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace sedbridge::display::profile_text
