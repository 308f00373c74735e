#pragma once
// Radius tracking: an object keeps its size while it touches. The warm fit's radius prior is
// centred on the last answer's radius (radius_track_log_sigma in log R) instead of the weak
// prior, and, with radius_track_posterior while the contact moves, widened by what the scans
// so far left open about the radius (the last accepted fit's posterior variance of log R).

#include <limits>

#include "contact/contact_fitter.h"
#include "contact/contact_parameters.h"
#include "contact/reconstruction_options.h"

namespace sedbridge::contact {

/// A scan's tracked radius prior: log R ~ N(log_radius, log_sigma^2); log_radius NaN: none.
struct TrackedRadius {
  double log_radius = std::numeric_limits<double>::quiet_NaN();
  double log_sigma = 0;
};

/// The prior from the last answer (none without one, for a pair or a flat, or when
/// radius_track_log_sigma is 0). averaged_scans > 1 (a hold's mean, which holds the last
/// answer's scans already) keeps the prior at radius_track_log_sigma.
TrackedRadius TrackRadius(const ReconstructionOptions& options, bool have_last, const Hypothesis& last,
                          double last_log_radius_variance, int averaged_scans);

/// The posterior variance of log R that an accepted LM fit of a single sphere or rod leaves
/// (the inverse of its weighted Gauss-Newton information at its prediction's Jacobian, its
/// radius prior included); NaN for other fits.
double LogRadiusVariance(const FitProblem& problem, const Fit& fit);

}  // namespace sedbridge::contact
