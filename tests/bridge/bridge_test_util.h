#pragma once
// Shared helpers for the bridge tests: the test config, the example log, scans by hand.

#include <string>
#include <vector>

#include "bridge/bridge_config.h"
#include "bridge/replay.h"
#include "common/resource_path.h"
#include "display/display_profile.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge::testing {

inline std::string TestConfigPath() { return std::string(SEDBRIDGE_SOURCE_DIR) + "/tests/bridge/data/b_coarse.yaml"; }
inline std::string ExampleLogPath() { return std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_press.log"; }
inline BridgeConfig TestConfig() { return LoadBridgeConfig(TestConfigPath()); }

/// The display profile `config` names, loaded as the app does.
inline display::DisplayProfile ConfigDisplay(const BridgeConfig& config) {
  return display::LoadNamedDisplayProfile(config.display_profile);
}

/// RunReplay with the sensor and display profiles `config` names, loaded as the app does.
inline ReplayResult ReplayWithConfigProfiles(const BridgeConfig& config, sensors::FrameSource& source,
                                             const ReplayOptions& options) {
  return RunReplay(config, sensors::LoadNamedSensorProfile(config.sensor_profile), ConfigDisplay(config), nullptr,
                   source, options);
}

/// A complete, valid scan with `pressure_Pa` on every taxel (no shear for 1-axis).
inline sensors::Scan UniformScan(const sensors::SensorProfile& p, double pressure_Pa, int64_t utime = 1000) {
  sensors::Scan s;
  s.utime = utime;
  s.complete = true;
  s.num_taxels = p.taxel_count;
  s.num_axes = p.axes;
  s.raw_counts.assign(size_t(p.channel_count()), 0);
  s.pressure_Pa.assign(size_t(p.taxel_count), pressure_Pa);
  if (p.axes == 3) {
    s.shear_x_Pa.assign(size_t(p.taxel_count), 0.0);
    s.shear_y_Pa.assign(size_t(p.taxel_count), 0.0);
  }
  s.force_N.assign(size_t(p.taxel_count), pressure_Pa * p.taxel_area_mm2() * 1e-6);
  s.valid.assign(size_t(p.taxel_count), 1);
  s.flags.assign(size_t(p.taxel_count), 0);
  return s;
}

}  // namespace sedbridge::bridge::testing
