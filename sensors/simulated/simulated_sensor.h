#pragma once
// Simulated follower sensor: a taxel grid on an elastomer pad touching rigid scene objects
// (geometry::RigidObject: plane, sphere, edge, grating, ... on trajectories), encoded into
// CAN frames with the same profile the decoder uses, plus optional noise, dropouts and bit
// errors (seeded, deterministic).
//
// Contact model (elastic foundation / Winkler layer, Johnson "Contact Mechanics" §5.8):
// the pad is an elastomer layer of thickness h on a rigid base; its surface is the pad-frame
// plane z = 0 with outward normal +z. Each surface point q is an independent spring:
//     penetration  d(q) = how far below q (along -z) the deepest object's surface lies,
//                         0 outside every object (found by sphere tracing the SDF)  [m]
//     pressure     p(q) = E_eff * d(q) / h                     [Pa]
//     E_eff = E (1 - nu) / ((1 + nu)(1 - 2 nu))   (confined layer; nu = 0 gives E_eff = E)
// A taxel reports the mean of p over its sensing area (subsamples x subsamples points),
// optionally blurred with a Gaussian of `smoothing_mm` over the taxel centres (the skin
// spreads load over neighbours). Shear (3-axis profiles): sliding friction
//     tau = mu * p * (tangential velocity of the object at q) / |velocity|,
// zero when the object does not slide. The model ignores lateral coupling in the layer
// and large-deformation effects; it is a plausible, documented signal source, not a
// replacement for the FE model.
//
// `model: kernel` puts the same Winkler pressure on the forward model's cell grid and lets
// the profile's calibrated kernels carry it to the taxels (neighbours and shear channels
// respond, as on the rig). `model: halfspace` keeps the kernels but takes the pressure of an
// elastic half-space (E* = forward_model.contact_modulus_kPa) in contact with the objects
// (elastic_pad_contact.h): Hertz's law for curved objects, which the rig presses fit;
// Winkler's is wider for the same object. `model: layer` is that elastomer as a layer of
// thickness_mm (poisson_ratio) on a rigid base: Hertz's law for contacts small against
// the layer, the confined columns of Winkler's law for contacts much wider (a flat).
// Friction as above, from any of these pressures.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/geometry/rigid_object.h"
#include "common/name_value.h"
#include "sensors/can_frame.h"
#include "sensors/frame_source.h"
#include "sensors/sensor_profile.h"
#include "sensors/simulated/elastic_pad_contact.h"
#include "sensors/tactile_forward_model.h"
#include "sensors/taxel_codec.h"

namespace sedbridge::sensors {

/// How the pad turns contact into taxel readings.
enum class PadMechanics {
  kWinkler,  ///< each taxel averages the Winkler pressure over its own area (no spreading)
  kKernel,   ///< Winkler pressure on the forward model's grid, spread to the taxels by the
             ///< profile's calibrated kernels (sensors/tactile_forward_model.h): neighbours
             ///< respond, shear channels see normal presses, part of the load is lost, as in
             ///< a real elastomer. Needs a profile with `forward_model`.
  kHalfSpace,  ///< as kKernel, but the pressure of an elastic half-space in contact with the
               ///< objects (sensors/simulated/elastic_pad_contact.h; E* = the forward model's
               ///< contact_modulus_kPa, solved on cells of about 0.5 mm): Hertz's law, which
               ///< the rig presses fit, for any shape. Needs a profile with `forward_model`.
  kLayer,      ///< as kHalfSpace, for the pad's elastomer (youngs_modulus_kPa, poisson_ratio)
               ///< as a layer of thickness_mm bonded to a rigid base: Hertz's law while a
               ///< contact is small against the layer, nearly uniform pressure under a flat
               ///< much wider than it (the layer's columns), as the rig presses show both.
};
/// "winkler", "kernel", "halfspace", "layer" (key sensor.pad.model).
const config::EnumNames<PadMechanics>& NamesOf(PadMechanics);

struct PadModel {
  PadMechanics mechanics = PadMechanics::kWinkler;  ///< key `model: winkler | kernel | halfspace | layer`
  double thickness_m = 3e-3;         ///< elastomer layer thickness h (winkler, kernel, layer)
  double youngs_modulus_Pa = 300e3;  ///< E of the elastomer (winkler, kernel, layer)
  double poisson_ratio = 0.0;        ///< nu, in [0, 0.5) (winkler, kernel, layer)
  double friction_coefficient = 0;   ///< mu for shear (3-axis profiles)
  int subsamples = 3;                ///< per taxel edge, for area averaging
  double smoothing_m = 0;            ///< Gaussian sigma over taxel centres (0 = off)
  /// Pose of the pad frame in the scene frame (objects live in the scene frame).
  Eigen::Isometry3d scene_from_pad = Eigen::Isometry3d::Identity();

