#pragma once
// One scan's taxel readings made safe for the FE: registered into the leader's pad frame,
// invalid taxels handled, non-finite values never passed on. This is the input of an FE step
// (fe_step.h) and of the pressure boundary condition (pressure_boundary_condition.h).
//
// Invalid taxels (missing, saturated, non-finite, stale: sensors::Scan::valid == 0):
//   fill  (default)  the value is the Gaussian-weighted mean of the valid taxels (same kernel
//                    width as the traction interpolation), so one dead taxel does not punch a
//                    hole in the load, capped at the weakest valid taxel of its nearest ring
//                    (0 without one): a fill never exceeds what its valid neighbours support;
//   zero             the taxel reads 0.
// A scan is rejected (not stepped; the display goes to its safe state) when its taxel count
// or vector lengths do not match the profile, or more than `max_invalid_fraction` of its
// taxels are invalid. A value that is NaN/Inf in a taxel marked valid is treated as invalid
// and counted.
//
// Pressure below `noise_floor_Pa` (including any negative value) becomes 0: a sensor pad
// cannot pull on the skin, and tare noise would otherwise do so.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bridge/pipeline_status.h"
#include "bridge/pad_registration.h"
#include "common/enum_names.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

/// Taxel tractions in the leader's pad frame, all finite.
struct TaxelValues {
  int64_t scan_utime = 0;            ///< receive time of the scan [us]
  std::vector<double> pressure_Pa;   ///< per taxel, compression positive (>= 0)
  std::vector<double> shear_x_Pa;    ///< per taxel along pad x (after registration); empty = normal only
  std::vector<double> shear_y_Pa;    ///< per taxel along pad y
  double total_force_N = 0;          ///< measured normal force: sum_i pressure_Pa[i] * pad area_i
  /// The scan these values came from, unconditioned (contact reconstruction reads the raw
  /// readings and saturation flags). Set by ScanConditioner::Condition; valid only while
  /// that scan lives (one pipeline step).
  const sensors::Scan* scan = nullptr;
};

enum class InvalidTaxelPolicy { kFill, kZero };
/// "fill", "zero" (bridge key traction.invalid_taxels). Inline: the YAML fuzzer links the
/// config readers without the stages.
inline const config::EnumNames<InvalidTaxelPolicy>& NamesOf(InvalidTaxelPolicy) {
  static const config::EnumNames<InvalidTaxelPolicy> names{{InvalidTaxelPolicy::kFill, "fill"},
                                                           {InvalidTaxelPolicy::kZero, "zero"}};
  return names;
}

struct ScanConditioningOptions {
  InvalidTaxelPolicy invalid = InvalidTaxelPolicy::kFill;
  double max_invalid_fraction = 0.5;  ///< more invalid taxels than this -> scan rejected
  double noise_floor_Pa = 0;          ///< pressure below this -> 0 [Pa]
  double fill_sigma_mm = 0;           ///< fill kernel width, sensor mm (0 = half the smallest taxel spacing)
};

/// What conditioning did to one scan.
struct ConditioningReport {
  bool usable = true;        ///< false: do not step; `reject_reason` and `reason` say why
  RejectReason reject_reason = RejectReason::kWrongTaxelCount;  ///< when not usable
  std::string reason;        ///< detail text, e.g. "9 of 16 taxels invalid"
  int invalid_taxels = 0;    ///< taxels with valid == 0 or a non-finite value
  int nonfinite_values = 0;  ///< NaN/Inf values found in taxels marked valid
};

/// Smallest distance between two taxel centres [mm] (0 for fewer than two taxels).
double SmallestTaxelSpacing_mm(const std::vector<sensors::TaxelPosition>& taxels);

class ScanConditioner {
 public:
  /// `profile` gives taxel positions and areas; `registration` maps them onto the pad.
  ScanConditioner(const sensors::SensorProfile& profile, const PadRegistration& registration,
                  ScanConditioningOptions options = {});

  /// Fills `out` from `scan` (out's vectors are reused). On a rejected scan `out` is left
  /// in an unspecified but finite state.
  ConditioningReport Condition(const sensors::Scan& scan, TaxelValues* out) const;

  /// Taxel area on the leader's pad [m^2] (sensor area * scale^2), per taxel.
  const std::vector<double>& pad_area_m2() const { return pad_area_m2_; }
  int num_taxels() const { return num_taxels_; }
  bool has_shear() const { return has_shear_; }

 private:
  int num_taxels_ = 0;
  bool has_shear_ = false;
  ScanConditioningOptions options_;
  Eigen::Matrix2d rotation_;
  std::vector<double> pad_area_m2_;
  Eigen::MatrixXd fill_kernel_;  // Gaussian weights between taxel centres
  std::vector<uint8_t> adjacent_;  // i * n + j: j is in i's nearest ring
  mutable std::vector<uint8_t> ok_;
};

}  // namespace sedbridge::bridge
