#pragma once
// The fitter: Levenberg-Marquardt on one contact model's unknowns (contact_parameters.h)
// against a scan in noise units, the residuals through the sensor's forward model.
//
// Solver: Eigen's Levenberg-Marquardt (unsupported/NonLinearOptimization, a MINPACK port that
// ships with Eigen). The problem is dense and tiny (<= 10 unknowns, 48 residuals) and runs per
// scan, so Ceres' strengths (sparsity, autodiff through a cost graph, robust losses) buy
// nothing here and its setup cost per solve would.
//
// Residuals are in units of the noise of each axis (of the scan, or of the mean); invalid
// taxels carry no weight, except saturated ones, which only say "at least full scale" (a
// one-sided residual: hard contact there, not missing data). A fit runs within a budget of
// evaluations (FitBudget) and can start from the parts and Jacobian of the last answer
// (Prediction), so a scan continues where the last one stopped.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <vector>

#include "contact/contact_parameters.h"
#include "contact/reconstruction_options.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::contact {

/// One sphere's (or a single shape's) forward-model parts: normal readings, readings per
/// unit shear, and the force they were computed for.
struct ModelPart {
  Eigen::VectorXd normal, per_x, per_y;
  double force_N = 0;
};
/// The last Jacobian of the prediction (d pred / du, single shapes) with the point and
/// prediction it was taken at, and LM iterations since its finite differences (-1: none):
/// a fit's next iteration, or the next scan's first, updates it (Broyden) instead of
/// differencing again.
struct Linearization {
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd at, pred;
  int since_differences = -1;
};
/// The forward model's parts (normal readings, per unit shear) at a fit's final
/// unknowns. They do not depend on the readings, so the next scan's force step and warm
/// fit, which start there, need not evaluate that point again.
struct Prediction {
  bool valid = false;
  sensors::ContactShape shape = sensors::ContactShape::kSphere;
  bool pair = false, finite = false;
  Eigen::VectorXd at;
  ModelPart whole;      // the model's parts at `at` (a pair's combined)
  ModelPart parts[2];   // a pair's two spheres, each its own
  Linearization linearization;
};
/// A fit's budget in units (evaluations weighted by patch size, cells_per_evaluation).
struct FitBudget {
  FitBudget(int soft = 0) : units(soft) {}  // NOLINT: a plain number is the soft budget
  /// Stop after the LM iteration that reaches this many (0: none).
  int units = 0;
  /// Never start evaluations that would pass this many (0: no such cap; their cost
  /// estimated from the patches they would load): the fit stops at its last accepted
  /// point instead.
  int hard_units = 0;
};
/// How a fit moves its unknowns.
enum class FitMode {
  kLevenbergMarquardt,
  /// One Gauss-Newton step in log F and the shear with the shape held (single, non-flat
  /// shapes with shear; no saturated taxel): three evaluations, two from `known`.
  kForceStep,
};

/// One fit's answer and what it cost.
struct Fit {
  Hypothesis model;
  double chi2 = std::numeric_limits<double>::infinity();
  int unknowns = 0;
  int evaluations = 0;
  bool converged = false;  // LM stopped by its own tests, not by a budget or an error
  bool at_radius_bound = false;  // the radius ran out of the plausible range (clamped)
  int budget_used = 0;           // evaluations weighted by patch size
  bool stopped = false;          // by FitBudget::hard_units (chi2 infinite if nothing was evaluated)
  double refused_units = 0;      // stopped: units of one evaluation where (an estimate)
  Prediction prediction;         // at the model's unknowns
  /// LM fits of single spheres and rods: the weight of the radius prior's residual, for the
  /// radius's posterior variance (LogRadiusVariance); NaN for other fits (force steps, pairs,
  /// flats), which give none.
  double radius_prior_weight = std::numeric_limits<double>::quiet_NaN();
  double Penalized() const { return chi2 + 2.0 * unknowns; }
};

/// What a fit reads: the forward model and options, and the scan being fitted.
struct FitProblem {
  const sensors::TactileForwardModel& model;
  const ReconstructionOptions& options;
  const Eigen::VectorXd& obs;           ///< readings being fitted [N] (a scan, or a hold's mean)
  const Eigen::VectorXd& weight;        ///< 1 / noise per channel of obs [1/N]; 0: no weight
  const Eigen::VectorXd& inv_sigma;     ///< 1 / single-scan noise per channel [1/N]
  const Eigen::VectorXd& full_scale_N;  ///< per channel, saturation reading [N]
  const std::vector<uint8_t>& saturated;  ///< per taxel: at least full scale on the normal axis
  double log_r_lo = 0, log_r_hi = 0;    ///< plausible log radius [log mm]
};

/// LM from `start`; max_evaluations: LM function evaluations (0: options' max_evaluations);
/// budget: see FitBudget. Each sphere of a pair counts as one evaluation.
/// known: the parts at `start` when they are known (its unknowns within round-off).
/// @param tracked_log_radius  finite: the radius prior is centred here with
///                            tracked_log_sigma (the warm fit: the last answer's)
Fit FitModel(const FitProblem& problem, const Hypothesis& start, int max_evaluations = 0, const FitBudget& budget = {},
             FitMode mode = FitMode::kLevenbergMarquardt, const Prediction* known = nullptr,
             double tracked_log_radius = std::numeric_limits<double>::quiet_NaN(), double tracked_log_sigma = 0);

}  // namespace sedbridge::contact
