#pragma once
// A non-parametric surface pressure from one scan: the normal force on every cell of a
// sub-taxel grid over the pad (cell_mm, 0.5 mm by default) and one tangential force, that
// explain the three-axis readings through the sensor's forward model
// (tactile_forward_model.h). The answer when no contact primitive explains a scan: it
// assumes no shape, only that the pad is pushed, never pulled.
//
// The problem, in noise units (w_i = 1 / sigma_i of reading i, 0 for an invalid taxel),
// on each cell's force scaled by its response (u_j = |W a_j| g_j, a_j the forward model's
// readings per newton on cell j):
//   min_{u >= 0}  1/2 |W A' u - W r|^2 + mu sum_j u_j + 1/2 lambda |u|^2,   A' = A diag(1/|W a_j|)
// The prior, and why (48 readings, 1444 unknowns: the prior decides what the readings leave
// open, which is most of the sub-taxel detail):
//  - non-negative: the pad is pushed, never pulled. With 48 readings this alone makes the
//    field compact where the readings are (an active set of a few dozen cells).
//  - a ridge (Tikhonov of order 0) on the scaled forces, not on the gradient: neighbouring
//    cells' columns are nearly equal, and the ridge splits a load evenly over the cells the
//    readings cannot tell apart (the grouping effect), so the field is as sharp as the
//    readings allow, with no smoothing length of its own. A gradient prior smooths at a
//    length of its own and takes the peak that a small contact's SED depends on (the
//    pressure map's failure: 0.01-0.29 of the peak SED). Scaled: on forces, the least-norm
//    answer pulls a load towards the taxel centres, where a newton reads the most.
//  - total variation would suit flat punches, but it is not separable: no small dual.
//  - the L1 term (sparsity_sigma, mu) is there but off: on uniform patches through the
//    forward model it fitted worse at every ridge tried (0.5-2 sigma: force 13-27 % off,
//    centre 0.5-1.4 mm, against 13-17 % and 0.5-0.7 mm without).
// Its dual lives in the readings' space (48 unknowns): u = max(0, A'^T W y - mu) / lambda,
// and a semi-smooth Newton method with an exact line search solves it on a 48 x 48
// Cholesky per iteration (warm-started from the last scan). A' per profile: computed once
// (construction). The ridge shrinks the total force a little; one least-squares scale on the
// whole field (its debiasing) restores it. The tangential force is one vector spread over
// the cells in proportion to their normal force, as the forward model spreads it: the first
// pass fits every channel without it, then the tangential force comes by least squares on
// that field; where it reads above noise (3 sigma: a stroke) a second pass fits the field
// again on every channel less the tangential part.
// What the readings cannot tell: a compact load from a spread one of the same centre. The
// force of a 1 x 1 mm patch between taxels comes back 8 % high, its centre 0.5 mm towards
// the nearest taxel (clean readings); a 3 x 3 mm patch within 2.5 % and 0.1 mm, with the
// sensor's noise within 9 % and 0.4 mm (tests/sensors/surface_pressure_inversion_test.cpp).
// Faults: a non-finite reading of a valid taxel, a scan of the wrong size: ok = false, the
// field all zero, never NaN. Zero readings give a zero field.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/scan.h"
#include "sensors/sensor_profile.h"
#include "sensors/tactile_model_params.h"

