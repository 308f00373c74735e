#pragma once
// Where the bridge's LCM traffic goes: the URL and the channel names (UPPER_SNAKE).

#include <string>

#include "common/name_value.h"

namespace sedbridge::config {
class MapReader;
}

namespace sedbridge::lcm_io {

/// Default LCM URL: UDP multicast with ttl=0, so nothing leaves the host unless asked.
inline constexpr char kDefaultLcmUrl[] = "udpm://239.255.76.67:7667?ttl=0";

/// Channel names; every one configurable. Defaults (documented in README.md):
struct LcmChannels {
  std::string tactile_scan = "TACTILE_SCAN";      ///< lcmt_tactile_scan
  std::string sed = "FINGERTIP_SED";              ///< lcmt_merkel_sed
  std::string command = "DISPLAY_COMMAND";        ///< lcmt_display_command
  std::string status = "BRIDGE_STATUS";           ///< lcmt_bridge_status
  std::string sa1_rate = "SA1_RATE_ESTIMATE";     ///< lcmt_sa1_rate_estimate
  std::string contact = "CONTACT_ESTIMATE";       ///< lcmt_contact_estimate (bridge fe.step: contact)
  std::string rendering = "DISPLAY_RENDERING";    ///< lcmt_display_rendering (display.rendering: inverse)

  /// Throws std::invalid_argument naming the first channel that is not UPPER_SNAKE.
  void Validate() const;

  /// Keys of `lcm.channels`; each name must be UPPER_SNAKE (CheckChannelNames).
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("tactile_scan", &tactile_scan));
    a->Visit(Field("sed", &sed));
    a->Visit(Field("command", &command));
    a->Visit(Field("status", &status));
    a->Visit(Field("sa1_rate", &sa1_rate));
    a->Visit(Field("contact", &contact));
    a->Visit(Field("rendering", &rendering));
  }
};

/// True for names like "DISPLAY_COMMAND", "SED2": [A-Z][A-Z0-9_]*, no trailing/double '_'.
bool IsUpperSnake(const std::string& name);

/// The `lcm:` section of a bridge config. All keys optional:
///   lcm:
///     url: "udpm://239.255.76.67:7667?ttl=0"
///     log: "out/run.lcmlog"          # also write every published message here ("" = no log)
///     channels: {tactile_scan: TACTILE_SCAN, sed: FINGERTIP_SED, command: DISPLAY_COMMAND,
///                status: BRIDGE_STATUS, sa1_rate: SA1_RATE_ESTIMATE}
///     auth_key_file: "/etc/sedbridge/display.key"   # sign DISPLAY_COMMAND (HMAC-SHA256)
struct LcmSettings {
  std::string url = kDefaultLcmUrl;
  std::string log_path;
  /// Key for signing every DISPLAY_COMMAND on the bus ("" = unsigned); see
  /// display/command_authenticator.h. The log gets the unsigned message.
  std::string auth_key_file;
  LcmChannels channels;

  /// Keys of the bridge's `lcm:` section (config/bridge/README.md).
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("url", &url));
    a->Visit(Field("log", &log_path));
    a->Visit(Field("auth_key_file", &auth_key_file));
    a->Visit(Field("channels", &channels));
  }
};

/// Reads an `lcm:` mapping strictly; throws config::ConfigError (file:line:column) for unknown
/// keys or channel names that are not UPPER_SNAKE. Calls Finish() on `r`.
LcmSettings ParseLcmSettings(config::MapReader& r);

/// Throws config::ConfigError at the first channel name of the `lcm:` mapping `lcm_section`
/// that is not UPPER_SNAKE (for readers that read the section through its Serialize).
void CheckChannelNames(const config::MapReader& lcm_section);

}  // namespace sedbridge::lcm_io
