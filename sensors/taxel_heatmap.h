#pragma once
// Taxel heatmap of one scan: CSV (always) and PNG via tools/plot_taxels.py (matplotlib).

#include <string>

#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::sensors {

/// Writes one row per taxel: taxel,x_mm,y_mm,pressure_kPa,shear_x_kPa,shear_y_kPa,valid.
/// Throws std::runtime_error if the file cannot be written.
void WriteTaxelCsv(const SensorProfile& profile, const Scan& scan, const std::string& csv_path);

struct PlotResult {
  bool ok = false;
  std::string message;  ///< what happened (the reason when !ok: no python, no matplotlib, ...)
};

/// Runs `python3 tools/plot_taxels.py CSV PNG --title TITLE --size-mm W H`, preferring
/// /usr/bin/python3 (Debian's, which has python3-matplotlib) over the one on PATH.
PlotResult PlotTaxelHeatmap(const SensorProfile& profile, const std::string& csv_path,
                            const std::string& png_path, const std::string& title);

}  // namespace sedbridge::sensors
