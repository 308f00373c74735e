#include "lcm/tactile_scan_message.h"

#include <algorithm>

#include "lcm/lcm_float.h"

namespace sedbridge::lcm_io {

lcmt_tactile_scan ToLcm(const sensors::Scan& s, const std::string& sensor_id) {
  lcmt_tactile_scan m;
  m.utime = s.utime;
  m.sequence = s.sensor_counter >= 0 ? s.sensor_counter : s.sequence;
  m.sensor_id = sensor_id;
  m.num_taxels = s.num_taxels;
  const size_t n = static_cast<size_t>(std::max(0, s.num_taxels));
  m.raw_counts.assign(n, 0);
  m.pressure_kPa.assign(n, 0.0f);
  m.valid.assign(n, false);
  const int axes = std::max(1, s.num_axes);
  for (size_t i = 0; i < n; ++i) {
    // The message has one raw value per taxel: the normal axis.
    const size_t ch = i * size_t(axes) + size_t(axes == 3 ? 2 : 0);
    if (ch < s.raw_counts.size()) m.raw_counts[i] = s.raw_counts[ch];
    if (i < s.pressure_Pa.size()) m.pressure_kPa[i] = ToLcmFloat(s.pressure_Pa[i] * 1e-3);
    if (i < s.valid.size()) m.valid[i] = s.valid[i] != 0;
  }
  m.num_shear = 0;
  if (s.shear_x_Pa.size() == n && s.shear_y_Pa.size() == n && n > 0) {
    m.num_shear = s.num_taxels;
    m.shear_x_kPa.resize(n);
    m.shear_y_kPa.resize(n);
    for (size_t i = 0; i < n; ++i) {
      m.shear_x_kPa[i] = ToLcmFloat(s.shear_x_Pa[i] * 1e-3);
      m.shear_y_kPa[i] = ToLcmFloat(s.shear_y_Pa[i] * 1e-3);
    }
  }
  return m;
}

}  // namespace sedbridge::lcm_io