  /// E_eff of the layer [Pa].
  double EffectiveModulus_Pa() const;

  /// Keys of `sensor.pad`; `position_mm` and `rpy_deg` (default [0, 0, 0]) are read by
  /// LoadSimulatedSensorScene into scene_from_pad.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("model", &mechanics));
    a->Visit(Field("thickness_mm", &thickness_m).Positive().Scale(1e-3));
    a->Visit(Field("youngs_modulus_kPa", &youngs_modulus_Pa).Positive().Scale(1e3));
    a->Visit(Field("poisson_ratio", &poisson_ratio).Within({0, 0.5, false, true}));
    a->Visit(Field("friction_coefficient", &friction_coefficient).NonNegative());
    a->Visit(Field("subsamples", &subsamples).InRange(1, 16));
    a->Visit(Field("smoothing_mm", &smoothing_m).NonNegative().Scale(1e-3));
    a->HandRead("position_mm");
    a->HandRead("rpy_deg");
  }
};

/// Longest simulated run [s] (a scene asking for more is refused, not run until killed).
constexpr double kMaxSimulatedDuration_s = 86400;

struct SimulationNoise {
  uint64_t seed = 1;
  double stddev_counts = 0;          ///< Gaussian noise added to every raw reading
  double dropout_probability = 0;    ///< a frame is not sent
  double bit_error_probability = 0;  ///< each payload bit flips independently

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("seed", &seed));
    a->Visit(Field("stddev_counts", &stddev_counts).NonNegative());
    a->Visit(Field("dropout_probability", &dropout_probability).InRange(0, 1));
    a->Visit(Field("bit_error_probability", &bit_error_probability).InRange(0, 1));
  }
};

/// Everything a simulated-sensor scene file (config/scenes/sensor_*.yaml) describes.
struct SimulatedSensorConfig {
  SensorProfile profile;
  PadModel pad;
  SimulationNoise noise;
  std::vector<geometry::RigidObject> objects;
  double duration_s = 1.0;
  int64_t start_utime = 1700000000000000;  ///< time stamp of scan 0 [us]
  std::string interface = "can0";
  /// Spacing of consecutive frames of one scan on the bus [us] (about one classic 8-byte
  /// frame at 1 Mbit/s); squeezed if the scan period is shorter.
  int64_t frame_spacing_us = 130;
};

/// Loads a scene:
///   sensor:
///     profile: uskin_4x4            # shipped name or path (optional if given in code/CLI)
///     interface: can0               # optional
///     start_utime: 1700000000000000 # optional
///     duration_s: 2.0
///     pad: {model: winkler, thickness_mm: 3, youngs_modulus_kPa: 300, poisson_ratio: 0.0,
///           friction_coefficient: 0.5, subsamples: 3, smoothing_mm: 0,
///           position_mm: [0, 0, 0], rpy_deg: [0, 0, 0]}
///     noise: {seed: 1, stddev_counts: 2, dropout_probability: 0.0, bit_error_probability: 0.0}
///   objects: [...]                  # geometry::ParseRigidObjects
/// `profile_override` (non-empty) replaces sensor.profile. Throws config::ConfigError.
SimulatedSensorConfig LoadSimulatedSensorScene(const std::string& path,
                                               const std::string& profile_override = "");

/// Depth of `object`'s surface below the point `q_m` along the unit direction `inward`
/// (into the pad) at time t; 0 when q is outside the object. Scene frame, metres.
double PenetrationAlong(const geometry::RigidObject& object, const Eigen::Vector3d& q_m,
                        const Eigen::Vector3d& inward, double t_s);

/// Pad tractions at the taxels, before any encoding: the simulation's ground truth.
struct TaxelTractions {
  std::vector<double> pressure_Pa;  ///< per taxel, compression positive
  std::vector<double> shear_x_Pa;   ///< per taxel, pad frame
  std::vector<double> shear_y_Pa;
};

class SimulatedSensor {
 public:
  explicit SimulatedSensor(SimulatedSensorConfig config);

