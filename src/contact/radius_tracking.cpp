#include "contact/radius_tracking.h"

#include <cmath>
#include <Eigen/Cholesky>

namespace sedbridge::contact {

TrackedRadius TrackRadius(const ReconstructionOptions& options, bool have_last, const Hypothesis& last,
                          double last_log_radius_variance, int averaged_scans) {
  const double q = options.radius_track_log_sigma;
  TrackedRadius track;
  if (!have_last || last.pair || !sensors::HasFittedRadius(last.first.shape) || !(q > 0))
    return track;
  track.log_radius = std::log(last.first.radius_mm);
  // While a hold goes on its mean decides, and the last answer already holds its scans.
  const bool moving = averaged_scans <= 1;
  track.log_sigma = options.radius_track_posterior && moving ? std::sqrt(last_log_radius_variance + q * q) : q;
  return track;
}

double LogRadiusVariance(const FitProblem& problem, const Fit& fit) {
  // What the scan (and the prior) leave open about log R: (J^T W^2 J + prior)^-1 at the last
  // Jacobian of the fit's prediction. Saturated channels, one-sided, are left out.
  const Prediction& p = fit.prediction;
  const Eigen::MatrixXd& jacobian = p.linearization.jacobian;
  if (!std::isfinite(fit.radius_prior_weight) || !p.valid || jacobian.cols() != p.at.size() ||
      jacobian.rows() != problem.obs.size())
    return std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd w = problem.weight;
  for (size_t k = 0; k < problem.saturated.size(); ++k)
    if (problem.saturated[k]) w[3 * static_cast<Eigen::Index>(k) + 2] = 0;
  const Eigen::MatrixXd jw = w.asDiagonal() * jacobian;
  Eigen::MatrixXd information = jw.transpose() * jw;
  information(kLogRadius, kLogRadius) += fit.radius_prior_weight * fit.radius_prior_weight;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(information);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::VectorXd column = ldlt.solve(Eigen::VectorXd::Unit(p.at.size(), kLogRadius));
  return column.allFinite() && column[kLogRadius] > 0 ? column[kLogRadius] : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace sedbridge::contact
