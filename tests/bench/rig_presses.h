#pragma once
// What the benchmarks that replay the calibration rig share: the shipped uSkin profile and
// the rig's presses (loaded once a process).

#include <vector>

#include "common/resource_path.h"
#include "sensors/calibration_press.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bench {

inline const sensors::SensorProfile& Profile() {
  static const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  return p;
}

inline const std::vector<sensors::CalibrationPress>& Rig() {
  static const auto presses = sensors::LoadCalibrationPresses(
      config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), Profile());
  return presses;
}

}  // namespace sedbridge::bench
