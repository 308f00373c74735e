#pragma once
// How well a leader model resolves the truth itself: an object pressed at a given force
// at several sub-node shifts of its place. The leader's skin carries contact points about
// 1 mm apart on model B; a light touch's patch spans a few of them, so where the object
// lands between points moves its Merkel SED. A truth whose peak moves by a fifth under a
// quarter-millimetre shift cannot score a bridge to better than that. The spread over the
// shifts, model by model (B, B_fine: the same layers on a finer mesh) and with node or face
// contact, says at which force the truth is resolved and by which model.
//
// `sedbridge fidelity --truth-resolution MODELS` runs it on the rig's light presses.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "sensors/contact_primitive.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::model {
struct FingertipModel;
}
namespace sedbridge::scene {
class FingertipCompliance;
}

namespace sedbridge::fidelity {

/// One press of the study: an object at one shift.
struct TruthShiftRow {
  std::string object;      ///< the caller's label ("press_25 sphere R4")
  std::string model;       ///< leader model name
  bool face_contact = false;
  double force_N = 0;
  double dx_mm = 0, dy_mm = 0;  ///< shift of the object from its place [mm]
  bool reached = false;         ///< the press reached the force on the patch (else not scored)
  double depth_mm = 0;          ///< indentation at the force [mm]
  double peak_sed_Pa = 0;       ///< largest Merkel-vertex SED [Pa]
  /// Merkel SED summed over the layer's vertices [Pa]: a measure of the whole field that
  /// sampling the peak on one vertex or another does not move as much.
  double sum_sed_Pa = 0;
  int contact_points = 0;       ///< contact points carrying load at the force
};

/// The spread of one (object, model, contact) over its reached shifts.
struct TruthSpread {
  int reached = 0, shifts = 0;
  double peak_median_Pa = 0;
  double peak_min_over_max = 0;  ///< min / max of the peak SED over the shifts (1: resolved)
  double sum_min_over_max = 0;   ///< the same for the summed SED
};

/// Shifts on a square grid, `step_mm` apart, `per_side` to a side, from (0, 0): the cell of
/// the skin's contact points that a shift up to about half their spacing samples.
std::vector<Eigen::Vector2d> ShiftGrid(double step_mm, int per_side);

/// One leader model pressed again and again: the model and its compliance precompute loaded
/// once (`cache_dir`: the compliance cache, "" = none), with node or face contact. Throws
/// std::runtime_error if the model cannot load.
class ShiftedTruthLeader {
 public:
  ShiftedTruthLeader(const std::string& model_name, bool face_contact, const std::string& cache_dir);
  ~ShiftedTruthLeader();

  /// Presses `object` (pad frame, ToRigidObject's pose: lowest point on the pad at (x, y)) to
  /// `force_N` at each shift, each from no warm start.
  std::vector<TruthShiftRow> PressAtShifts(const std::string& label, const sensors::ContactPrimitive& object,
                                           double force_N, const std::vector<Eigen::Vector2d>& shifts_mm);

 private:
  std::string model_name_;
  bool face_contact_;
  std::unique_ptr<model::FingertipModel> model_;
  std::unique_ptr<scene::FingertipCompliance> leader_;
};

/// The spread of `rows` (one object, model and contact).
TruthSpread SpreadOf(const std::vector<TruthShiftRow>& rows);

/// What one scan's noise leaves open about a sphere's or rod's radius: the Cramér–Rao bound
/// on log R (1 sigma) from the sensor's forward model at `object`, with the place (a rod's:
/// across its axis), the force and log R unknown together (a rod's yaw held), `noise_counts` per raw reading (1 sigma,
/// white), unsaturated channels. A hold's mean of N scans divides it by sqrt(N). Throws
/// std::invalid_argument for a profile without a forward model or an object that is not a
/// sphere or a rod.
double LogRadiusSigmaPerScan(const sensors::SensorProfile& profile, const sensors::ContactPrimitive& object,
                             double noise_counts);

/// truth_resolution.csv: one row per press (TruthShiftRow's fields).
void WriteTruthShiftCsv(const std::string& path, const std::vector<TruthShiftRow>& rows);

}  // namespace sedbridge::fidelity
