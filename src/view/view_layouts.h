#pragma once
// Where things sit on the pad, for drawing: the taxel centres of a sensor profile and the
// actuator sites of a display profile, looked up by the ids the messages carry
// (lcmt_tactile_scan::sensor_id, lcmt_display_command::display_id) and kept. An id with no
// shipped profile gives an empty layout (the page then draws a plain row) and one warning.

#include <map>
#include <string>
#include <vector>

namespace sedbridge::view {

struct PadLayout {
  std::string id;      ///< profile name; "" when none was found
  std::vector<double> x_mm, y_mm;  ///< one entry per taxel / actuator, pad frame [mm]
  double cell_w_mm = 0, cell_h_mm = 0;  ///< taxel size (sensor); 0 for a display
  double max = 0;      ///< display: the hard limit [unit]; 0 for a sensor
  std::string unit;    ///< display: "kPa", "mm", "mA"
  std::string error;   ///< why it is empty
};

class ViewLayouts {
 public:
  /// Fixed profiles (--sensor, --display); "" = from the messages' ids.
  ViewLayouts(std::string sensor, std::string display)
      : fixed_sensor_(std::move(sensor)), fixed_display_(std::move(display)) {}
  const PadLayout& Sensor(const std::string& sensor_id);
  const PadLayout& Display(const std::string& display_id);

 private:
  std::string fixed_sensor_, fixed_display_;
  std::map<std::string, PadLayout> sensors_, displays_;
};

}  // namespace sedbridge::view
