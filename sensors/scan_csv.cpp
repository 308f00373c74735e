#include "sensors/scan_csv.h"

#include <cstdio>

namespace sedbridge::sensors {

namespace {
const char* AxisName(int axes, int a) { return axes == 3 ? (a == 0 ? "x" : a == 1 ? "y" : "z") : "z"; }
}  // namespace

std::string ScanCsvHeader(const SensorProfile& p) {
  std::string s = "scan,utime,complete";
  for (int i = 0; i < p.taxel_count; ++i)
    for (int a = 0; a < p.axes; ++a) s += ",t" + std::to_string(i) + "_" + AxisName(p.axes, a) + "_Pa";
  return s + "\n";
}

void AppendScanCsvRow(const Scan& s, std::string* out) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%lld,%lld,%d", static_cast<long long>(s.sequence),
                static_cast<long long>(s.utime), s.complete ? 1 : 0);
  *out += buf;
  for (int i = 0; i < s.num_taxels; ++i) {
    for (int a = 0; a < s.num_axes; ++a) {
      out->push_back(',');
      if (!s.valid[i]) continue;
      const double v = s.num_axes == 3
                           ? (a == 0 ? s.shear_x_Pa[i] : a == 1 ? s.shear_y_Pa[i] : s.pressure_Pa[i])
                           : s.pressure_Pa[i];
      std::snprintf(buf, sizeof buf, "%.6g", v);
      *out += buf;
    }
  }
  out->push_back('\n');
}

}  // namespace sedbridge::sensors
