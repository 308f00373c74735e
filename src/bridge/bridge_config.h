#pragma once
// One bridge YAML (config/bridge/*.yaml): which sensor, which fingertip model and preset,
// where the sensor sits on the pad, how taxels become traction, which display, LCM URL and
// channels, rates. Every key is documented in config/bridge/README.md; the reader is strict
// (unknown keys and wrong types are config::ConfigError naming file:line:column).

#include <string>

#include "bridge/pad_registration.h"
#include "bridge/taxel_values.h"
#include "bridge/traction_field.h"
#include "lcm/lcm_channels.h"

namespace sedbridge::bridge {

/// Bounds of `rates.*` [Hz]. The tick drives the display's ramp to zero while no scan
/// arrives: below 50 Hz a ramp would move in steps longer than the limiter's rise interval
/// (25 ms) and a 0.05 s watchdog would be noticed late; above 10 kHz it only burns CPU.
/// BRIDGE_STATUS at 0.1..100 Hz (1e-30 Hz overflowed the period).
inline constexpr double kMinTick_Hz = 50, kMaxTick_Hz = 10000;
inline constexpr double kMinStatus_Hz = 0.1, kMaxStatus_Hz = 100;

/// Which FeStep the bridge builds (bridge config `fe.step`).
enum class FeStepKind {
  kScene,    ///< "scene": SceneFeStep, the scene solved every scan
  kReduced,  ///< "reduced": ReducedLinearFeStep (preset fast only)
  kContact,  ///< "contact": ContactFeStep, reconstructed contact pressed on the model (preset fast only)
};
/// "scene", "reduced", "contact".
const char* ToString(FeStepKind kind);
/// The kind named by `name` (as in the config); throws std::invalid_argument for others.
FeStepKind FeStepKindFromString(const std::string& name);

struct BridgeConfig {
  std::string file;  ///< where it was read from ("" = defaults)

  // sensor:
  std::string sensor_profile = "uskin_4x4";  ///< shipped name or YAML path
  std::string can_interface = "can0";        ///< live mode (sedbridge run)
  int tare_scans = 0;                        ///< automatic tare over N quiet scans (0 = profile offsets)

  // fe:
  std::string model = "B";      ///< model name or path (model::LoadFingertipModel)
  std::string preset = "fast";  ///< fast | balanced | accurate
  FeStepKind fe_step = FeStepKind::kScene;  ///< fe.step: scene | reduced | contact
  std::string compliance_cache_dir = "out/cache";  ///< fe.compliance_cache: precompute cache of fe.step contact

  // registration:
  PadRegistrationParams registration;

  // traction:
  TractionFieldOptions traction;
  ScanConditioningOptions conditioning;

  // display:
  std::string display_profile = "suction_4x4";  ///< shipped name (config/displays/NAME.yaml) or path

  // rates:
  double status_Hz = 10;  ///< BRIDGE_STATUS rate (pipeline clock)
  double tick_Hz = 200;   ///< live mode: display Tick rate while no scan arrives

  // outputs:
  bool publish_sed = true;    ///< FINGERTIP_SED every step
  bool publish_scans = true;  ///< TACTILE_SCAN every scan

  // lcm:
  lcm_io::LcmSettings lcm;
};

/// Reads a bridge YAML. Throws config::ConfigError.
BridgeConfig LoadBridgeConfig(const std::string& path);
/// Same from text (`file` is used in messages).
BridgeConfig ParseBridgeConfig(const std::string& yaml_text, const std::string& file);

/// The shipped default config (config/bridge/default.yaml, resolved from any directory).
std::string DefaultBridgeConfigPath();

}  // namespace sedbridge::bridge
