#include "bridge/sa1_rate_at_peak.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "display/sed_to_command_mapping.h"

namespace sedbridge::bridge {

Sa1RateAtSites EstimateSa1RateAtSites(const display::DisplayProfile& profile, const display::SedField& field,
                                      const display::Sa1RateParams& params) {
  Sa1RateAtSites e;
  e.sed_at_site_Pa = display::SedToCommandMapping(profile).Map(field).sed_at_site_Pa;
  e.rate_Hz = display::EstimateSa1Rates(e.sed_at_site_Pa, params);
  for (size_t i = 0; i < e.rate_Hz.size(); ++i)
    if (std::isfinite(e.rate_Hz[i]) && (e.peak_site < 0 || e.rate_Hz[i] > e.rate_Hz[size_t(e.peak_site)]))
      e.peak_site = int(i);
  return e;
}

void WriteSa1RateEstimateCsv(const std::string& path, const display::DisplayProfile& profile,
                             const Sa1RateAtSites& estimate, const std::vector<double>& command) {
  std::ofstream out(path);
  out << "electrode,x_mm,y_mm,sed_at_site_Pa,sa1_rate_estimate_Hz,command_" << profile.unit << "\n";
  for (size_t i = 0; i < profile.size(); ++i)
    out << i << ',' << profile.x_mm[i] << ',' << profile.y_mm[i] << ','
        << (i < estimate.sed_at_site_Pa.size() ? estimate.sed_at_site_Pa[i] : NAN) << ','
        << (i < estimate.rate_Hz.size() ? estimate.rate_Hz[i] : NAN) << ','
        << (i < command.size() ? command[i] : 0.0) << '\n';
  if (!out) throw std::runtime_error("write failed: " + path);
}

}  // namespace sedbridge::bridge
