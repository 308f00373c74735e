// Fuzzes every YAML config reader that needs no FE code: display profile, sensor profile,
// bridge config (the first byte picks which). Any input must either load or throw
// config::ConfigError — no other exception, no crash, no UB — and a display profile that
// loads must satisfy every documented bound (config/displays/README.md).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "bridge/bridge_config.h"
#include "common/config_error.h"
#include "common/yaml_reader.h"
#include "display/display_kind_limits.h"
#include "display/display_profile.h"
#include "display/safety_limiter.h"
#include "sensors/sensor_profile.h"

using namespace sedbridge;

namespace {

void CheckProfile(const display::DisplayProfile& p) {
  const display::DisplayKindLimits k = display::LimitsOf(p.kind);
  if (p.size() == 0) std::abort();
  if (!(p.range_min >= 0 && p.range_min < p.range_max && p.range_max <= k.max_value)) std::abort();
  if (!(p.safety.max > p.range_min && p.safety.max <= p.range_max)) std::abort();
  if (!(p.safety.slew_rate_per_s > 0 && p.safety.slew_rate_per_s <= k.max_slew_per_s)) std::abort();
  if (!(p.safety.watchdog_timeout_s > 0 && p.safety.watchdog_timeout_s <= display::kMaxWatchdogTimeout_s))
    std::abort();
  for (double m : p.safety.max_per_actuator)
    if (!(m >= 0 && m <= p.safety.max)) std::abort();
  // The limiter accepts every profile the loader accepts.
  display::SafetyLimiter limiter(display::SafetyLimits::FromProfile(p));
  (void)limiter;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 20000) return 0;
  const int kind = data[0] % 3;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    switch (kind) {
      case 0: CheckProfile(display::ParseDisplayProfile(text, "fuzz.yaml")); break;
      case 1: (void)sensors::ParseSensorProfileString(text, "fuzz.yaml"); break;
      case 2: {
        const bridge::BridgeConfig c = bridge::ParseBridgeConfig(text, "fuzz.yaml");
        if (!(c.tick_Hz >= bridge::kMinTick_Hz && c.tick_Hz <= bridge::kMaxTick_Hz)) std::abort();
        if (!(c.status_Hz >= bridge::kMinStatus_Hz && c.status_Hz <= bridge::kMaxStatus_Hz)) std::abort();
        break;
      }
    }
  } catch (const config::ConfigError&) {
    // the expected way to refuse
  } catch (const std::invalid_argument&) {
    // sensor profile validation reports this way too
  }
  return 0;
}
