#pragma once
// A display worn on the leader's finger, as a load on the leader's FE model: what a
// command vector (the profile's unit: kPa below ambient for suction, mm of pin height for
// pins) does to the Merkel layer. One implementation per display kind with a mechanical
// load (render/pin_display_on_leader.h, render/suction_display_on_leader.h); electrotactile
// displays have none (they render against the SA1 rate estimate, display/sa1_rate_estimate.h).
// Two uses:
//   - Press(commands): the Merkel SED the commands produce, full contact (the display
//     fidelity's reference, and the replay's peak_display_sed.csv);
//   - Influence(reference): the linear influence about the preloaded state (each actuator
//     at `reference` alone), what the inverse renderer inverts every scan.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "display/display_device.h"
#include "render/display_influence.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {

class DisplayOnLeader {
 public:
  virtual ~DisplayOnLeader() = default;
  virtual int num_actuators() const = 0;
  /// The contact force of the pad on the display surface with every actuator off [N].
  virtual double preload_force_N() const = 0;
  /// Merkel SED [Pa] (the leader's Merkel vertex order) that `commands` (one per actuator,
  /// >= 0, the profile's unit) produce, full contact. False (message in error()) on bad
  /// input or a failed contact solve.
  virtual bool Press(const Eigen::VectorXd& commands, Eigen::VectorXd& sed_Pa) = 0;
  /// The linear influence about the preloaded state, each actuator at reference_command
  /// (> 0, profile unit) alone; strain per command unit. Throws std::runtime_error when a
  /// contact solve fails.
  virtual ElementStrainInfluence Influence(double reference_command) = 0;
  /// A reference command for Influence: in the device's working range, small enough that
  /// the load stays near linear [profile unit].
  virtual double default_reference_command() const = 0;
  virtual const std::string& error() const = 0;
};

/// True when MakeDisplayOnLeader builds a display of this kind (pin; suction once it has a
/// load on the leader; never electrotactile): what the bridge asks before it chooses the
/// inverse rendering, without the precompute.
bool HasMechanicalLoad(display::DisplayKind kind);

/// The pad's contact force on the display surface with every actuator off [N]:
/// device.preload_kPa over the actuated area (the footprints' bounding box grown by half the
/// nearest-actuator distance on each side; a single footprint: its diameter).
double PreloadForce_N(const display::DisplayDevice& device);

/// The Merkel layer's element strains [-] of `leader`'s last step (6 per element, the order
/// of ElementStrainInfluence).
Eigen::VectorXd StrainsOfLastStep(const scene::FingertipCompliance& leader);

/// Fills `in`'s per-element materials and vertex average from `leader`'s Merkel layer.
void AddLayerOf(const scene::FingertipCompliance& leader, ElementStrainInfluence& in);

/// The linear influence of `display` about its preloaded state by n + 1 full presses (every
/// actuator off, then each at `reference` alone), read from `leader`'s last step after each;
/// what DisplayOnLeader::Influence is for every kind. `what` names the display in messages.
/// A press that fails is tried again at a quarter of `reference`; with `failed_actuators`
/// given, an actuator whose presses both fail gets a zero column and is counted there,
/// else (and when the preload's press fails) std::runtime_error is thrown.
ElementStrainInfluence InfluenceByPresses(DisplayOnLeader& display, const scene::FingertipCompliance& leader,
                                          double reference, const std::string& what,
                                          int* failed_actuators = nullptr);

/// The leader's contact options a display on it needs: `base` (bone, contact stiffness,
/// cache folder) with face contact (holes and pins are narrower than the skin-node spacing)
/// and at least 200 contact iterations (a rising pin moves the contact set far: the skin
/// lifts off the plate around it), then as many unaccelerated where those fail
/// (fem::ComplianceContactOptions::monotone_fallback). What DisplayRendering and the display
/// press build.
scene::FingertipComplianceOptions DisplayLeaderOptions(scene::FingertipComplianceOptions base = {});

/// The display of `device`'s kind pressed on `leader` (kept by reference). Throws
/// std::invalid_argument for a kind without a mechanical load (electrotactile) or no
/// device model, std::runtime_error when the preload press fails.
std::unique_ptr<DisplayOnLeader> MakeDisplayOnLeader(scene::FingertipCompliance& leader,
                                                     const display::DisplayDevice& device);

}  // namespace sedbridge::render
