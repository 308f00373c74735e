#pragma once
// A pin display pressed on the leader's finger, by the compliance method on the leader's FE
// model (scene::FingertipCompliance): the pad rests on the display's rigid plate, pressed to
// the preload force, and each pin rises through the plate by its command (height [mm]),
// pressing the skin with its tip (unilateral contact: skin lifts off the plate around a
// raised pin). Two uses:
//   - Press(heights): the Merkel SED the commands produce, full contact (the display
//     fidelity's reference);
//   - Influence(h_ref): each pin's response about the preloaded state, alone: its gap to the
//     skin (a pin outside the pad's contact patch on the plate touches nothing until it has
//     risen that far) and its strain at the knots gap + h_ref x {1/4, 1/2, 1, 2, 4},
//     piecewise linear between (the skin lifts off the plate around a rising pin, so one
//     slope does not hold); what the inverse renderer inverts every scan.
// The leader's FE resolves no pin narrower than the spacing of its skin's contact samples
// (nodes and face centroids; on model B about 1 mm): a narrower pin passes between them
// and presses nothing more as it rises. Such a pin is pressed as one that wide.
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
  /// Each pin's gap and piecewise-linear response about the preloaded state (above).
  ElementStrainInfluence Influence(double reference_height_mm) override;
  /// The gaps of the last Influence call [mm]: how far each pin rises before it touches the
  /// skin (the travel when it never does).
  const Eigen::VectorXd& gaps_mm() const { return gaps_mm_; }
  /// 0.2 mm, or a fifth of the travel if shorter.
  double default_reference_command() const override;
  const std::string& error() const override { return error_; }
  /// The leader's contact-sample spacing under the display [mm] (median nearest-neighbour
  /// distance) and the pin radius pressed: the device's, or that spacing if wider (the FE
  /// resolves no narrower indenter). Rounded tips: the cap's radius at least that.
  double sample_spacing_mm() const { return sample_spacing_mm_; }
  /// Knots of the last Influence call whose contact solve failed (their response held at
  /// the pin's last good knot).
  int failed_knots() const { return failed_knots_; }
  double pressed_radius_mm() const { return pressed_radius_mm_; }

 private:
  std::vector<geometry::RigidObject> Objects(const Eigen::VectorXd& heights_mm) const;
  /// The pins moved from from_mm to to_mm in steps of at most kLongestRise_mm, a failed
  /// step retried at half the length (down to 1/32). False (error_ set) if one still fails.
  bool MoveTo(const Eigen::VectorXd& from_mm, const Eigen::VectorXd& to_mm);
  /// Pin `pin` alone raised to height_mm from the last state, in steps short enough that no
  /// node tunnels past it; returns the pin's contact force [N], or -1 if a solve failed.
  double RaiseAlone(int pin, double from_mm, double height_mm);
  /// The height at which pin `pin` alone first touches the skin of the preloaded pad [mm],
  /// from the first two heights where it carries force (contact force is linear in the
  /// overlap there); max_mm if it does not touch below max_mm. -1 on a failed solve.
  double Gap(int pin, double max_mm);

  scene::FingertipCompliance& leader_;
  display::DisplayDevice device_;
  double preload_force_N_ = 0, preload_depth_mm_ = 0;
  double sample_spacing_mm_ = 0, pressed_radius_mm_ = 0, pressed_tip_radius_mm_ = 0;
  Eigen::VectorXd gaps_mm_;
  int failed_knots_ = 0;
  std::string error_;
};

}  // namespace sedbridge::render
