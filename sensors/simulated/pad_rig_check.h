#pragma once
// How well a simulated pad reproduces the calibration rig's presses
// (config/sensors/rig_uskin_4x4/): each press's object is lowered into the simulated pad
// until the pad carries the press's hold force, the rig's tangential force is spread over
// the pad's pressure (as the forward model spreads it), the profile's kernels carry the
// loads to the taxels, and the readings are compared with the hold's mean. The same measure
// `fit-sensor --evaluate` reports for the forward model itself, so the two read side by
// side: which contact law (Winkler, half-space, a layer of some thickness) the rig says.

#include <string>
#include <vector>

#include "sensors/calibration_press.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::sensors {

/// The uskin_4x4 rig's elastomer as a layer pad (mechanics kLayer): 2.5 mm thick, E = 230 kPa,
/// nu = 0.2, the best of a grid search of EvaluatePadOnPresses over thickness 0.5-8 mm, E
/// 100-280 kPa, nu 0.1-0.49: 19 of the 21 presses within noise on every axis, against 10
/// for the half-space pad and 7 for the kernel (Winkler) pad
/// (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s1).
PadModel RigFittedLayerPad();

struct PadPressReport {
  std::string name;
  /// RMS of (simulated - measured hold mean) per axis x, y, z, in single-scan noise units.
  double rms_sigma[3] = {0, 0, 0};
  /// The same on the ramp at 0.29 of the hold force (mean of 0.48-0.52 s): light contact.
  double ramp_rms_sigma[3] = {0, 0, 0};
  double depth_mm = 0;   ///< how far the object went into the pad to carry the hold force
  bool reached = false;  ///< the force was reached within 3 mm (or the radius) of depth (else: not scored)
};

/// Presses every calibration press's hold, and its ramp at 0.29 of the force, into `pad` (its mechanics kernel, halfspace or
/// layer; position and friction ignored). Deterministic.
/// @param noise_counts single-scan noise (1 sigma) of every raw reading [counts]
/// Throws std::invalid_argument for a winkler pad or a profile without a forward model.
std::vector<PadPressReport> EvaluatePadOnPresses(const std::vector<CalibrationPress>& presses,
                                                 const SensorProfile& profile, const PadModel& pad,
                                                 double noise_counts = 2);

}  // namespace sedbridge::sensors
