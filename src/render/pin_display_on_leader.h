#pragma once
// A pin display pressed on the leader's finger, by the compliance method on the leader's FE
// model (scene::FingertipCompliance): the pad rests on the display's rigid plate, pressed to
// the preload force, and each pin rises through the plate by its command (height [mm]),
// pressing the skin with its tip (unilateral contact: skin lifts off the plate around a
// raised pin). Two uses:
//   - Press(heights): the Merkel SED the commands produce, full contact (the display
//     fidelity's reference);
//   - Influence(h_ref): the linear influence about the preloaded state (each pin raised by
//     h_ref alone; strain per mm), what the inverse renderer inverts every scan.
// Pad frame: the pad faces +z; the plate's surface is the plane z = -preload depth, the
// pins rise from it toward -z. Units: mm and N at the boundary, SI inside.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/geometry/rigid_object.h"
#include "display/display_device.h"
#include "render/display_influence.h"
#include "render/display_on_leader.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {

class PinDisplayOnLeader : public DisplayOnLeader {
 public:
  /// @param leader  the leader's finger (kept by reference; its contact state is used)
  /// @param device  a pin display's device model (kind pin)
  /// Presses the plate to the preload force: preload_kPa over the actuated area (the
  /// footprints' bounding box grown by half the nearest-actuator distance on each side).
  /// Throws std::invalid_argument for a non-pin device, std::runtime_error when the
  /// preload press fails (its status in the message).
  PinDisplayOnLeader(scene::FingertipCompliance& leader, const display::DisplayDevice& device);

  int num_actuators() const override { return int(device_.footprints.size()); }
  double preload_force_N() const override { return preload_force_N_; }
  /// The plate's indentation at the preload [mm].
  double preload_depth_mm() const { return preload_depth_mm_; }

  /// Merkel SED [Pa] (leader's Merkel vertex order) with the pins at heights_mm (one per
  /// actuator, >= 0), full contact. False (message in error()) if the contact solve fails.
  bool Press(const Eigen::VectorXd& heights_mm, Eigen::VectorXd& sed_Pa) override;
  /// The linear influence about the preloaded state, each pin raised by
  /// reference_height_mm alone.
  ElementStrainInfluence Influence(double reference_height_mm) override;
  /// 0.2 mm, or a fifth of the travel if shorter.
  double default_reference_command() const override;
  const std::string& error() const override { return error_; }

 private:
  std::vector<geometry::RigidObject> Objects(const Eigen::VectorXd& heights_mm) const;

  scene::FingertipCompliance& leader_;
  display::DisplayDevice device_;
  double preload_force_N_ = 0, preload_depth_mm_ = 0;
  std::string error_;
};

}  // namespace sedbridge::render
