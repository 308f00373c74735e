#include "view/view_layouts.h"

#include <cstdio>
#include <exception>

#include "display/display_profile.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::view {

const PadLayout& ViewLayouts::Sensor(const std::string& sensor_id) {
  const std::string name = fixed_sensor_.empty() ? sensor_id : fixed_sensor_;
  auto it = sensors_.find(name);
  if (it != sensors_.end()) return it->second;
  PadLayout l;
  try {
    const sensors::SensorProfile p = sensors::LoadNamedSensorProfile(name);
    l.id = p.name;
    for (const auto& t : p.taxels) {
      l.x_mm.push_back(t.x_mm);
      l.y_mm.push_back(t.y_mm);
    }
    l.cell_w_mm = p.taxel_width_mm;
    l.cell_h_mm = p.taxel_height_mm;
  } catch (const std::exception& e) {
    l.error = e.what();
    std::fprintf(stderr, "view: no sensor profile '%s' (%s); taxels drawn in a row\n", name.c_str(), e.what());
  }
  return sensors_.emplace(name, std::move(l)).first->second;
}

const PadLayout& ViewLayouts::Display(const std::string& display_id) {
  const std::string name = fixed_display_.empty() ? display_id : fixed_display_;
  auto it = displays_.find(name);
  if (it != displays_.end()) return it->second;
  PadLayout l;
  try {
    const display::DisplayProfile p = display::LoadNamedDisplayProfile(name);
    l.id = p.name;
    l.x_mm = p.x_mm;
    l.y_mm = p.y_mm;
    l.max = p.safety.max;
    l.unit = p.unit;
  } catch (const std::exception& e) {
    l.error = e.what();
    std::fprintf(stderr, "view: no display profile '%s' (%s); actuators drawn in a row\n", name.c_str(), e.what());
  }
  return displays_.emplace(name, std::move(l)).first->second;
}

}  // namespace sedbridge::view
