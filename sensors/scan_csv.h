#pragma once
// CSV of scans, one row per scan: scan,utime,complete, then one column per taxel axis in Pa
// (t<i>_x_Pa, t<i>_y_Pa shear and t<i>_z_Pa normal for 3-axis sensors; t<i>_z_Pa only for
// normal-only ones). Cells of invalid taxels are empty. Used by `sedbridge decode --csv`
// and `sedbridge make-log --truth-csv`, so decoded and simulated values line up.

#include <string>

#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::sensors {

/// Header line (with '\n').
std::string ScanCsvHeader(const SensorProfile& profile);
/// Appends one row (with '\n') to `out`.
void AppendScanCsvRow(const Scan& scan, std::string* out);

}  // namespace sedbridge::sensors
