#pragma once
// One case of the fidelity benchmark (fidelity_benchmark.h): the follower sensor's scans of
// a press and the truth behind them — the objects and the load they put on the sensor.
//
// Two sources:
//  - calibration-rig presses (config/sensors/rig_uskin_4x4/): recorded scans, the object
//    and force from cases.json, the load over time from the rig's protocol;
//  - a synthetic set: the simulated sensor pressed by shapes the rig did not use — spheres
//    2-15 mm, rods 0.5-3 mm at several yaws, a flat, a box edge and a box corner, two
//    spheres at once, a sphere sliding with friction, and flat faces (a rectangular punch,
//    a round one and a bar) — with 2-count noise. Its pad is by
//    default the rig-fitted elastomer layer (sensors::RigFittedLayerPad: the simulated pad
//    that reproduces the rig's presses best), whose pressure goes through the calibrated
//    kernels; the reconstruction's Hertz patches and uniform flats are only approximations
//    of it. The kernel pad (Winkler pressure) and the half-space pad are the other choices.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/geometry/rigid_object.h"
#include "sensors/simulated/simulated_sensor.h"
#include "sensors/calibration_press.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::fidelity {

struct FidelityCase {
  std::string name;    ///< e.g. "press_03" or "edge_r1_yaw30"
  std::string label;   ///< what the object is, for tables ("sphere R5 (0, 0)", "box corner")
  std::vector<sensors::Scan> scans;
  std::vector<double> t_s;             ///< per scan, since the first
  std::vector<Eigen::Vector3d> load_N; ///< per scan: true load on the pad (x, y tangential, z normal)
  /// True objects in the pad frame, posed at first touch (the leader's press pushes them
  /// along -z_pad from here); given the x-y pose of scan `pose_scan`... see ObjectsAt.
  std::vector<geometry::RigidObject> objects;
  /// The truth as a primitive where it is one (rig presses, spheres, rods, flats).
  bool has_primitive = false;
  sensors::ContactPrimitive primitive;

  /// The objects posed for the leader at scan k: the x-y (and orientation) they have at
  /// that scan, lifted to their height at the first scan (above the pad).
  std::vector<geometry::RigidObject> ObjectsAt(size_t k) const;
};

/// What the random presses of SyntheticFidelityCases are drawn from.
enum class RandomRanges {
  /// Like the rig's presses: spheres 2-15 mm within 6 mm of the pad centre (x and y),
  /// 0.3-0.8 mm deep; rods 0.5-3 mm within 4 mm, 0.1-0.3 mm deep; flats 0.02-0.05 mm;
  /// strokes of 4-10 mm spheres (the sets the reconstruction's changes are judged by).
  kRig,
  /// Past the rig's: spheres 1.5-20 mm within 7 mm, 0.15-1.1 mm deep; rods 0.4-4 mm within
  /// 6 mm, 0.05-0.45 mm deep; flats 0.01-0.08 mm; strokes as kRig. Forces from under 0.1 N
  /// to several N on the layer pad: where the bridge holds outside what it was calibrated on.
  kWide,
};
const config::EnumNames<RandomRanges>& NamesOf(RandomRanges);

/// A calibration-rig press as a case.
FidelityCase FromCalibrationPress(const sensors::CalibrationPress& press);

/// The synthetic set (see the file comment), simulated with `profile` (needs forward_model)
/// and the pad mechanics `pad` (kKernel: Winkler pressure, a contact law the rig presses do
/// not fit; kHalfSpace: the elastic half-space's, Hertz's for a sphere; kLayer: the rig's
/// elastomer as a layer on a rigid base, sensors::RigFittedLayerPad()).
/// random_count > 0: instead of the fixed set, that many presses drawn with `seed` from
/// `ranges` (spheres, rods at any yaw, flats, strokes; places, sizes and depths the rig did
/// not use): the closest thing here to presses of this sensor not seen before. Each
/// drawn press has its own sensor-noise stream (from `seed` and its index); the fixed set's
/// presses share the stream `seed`. The simulated sensor sees every object as it is; a rod or
/// sphere thinner than the leader holds (kLeaderMinRodRadius_mm, kLeaderMinSphereRadius_mm)
/// is pressed on the leader for the truth at that minimum, as the rig presses' truths are.
/// random_faces > 0: that many flat faces drawn after them (rectangular punches, round ones
/// and bars in turn, from a stream of their own: the random_count presses stay as they were,
/// and so do their rows), named on from random_count; the same for either ranges.
std::vector<FidelityCase> SyntheticFidelityCases(const sensors::SensorProfile& profile, uint64_t seed = 1,
                                                 sensors::PadMechanics pad = sensors::PadMechanics::kLayer,
                                                 int random_count = 0,
                                                 RandomRanges ranges = RandomRanges::kRig, int random_faces = 0);

/// Presses no contact primitive holds, on the simulated sensor (`fidelity --synthetic
/// --beyond-primitives`): a grating of four bars, a cross of two rods, three spheres at once
/// (the model-adequacy tests' shapes) and a tilted block; each its own noise stream from
/// `seed`. What the bridge's fallback (the pressure map or the surface pressure) is for.
std::vector<FidelityCase> BeyondPrimitiveFidelityCases(const sensors::SensorProfile& profile, uint64_t seed = 1,
                                                       sensors::PadMechanics pad = sensors::PadMechanics::kLayer);
/// The calibration rig's presses re-made on the simulated sensor: each press's object, at
/// its place, pressed into the simulated pad `pad` to the depth at which the pad carries the
/// press's hold force (sensors::EvaluatePadOnPresses), with the synthetic set's timing and
/// 2-count noise, a stream per press from `seed`. A stroke (the rig's tangential load) slides
/// 3 mm along its load, centred on the rig's place, with friction equal to the load's ratio.
/// Run beside the recorded presses, it says how far the simulated pad (and so the random
/// sets) stands in for the rig: where the two read an object differently, a random set's
/// result says more about the pad than about the bridge. Presses the pad cannot carry
/// (EvaluatePadOnPresses' `reached` false) are left out.
std::vector<FidelityCase> CalibrationPressesOnSimulatedPad(const std::vector<sensors::CalibrationPress>& presses,
                                                           const sensors::SensorProfile& profile, uint64_t seed = 1,
                                                           sensors::PadMechanics pad = sensors::PadMechanics::kLayer);

}  // namespace sedbridge::fidelity
