#pragma once
// What an electrotactile display is rendered against: it puts no mechanical load on the
// finger (no device model, no inverse FE), so its fidelity cannot be an SED the display
// produces. Electrodes excite the afferents directly; the quantity they aim at is the SA1
// (Merkel) afferents' firing, here the ESTIMATE of display/sa1_rate_estimate.h (a
// saturating function of the Merkel SED with illustrative, unfitted parameters) at each
// electrode's site, from the SED the bridge asked for. The commands still come from the
// profile's curve; this is what they are read against, labelled as an estimate wherever it
// is printed or written.

#include <string>
#include <vector>

#include "display/display_profile.h"
#include "display/sa1_rate_estimate.h"
#include "display/sed_field.h"

namespace sedbridge::bridge {

struct Sa1RateAtSites {
  std::vector<double> sed_at_site_Pa;  ///< the curve's sample of the field at each site [Pa]
  std::vector<double> rate_Hz;         ///< SA1 rate ESTIMATE at each site [spikes/s]
  int peak_site = -1;                  ///< the site of the largest estimate (-1: none finite)
};

/// The SA1 rate estimate at each of `profile`'s sites for `field` (sampled as the profile's
/// curve samples it: mapping.sampling, radius_mm, z window).
Sa1RateAtSites EstimateSa1RateAtSites(const display::DisplayProfile& profile, const display::SedField& field,
                                      const display::Sa1RateParams& params = {});

/// peak_sa1_rate_estimate.csv: electrode,x_mm,y_mm,sed_at_site_Pa,sa1_rate_estimate_Hz,command
/// (`command`: the published value [the profile's unit], 0 where absent). Throws
/// std::runtime_error when it cannot be written.
void WriteSa1RateEstimateCsv(const std::string& path, const display::DisplayProfile& profile,
                             const Sa1RateAtSites& estimate, const std::vector<double>& command);

}  // namespace sedbridge::bridge