namespace sedbridge::sensors {

struct SurfacePressureOptions {
  double cell_mm = 0.5;           ///< grid spacing over the pad square (pad_size_mm) [mm]
  double noise_counts = 2;        ///< single-scan noise per raw reading (1 sigma) [counts]
  /// mu: a cell takes load only when the residual's correlation with its (unit) response
  /// exceeds this many noise sigmas [-]. 0: off (see the file comment).
  double sparsity_sigma = 0;
  /// lambda on the scaled unknowns [-]: how evenly a load spreads over cells the readings
  /// cannot tell apart (larger: broader, and a worse fit).
  double ridge = 1e-3;
  /// Semi-smooth Newton iterations per pass (20-26 to converge from cold on rig scans). 10
  /// scored as 40 on the fidelity sets at the peak scan (peak ratio medians within 0.06) at
  /// about two thirds of the time, but leaves a uniform patch after another's warm start
  /// at 4.8 sigma, its centre 1 mm off: not the default.
  int max_iterations = 40;
  double tolerance = 1e-6;        ///< stop when |grad|^2 of the dual falls below this x m
};

struct SurfacePressure {
  bool ok = false;
  std::string fault;                  ///< why not ok
  Eigen::VectorXd cell_force_N;       ///< normal force per cell [N], >= 0 (all 0 when not ok)
  double normal_force_N = 0;          ///< sum of cell_force_N
  Eigen::Vector2d shear_N = Eigen::Vector2d::Zero();  ///< tangential force, pad frame [N]
  Eigen::Vector2d centroid_mm = Eigen::Vector2d::Zero();  ///< force-weighted centre [mm]
  double rms_sigma = 0;               ///< RMS residual over the weighted readings [noise]
  int iterations = 0;                 ///< Newton iterations, both passes
  int evaluations = 0;                ///< products A^T (a line search's direction), both passes
  bool second_pass = false;           ///< the tangential force read above noise: refitted without it
  int active_cells = 0;               ///< cells with load
};

class SurfacePressureInversion {
 public:
  /// From a three-axis profile with a forward model (its params unless `params` is given);
  /// throws std::invalid_argument otherwise, or for options out of range.
  SurfacePressureInversion(const SensorProfile& profile, SurfacePressureOptions options = {});
  SurfacePressureInversion(const SensorProfile& profile, const TactileModelParams& params,
                           SurfacePressureOptions options);

  /// Readings [N], out(3 k + a) as TactileForwardModel::Predict gives them; `valid` per
  /// taxel (empty: all valid). Result valid until the next call.
  const SurfacePressure& Solve(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid = {});
  /// A scan (sensors::ScanReadings_N; saturated taxels left out: their reading is a bound).
  const SurfacePressure& Solve(const Scan& scan);

  int cell_count() const { return grid_n_ * grid_n_; }
  int grid_n() const { return grid_n_; }           ///< cells per row (x along columns)
  double cell_mm() const { return options_.cell_mm; }
  Eigen::Vector2d CellCentre_mm(int cell) const;   ///< sensor pad frame
  /// Readings [N] of a cell field and a tangential force (the model the solve inverts).
  Eigen::VectorXd Predict(const Eigen::VectorXd& cell_force_N, const Eigen::Vector2d& shear_N) const;
  const SurfacePressureOptions& options() const { return options_; }
  /// Forgets the last scan's dual (the next Solve starts cold).
  void ResetWarmStart() { y_.setZero(); }

 private:
  /// One pass: the field for weighted readings (target - shear part), warm-started from y_.
  int SolvePass(const Eigen::VectorXd& w, const Eigen::VectorXd& target_N);
  /// Standard deviation of the tangential force's estimate on the current field [N].
  double ShearSigma_N(const Eigen::VectorXd& w, double total) const;
  /// Predict on the scaled unknowns u = force / inv_scale_.
  Eigen::VectorXd PredictScaled(const Eigen::VectorXd& u, const Eigen::Vector2d& shear_N) const;

  SensorProfile profile_;
  SurfacePressureOptions options_;
  int grid_n_ = 0;
  double x0_mm_ = 0, y0_mm_ = 0;
  Eigen::MatrixXd A_;             // readings per unit of each cell's unknown (scaled columns), 3 #taxels x #cells
  Eigen::MatrixXd At_x_, At_y_;   // the same per unit tangential force on each cell
  Eigen::VectorXd inv_sigma_;     // per reading [1/N]
  Eigen::VectorXd inv_scale_;     // per cell: force per unit of its unknown [N]
  double mu_scale_ = 0, lambda_ = 0;
  // Scratch.
  SurfacePressure result_;
  Eigen::VectorXd y_, g_, corr_;
  Eigen::MatrixXd J_, As_;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> ridge_dual_;  // I + W A A^T W / lambda, every taxel valid
  std::vector<int> active_;
  int evaluations_ = 0;
};

}  // namespace sedbridge::sensors
