#pragma once
// ESTIMATE of the SA1 (Merkel) afferent firing rate at a site from the local Merkel-layer SED.
//
// Model: a static saturating (Hill / Naka-Rushton) function of SED,
//     rate = max_rate_Hz * s^n / (s^n + half_rate_sed_Pa^n),   s = max(0, SED - threshold_Pa)
// It captures the two facts SA1 models agree on — rate grows monotonically with SED (the
// mechanical correlate used by Gerling and colleagues, e.g. Lesniak & Gerling 2009,
// Gerling et al. IEEE ToH 2014, and by TouchSim, Saal et al. PNAS 2017) and saturates at a
// few hundred spikes/s at most — but not their dynamics (adaptation, generator current,
// leaky integrate-and-fire spiking) nor any fitted parameter. The defaults are illustrative
// round numbers, not fitted to recordings. Publish it labelled as an estimate.

#include <vector>

namespace sedbridge::display {

struct Sa1RateParams {
  double max_rate_Hz = 150;       ///< saturation rate [spikes/s]
  double half_rate_sed_Pa = 1000; ///< SED above threshold giving half the max rate [Pa]
  double hill_exponent = 1.5;     ///< steepness [-]
  double threshold_Pa = 10;       ///< SED below which the estimate is 0 [Pa]
};

/// Estimated rate [spikes/s] for one SED value [Pa]. NaN in -> NaN out; Inf -> max_rate_Hz;
/// negative -> 0. Throws std::invalid_argument for non-finite or non-positive parameters.
double EstimateSa1Rate(double sed_Pa, const Sa1RateParams& params = {});

/// Per site, e.g. for SedToCommandMapping::Result::sed_at_site_Pa.
std::vector<double> EstimateSa1Rates(const std::vector<double>& sed_Pa,
                                     const Sa1RateParams& params = {});

}  // namespace sedbridge::display
