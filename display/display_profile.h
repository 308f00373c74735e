#pragma once
// A haptic distribution display worn on the leader's finger: where its actuators sit on the
// pad, what unit they take, the hard safety limits, and how Merkel-layer SED maps to them.
// Loaded from config/displays/*.yaml (keys documented in config/displays/README.md).

#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "common/config_error.h"
#include "common/enum_names.h"
#include "common/name_value.h"
#include "display/display_device.h"
#include "display/display_kind.h"

namespace sedbridge::display {

/// How the SED field is sampled at an actuator site (all within `radius_mm` in x-y).
enum class SamplingMethod {
  kInterpolate,       ///< inverse-distance (Shepard, power 2) interpolation at the site
  kMaxWithinRadius,   ///< largest vertex SED within the radius
  kMeanWithinRadius,  ///< mean vertex SED within the radius
};
/// "interpolate", "max_within_radius", "mean_within_radius" (key mapping.sampling).
const config::EnumNames<SamplingMethod>& NamesOf(SamplingMethod);

/// Largest `mapping.calibration.gain` entry [-]: a per-actuator correction, not an amplifier.
inline constexpr double kMaxCalibrationGain = 10.0;

/// SED [Pa] -> actuator value [display unit]:
///   s = sample(SED) at the site;  x = max(0, s - threshold_Pa)
///   y = min(saturation, gain * (x / reference_Pa)^exponent)
///   y = calibration_gain[i] * y + calibration_offset[i]   (only where y > 0)
struct MappingParams {
  SamplingMethod sampling = SamplingMethod::kMaxWithinRadius;
  double radius_mm = 1.0;  ///< sampling radius in the pad's x-y plane [mm]
  /// Only vertices with z in [z_min_mm, z_max_mm] are sampled (keeps the Merkel layer under
  /// the pad and drops its far side under the nail, which projects onto the same x-y).
  double z_min_mm = -std::numeric_limits<double>::infinity();
  double z_max_mm = std::numeric_limits<double>::infinity();
  double threshold_Pa = 0;       ///< SED below this gives 0 [Pa]
  double reference_Pa = 1000;    ///< SED above threshold at which y == gain [Pa]
  double gain = 1;               ///< output at (s - threshold) == reference_Pa [unit]
  double exponent = 1;           ///< power law exponent [-]
  double saturation = 1;         ///< transfer output cap [unit]
  std::vector<double> calibration_gain;    ///< per actuator [-]; empty = all 1
  std::vector<double> calibration_offset;  ///< per actuator [unit]; empty = all 0

  /// Keys of `mapping`. Limits that depend on the display kind (saturation, offsets) and
  /// list lengths are checked by display_profile.cpp.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("sampling", &sampling).Required());
    a->Visit(Field("radius_mm", &radius_mm).Required().Positive());
    std::array<double, 2> z_window_mm{z_min_mm, z_max_mm};
    a->Visit(Field("z_window_mm", &z_window_mm));  // min < max
    z_min_mm = z_window_mm[0];
    z_max_mm = z_window_mm[1];
    a->Visit(Field("threshold_Pa", &threshold_Pa).NonNegative());
    a->Visit(Field("reference_Pa", &reference_Pa).Required().Positive());
    a->Visit(Field("gain", &gain).Required().Positive());
    a->Visit(Field("exponent", &exponent).InRange(0.1, 10));
    a->Visit(Field("saturation", &saturation).Positive());
    a->Section("calibration", [&](auto* c) {
      c->Visit(Field("gain", &calibration_gain).Within({0, kMaxCalibrationGain, true, false}));
      c->Visit(Field("offset", &calibration_offset));
    });
  }
};

/// Upper bound on any profile's watchdog timeout [s]: a config cannot turn the watchdog off
/// by making it very long.
inline constexpr double kMaxWatchdogTimeout_s = 1.0;

