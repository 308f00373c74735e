#pragma once
// Taxel heatmap of one scan: the per-taxel CSV that tools/plot_taxels.py draws (matplotlib;
// `sedbridge decode --heatmap-png` runs it through app/plot_runner.h).

#include <string>
#include <vector>

#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::sensors {

/// Writes one row per taxel: taxel,x_mm,y_mm,pressure_kPa,shear_x_kPa,shear_y_kPa,valid,health.
/// @param health per taxel, what taxel health judged it at that scan ("healthy", "stuck high",
///        "dead", "frozen": sensors/taxel_health.h, or "left out": a suspect not yet masked);
///        empty: the column is left empty.
/// Throws std::runtime_error if the file cannot be written.
void WriteTaxelCsv(const SensorProfile& profile, const Scan& scan, const std::string& csv_path,
                   const std::vector<std::string>& health = {});

}  // namespace sedbridge::sensors
