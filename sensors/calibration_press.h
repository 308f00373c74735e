#pragma once
// Indentation-stage calibration presses of a tactile sensor (config/sensors/rig_uskin_4x4/):
// candump logs of known objects pressed to known forces, indexed by a cases.json. They are
// what `sedbridge fit-sensor` calibrates the forward model to and what the fidelity
// benchmark runs on.
//
// cases.json: {"cases": [{"object": {"shape": "sphere"|"cylinder"|"flat"|"punch"|"pair",
//   "position_mm": [x, y], "radius_mm": R, "yaw_deg": yaw, "length_mm": L, "traction": [tx, ty],
//   "half_size_mm": [a, b], "objects": [{...}, {...}], "split": [s1, s2]},
//   "force_N": F, "log": "press_00.log"}, ...]}  (traction: tangential force / normal force;
//   length_mm: a finite rod's; half_size_mm: a punch's; objects and split: a pair's)
// Every press follows the rig's protocol: 0.3 s unloaded, a linear ramp to F over 0.7 s,
// 0.5 s hold, a 0.3 s linear release, then unloaded.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/name_value.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {

/// A calibration press's load over time [s]: unloaded, a linear ramp of the normal force
/// to its peak, a hold, a linear release, unloaded again. The defaults are the shipped rig's
/// (config/sensors/rig_uskin_4x4); a cases file whose stage ran another protocol says so
/// with a top-level `protocol:` (config/sensors/README.md).
struct PressProtocol {
  double unloaded_s = 0.3;
  double ramp_s = 0.7;
  double hold_s = 0.5;
  double release_s = 0.3;
  /// Fraction of the peak force at time t since the first scan.
  double LoadFraction(double t_s) const;
  /// Middle of the hold [s].
  double HoldMid_s() const { return unloaded_s + ramp_s + 0.5 * hold_s; }
  /// The time in this protocol at the point of the ramp where the rig's protocol
  /// (PressProtocol{}) is at t_rig_s: windows placed on the rig's ramp (fit-sensor's ramp
  /// windows) read other protocols at the same load fraction. t_rig_s itself for the rig's.
  double FromRigTime_s(double t_rig_s) const;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(config::Field("unloaded_s", &unloaded_s).Unit("s").NonNegative());
    a->Visit(config::Field("ramp_s", &ramp_s).Unit("s").Positive());
    a->Visit(config::Field("hold_s", &hold_s).Unit("s").Positive());
    a->Visit(config::Field("release_s", &release_s).Unit("s").NonNegative());
  }
};

/// What a press's object is in cases.json: the forward model's primitives (sphere, cylinder,
/// flat), a rigid flat-faced punch, or a pair of objects pressed together by one holder. The
/// forward model has no punch and no pair (yet): their presses are data for the fidelity
/// benchmark, not for fit-sensor (PrimitivePresses).
enum class PressShape { kSphere, kCylinder, kFlat, kPunch, kPair };
const config::EnumNames<PressShape>& NamesOf(PressShape);

/// One rigid object of a press at the peak force, in the pad frame: a primitive's shape,
/// or a punch. A pair's objects each carry their split of the press's load.
struct PressedObject {
  PressShape shape = PressShape::kSphere;  ///< never kPair
  /// Pose, size and this object's share of the load at the peak (force_N x share, traction
  /// included). Its `shape` is the primitive's for a sphere, cylinder or flat; a punch uses
  /// x_mm, y_mm, yaw_deg and the loads only.
  ContactPrimitive primitive;
  /// A punch's half sizes along its own axes [mm] (a along (cos yaw, sin yaw)); its edges are
  /// sharp (the rig's: rounded by 0.2 mm at most).
  double half_size_mm[2] = {0, 0};
  double share = 1;  ///< of the press's force
};

struct CalibrationPress {
  std::string name;               ///< log file name without directory, e.g. "press_03.log"
  std::string log_path;           ///< resolved path of the log
  PressShape shape = PressShape::kSphere;  ///< the case's object
  /// The object at the peak force (force_N, traction x force) as the forward model's
  /// primitive: only when is_primitive() (a sphere, cylinder or flat); else default.
  ContactPrimitive object;
  /// Every object pressed (one; a pair's two), each with its share of the load; a
  /// primitive's one is `object` as loaded (the code that presses it reads `object`).
  std::vector<PressedObject> objects;
  /// The forward model can predict this press (its object is a sphere, cylinder or flat).
  bool is_primitive() const { return shape != PressShape::kPunch && shape != PressShape::kPair; }
  std::vector<double> t_s;        ///< scan times since the first scan
  std::vector<Eigen::VectorXd> readings_N;  ///< per scan, 3 x #taxels (x, y, z per taxel) [N]
  std::vector<Scan> scans;        ///< the assembled scans themselves
  PressProtocol protocol;         ///< the cases file's (the rig's by default)
  /// The object at time t (force and traction scaled by the press's protocol).
  ContactPrimitive ObjectAt(double t_s) const;
  /// Mean reading over scans with t in [t0, t1] (3 x #taxels) [N].
  Eigen::VectorXd MeanReadings(double t0_s, double t1_s) const;
};

/// A scan's readings as forces per taxel [N]: x, y shear and z normal, 3 x #taxels
/// (pressures times the taxel area). Invalid taxels read 0.
Eigen::VectorXd ScanReadings_N(const Scan& scan, const SensorProfile& profile);

/// Force per raw count of one channel [N/count], whatever unit the profile calibrates to
/// (N; or Pa / kPa times the taxel area), taxel gain included: the scale that turns count
/// noise and full-scale readings into readings_N.
double NewtonsPerCount(const SensorProfile& profile, int taxel, int axis);

/// The presses whose object the forward model knows (is_primitive()), in order: what
/// fit-sensor fits and evaluates, and what the simulated pad re-makes.
std::vector<CalibrationPress> PrimitivePresses(std::vector<CalibrationPress> presses);

/// Loads cases.json and decodes every log it names (paths relative to the JSON) with
/// `profile`. Throws config::ConfigError naming file:line:column for a bad entry, and
/// std::runtime_error for an unreadable or empty log.
std::vector<CalibrationPress> LoadCalibrationPresses(const std::string& cases_json, const SensorProfile& profile);

}  // namespace sedbridge::sensors