/// Limits the SafetyLimiter enforces. These are not switchable: every field is required to be
/// finite and positive, and the watchdog timeout is capped at kMaxWatchdogTimeout_s.
struct SafetyParams {
  double max = 0;                         ///< hard limit for every actuator [unit]
  std::vector<double> max_per_actuator;   ///< filled: min(max, per-actuator override) [unit]
  double slew_rate_per_s = 0;             ///< largest rise (and normal fall) rate [unit/s]
  double watchdog_timeout_s = 0;          ///< no fresh input this long -> ramp to zero [s]

  /// Keys of `safety`. Bounds that depend on the device range or the display kind (max,
  /// slew rate) and the length of max_per_actuator are checked by display_profile.cpp.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("max", &max).Required().Positive());
    a->Visit(Field("max_per_actuator", &max_per_actuator).NonNegative());  // default: max for every actuator
    a->Visit(Field("slew_rate_per_s", &slew_rate_per_s).Required().Positive());
    a->Visit(Field("watchdog_timeout_s", &watchdog_timeout_s).Required().Unit("s").Within({0, kMaxWatchdogTimeout_s, true, false}));
  }
};

struct DisplayProfile {
  std::string name;         ///< e.g. "suction_4x4"; published as display_id
  std::string description;
  DisplayKind kind = DisplayKind::kSuction;
  std::string unit;         ///< "kPa", "mm" or "mA" (must match kind)
  /// Actuator sites on the leader's pad, pad frame [mm]; one entry per actuator, in the
  /// order of the command's value[] array.
  std::vector<double> x_mm, y_mm;
  double range_min = 0, range_max = 0;  ///< what the device accepts [unit]
  SafetyParams safety;
  MappingParams mapping;
  /// The device model (key `device`, suction and pin only); see has_device_model().
  DisplayDevice device;
  std::string file;         ///< where it was loaded from (for messages)
  /// Where the `actuators` and `device` keys are (device_at: line 0 when absent), so a
  /// later check (CheckDeviceFitsPad) can name them.
  config::SourceLocation actuators_at, device_at;

  std::size_t size() const { return x_mm.size(); }
  /// True when the profile has a `device` block (device.footprints has one per actuator).
  bool has_device_model() const { return !device.footprints.empty(); }

  /// Every key of a display profile (config/displays/README.md). `actuators` (a grid or a
  /// list of sites) is hand-read by display_profile.cpp, which also checks every bound that
  /// spans keys: unit vs kind, range and safety limits vs the kind's limits, list lengths.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("name", &name).Required());
    a->Visit(Field("description", &description));
    a->Visit(Field("kind", &kind).Required());
    a->Visit(Field("unit", &unit).Required());
    a->Section("actuators", [&](auto* s) {
      s->HandRead("grid");
      s->HandRead("positions_mm");
    });
    // Optional; completed and checked against kind and actuators by CompleteDisplayDevice.
    a->Section("device", [&](auto* d) { device.Serialize(d); });
    std::array<double, 2> range{range_min, range_max};
    a->Visit(Field("range", &range).Required().NonNegative());  // min < max
    range_min = range[0];
    range_max = range[1];
    a->Visit(Field("safety", &safety).Required());
    mapping.saturation = safety.max;  // default of mapping.saturation
    a->Visit(Field("mapping", &mapping).Required());
  }
};

/// A display profile argument: a path, or a shipped name ("suction_4x4" ->
/// config/displays/suction_4x4.yaml); the rule is config::ResolveNameOrPath's.
std::string ResolveDisplayProfilePath(const std::string& name_or_path);

/// Loads a profile; `path` is resolved with config::ResolveResource, so
/// "config/displays/suction_4x4.yaml" works from any directory.
/// Throws config::ConfigError (file:line:column) on any bad, missing or unknown key.
DisplayProfile LoadDisplayProfile(const std::string& path);

/// ResolveDisplayProfilePath + LoadDisplayProfile: a shipped name ("suction_4x4") or a path.
DisplayProfile LoadNamedDisplayProfile(const std::string& name_or_path);

/// Parses YAML text (tests, embedded profiles); `file` names it in messages. Throws
/// config::ConfigError.
DisplayProfile ParseDisplayProfile(const std::string& yaml_text, const std::string& file);

}  // namespace sedbridge::display
