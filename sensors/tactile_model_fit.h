#pragma once
// Calibrates the tactile forward model (tactile_forward_model.h) to indentation-stage
// presses, as a lab calibrates a physical sensor: weighted nonlinear least squares
// (Eigen's Levenberg–Marquardt, a MINPACK port that ships with Eigen: 17 unknowns and ~3000
// residuals need nothing larger) over, per press, the mean reading of the hold and of two
// windows on the ramp, each residual divided by the single-scan noise of its axis. Two fits
// run and the lower chi^2 is kept: every unknown at once from the start, and in stages (the
// normal load's unknowns; the tangential kernels, which only presses with a traction see,
// from several starts; then all): the one-start fit stalled when a single stroke was left to
// calibrate the tangential kernels (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s15).

#include <functional>
#include <string>
#include <vector>

#include "sensors/calibration_press.h"
#include "sensors/tactile_model_params.h"

namespace sedbridge::sensors {

struct FitOptions {
  double noise_counts = 2;   ///< single-scan noise (1 sigma) of every raw reading [counts]
  int max_evaluations = 4000;
  /// Ramp windows besides the hold: their centres in the rig's protocol (PressProtocol{});
  /// a press with another protocol is read at the same load fractions (FromRigTime_s).
  std::vector<double> ramp_times_s = {0.5, 0.8};
  double window_half_s = 0.02;
  /// Called with a line as each stage of the fit starts (a fit takes ~20 s on 21 presses);
  /// empty: silent.
  std::function<void(const std::string&)> progress;
};

struct PressFitReport {
  std::string name;
  /// RMS of (predicted - measured) over the hold window, per axis x, y, z, in units of
  /// the single-scan noise: about 1 means "reproduced within noise".
  double rms_sigma[3] = {0, 0, 0};
  double measured_sum_z_N = 0;   ///< sum of normal readings in the hold
  double predicted_sum_z_N = 0;
};

struct FitReport {
  TactileModelParams params;
  std::vector<PressFitReport> presses;
  double rms_sigma_all = 0;  ///< over every residual used
  int evaluations = 0;
  std::string status;        ///< the solver's stop reason
};

/// Fits `initial` to `presses` (taken with `profile`). Deterministic.
FitReport FitTactileModel(const std::vector<CalibrationPress>& presses, const SensorProfile& profile,
                          const TactileModelParams& initial, const FitOptions& options = {});

/// The hold-window report of `params` on `presses`, without fitting.
std::vector<PressFitReport> EvaluateTactileModel(const std::vector<CalibrationPress>& presses,
                                                 const SensorProfile& profile, const TactileModelParams& params,
                                                 const FitOptions& options = {});

/// One rod press's hold read back as a rod: the radius that best explains its hold mean.
struct RodRadiusReport {
  std::string name;
  double true_radius_mm = 0;
  double fitted_radius_mm = 0;  ///< pose, force, shear and radius all free
  double chi2 = 0;              ///< of the hold mean, in units of its own noise
};

/// For every rod (cylinder) press: the radius at which `params` explains the mean of its hold
/// best, with the pose, force and shear free too (Levenberg–Marquardt from several radii, no
/// prior). What rod_min_halfwidth_mm calibrates: a line contact's band width is what the
/// taxels see of a rod's radius, so the model reads a rod at its true radius only if its
/// band is as wide as the sensor's. A rod far thinner than the band reads towards 0.
std::vector<RodRadiusReport> FitRodRadii(const std::vector<CalibrationPress>& presses, const SensorProfile& profile,
                                         const TactileModelParams& params, const FitOptions& options = {});

/// Defaults a fit starts from (a soft pad, kernels of about one taxel pitch).
TactileModelParams InitialTactileModelParams();

}  // namespace sedbridge::sensors