  /// Taxel tractions at time t (no noise).
  TaxelTractions Evaluate(double t_s) const;
  /// Total load the objects put on the pad at time t, pad frame [N] (the ground truth a
  /// load cell would read): x, y tangential, z pressing. Kernel, halfspace and layer pad
  /// models (zero for winkler).
  Eigen::Vector3d TotalLoad_N(double t_s) const;
  /// The pad's surface loads on the forward model's grid at time t (kernel, halfspace and
  /// layer pad models; empty for winkler): what the kernels carry to the taxels.
  void PadLoads(double t_s, std::vector<SurfaceLoad>* loads) const {
    if (kernel_model_) return KernelLoads(t_s, loads);
    loads->clear();
  }
  /// The profile's forward model the pad's loads go through (null for the winkler pad).
  const TactileForwardModel* forward_model() const { return kernel_model_.get(); }
  /// Ideal raw readings for `tractions` (inverse of the profile calibration, rounded).
  std::vector<int32_t> ToRawCounts(const TaxelTractions& tractions) const;

  /// Number of scans in the configured duration.
  int64_t scan_count() const;
  /// Time of scan k relative to the start [s].
  double ScanTime_s(int64_t k) const { return static_cast<double>(k) / config_.profile.scan_rate_Hz; }
  /// Appends the frames of scan k (noise, dropouts and bit errors applied) to `out`.
  /// Call with k = 0, 1, 2, ... in order for reproducible noise.
  void ScanFrames(int64_t k, std::vector<Frame>* out);

  const SimulatedSensorConfig& config() const { return config_; }
  /// Frames dropped and bits flipped so far.
  int64_t frames_dropped() const { return frames_dropped_; }
  int64_t bits_flipped() const { return bits_flipped_; }

 private:
  SimulatedSensorConfig config_;
  TaxelCodec codec_;
  std::mt19937_64 rng_;
  int64_t frames_dropped_ = 0, bits_flipped_ = 0;
  // Sub-sample offsets inside a taxel [m], pad frame.
  std::vector<Eigen::Vector2d> sub_offsets_m_;
  // Row-normalised Gaussian smoothing weights between taxels (empty = off).
  std::vector<double> smoothing_;
  // PadMechanics::kKernel, kHalfSpace and kLayer.
  std::shared_ptr<const TactileForwardModel> kernel_model_;
  // PadMechanics::kHalfSpace and kLayer: a contact solve per block size k (k x k cells), held by
  // pointer because its warm start changes from const evaluation.
  mutable std::map<int, std::shared_ptr<ElasticPadContact>> pad_contact_;
  /// Depth [m] of the deepest object below pad point `q_pad_m` at time t (0: none), and it.
  double Penetration_m(const Eigen::Vector3d& q_pad_m, double t_s, const geometry::RigidObject** deepest) const;
  /// Sliding friction traction (x, y) [Pa] of `object` at pad point q under pressure p.
  Eigen::Vector2d FrictionTraction_Pa(const geometry::RigidObject& object, const Eigen::Vector3d& q_pad_m, double t_s,
                                      double pressure_Pa) const;
  void ElasticPadLoads(double t_s, std::vector<SurfaceLoad>* loads) const;
  TaxelTractions EvaluateKernel(double t_s) const;
  /// The Winkler layer's traction at pad point `q_pad_m` (pad frame, z = 0) at time t:
  /// (shear x, shear y, pressure) [Pa], pressure from the deepest object, sliding friction.
  Eigen::Vector3d WinklerTraction_Pa(const Eigen::Vector3d& q_pad_m, double t_s) const;
  void KernelLoads(double t_s, std::vector<SurfaceLoad>* loads) const;
};

/// The simulated sensor as a FrameSource (as fast as possible; frames carry simulated
/// utimes). Done after the configured duration.
class SimulatedSensorSource final : public FrameSource {
 public:
  explicit SimulatedSensorSource(SimulatedSensorConfig config);
  std::optional<Frame> Next(int64_t timeout_us) override;
  bool Done() const override { return done_; }
  void Close() override { done_ = true; }
  FrameSourceStats Stats() const override { return stats_; }
  std::string Describe() const override;
  const SimulatedSensor& sensor() const { return sensor_; }

 private:
  SimulatedSensor sensor_;
  std::vector<Frame> pending_;
  size_t next_ = 0;
  int64_t scan_ = 0;
  bool done_ = false;
  FrameSourceStats stats_;
};

}  // namespace sedbridge::sensors
