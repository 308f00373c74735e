#include "sensors/taxel_heatmap.h"

#include <fstream>
#include <stdexcept>

namespace sedbridge::sensors {

void WriteTaxelCsv(const SensorProfile& profile, const Scan& scan, const std::string& path,
                   const std::vector<std::string>& health) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "taxel,x_mm,y_mm,pressure_kPa,shear_x_kPa,shear_y_kPa,valid,health\n";
  for (int i = 0; i < scan.num_taxels && i < profile.taxel_count; ++i) {
    const double sx = scan.shear_x_Pa.empty() ? 0.0 : scan.shear_x_Pa[i];
    const double sy = scan.shear_y_Pa.empty() ? 0.0 : scan.shear_y_Pa[i];
    out << i << ',' << profile.taxels[i].x_mm << ',' << profile.taxels[i].y_mm << ','
        << scan.pressure_Pa[i] * 1e-3 << ',' << sx * 1e-3 << ',' << sy * 1e-3 << ','
        << int(scan.valid[i]) << ',' << (size_t(i) < health.size() ? health[size_t(i)] : std::string()) << '\n';
  }
  if (!out) throw std::runtime_error("error writing " + path);
}

}  // namespace sedbridge::sensors
