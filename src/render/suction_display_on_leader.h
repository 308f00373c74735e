#pragma once
// A suction display pressed on the leader's finger, by the compliance method on the leader's
// FE model (scene::FingertipCompliance): the pad rests on the display's rigid plate, which
// has one round hole per actuator (device.hole_radius_mm at its footprint), pressed to the
// preload force; outside the holes the skin touches the plate (unilateral contact), and over
// each hole a pressure p_i below ambient (the command [kPa]) pulls the skin into the hole.
// Makino, Asamura & Shinoda (ICRA 2004): suction and compression give similar SED at the
// receptors' depth. Two uses, as every DisplayOnLeader:
//   - Press(suction): the Merkel SED the commands produce, full contact (the plate at the
//     preload depth plus the suction loads, raised in warm-started steps of <= 2.5 kPa);
//   - Influence(p_ref): the linear influence about the preloaded state (each hole at p_ref
//     alone; strain per kPa), what the inverse renderer inverts every scan.
//
// The suction load: a pressure p over a hole pulls the skin spanning it with p n dA, whose
// sum over any surface bounded by the hole's rim is p pi r^2 along the hole's axis (the
// vector area depends on the rim alone). It is applied as the FE's consistent nodal load:
// p times the integral of each skin node's shape function over the hole's disc (the skin
// faces projected on the plate at the preloaded state, by quadrature), along +z_pad, toward
// the display. A hole of 1 mm is smaller than the skin faces (node spacing about 1.5 mm on
// B), so lumped areas (a node's or a face's whole share) would miss the hole or smear it
// over a face; the integral puts p pi r^2 where the hole is, shared by the nodes of the
// faces under it as the elements' own interpolation shares it.
// Where the plate holds every node under a hole the skin cannot bulge into it: on a mesh
// coarser than the holes what a hole does depends on where the nodes fall
// (docs/display-rendering.md, "Where it stands").
//
// Pad frame: the pad faces +z; the plate's surface is the plane z = -preload depth, its
// holes run along z. Units: mm, kPa and N at the boundary, SI inside.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry/rigid_object.h"
#include "display/display_device.h"
#include "render/display_influence.h"
#include "render/display_on_leader.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {

class SuctionDisplayOnLeader : public DisplayOnLeader {
 public:
  /// @param leader  the leader's finger (kept by reference; its contact state is used, and
  ///                its sample loads are set during a press and cleared after it)
  /// @param device  a suction display's device model (kind suction)
  /// Presses the holed plate to the preload force (PreloadForce_N), then finds each hole's
  /// share of skin on the preloaded pad. Throws std::invalid_argument for a non-suction
  /// device, std::runtime_error when the preload press fails (its status in the message).
  SuctionDisplayOnLeader(scene::FingertipCompliance& leader, const display::DisplayDevice& device);

  int num_actuators() const override { return int(device_.footprints.size()); }
  double preload_force_N() const override { return preload_force_N_; }
  /// The plate's indentation at the preload [mm].
  double preload_depth_mm() const { return preload_depth_mm_; }
  /// Skin area each hole pulls on [mm^2]: pi r^2 where the pad covers the whole hole.
  double hole_skin_area_mm2(int actuator) const;
  /// Hole `actuator`'s consistent nodal load per unit pressure: (node sample = candidate
  /// index, area [m^2]) for each skin node under it.
  const std::vector<std::pair<int, double>>& hole_shares_m2(int actuator) const { return hole_shares_m2_.at(size_t(actuator)); }

  /// Merkel SED [Pa] (leader's Merkel vertex order) with the holes at suction_kPa below
  /// ambient (one per actuator, >= 0), full contact. False (message in error()) if the
  /// contact solve fails.
  bool Press(const Eigen::VectorXd& suction_kPa, Eigen::VectorXd& sed_Pa) override;
  /// The linear influence about the preloaded state, each hole at reference_kPa alone.
  ElementStrainInfluence Influence(double reference_kPa) override;
  /// 10 kPa: the middle of the shipped displays' working range (suction_4x4's safety max is
  /// 20 kPa). The load is linear in the command; only contact changes bend the response.
  double default_reference_command() const override { return 10.0; }
  const std::string& error() const override { return error_; }
  /// Holes of the last Influence call whose presses did not converge (at the reference and
  /// a quarter of it): modelled as doing nothing.
  int failed_actuators() const { return failed_actuators_; }

 private:
  /// Each hole's consistent nodal load per unit pressure: (node sample, area [m^2]).
  void FindHoleShares();
  /// The contact points' loads [N, pad frame] for the commands.
  Eigen::Matrix3Xd Loads(const Eigen::VectorXd& suction_kPa) const;

  scene::FingertipCompliance& leader_;
  display::DisplayDevice device_;
  geometry::RigidObject plate_at_preload_;
  std::vector<std::vector<std::pair<int, double>>> hole_shares_m2_;  // per hole
  double preload_force_N_ = 0, preload_depth_mm_ = 0;
  std::string error_;
  int failed_actuators_ = 0;
};

}  // namespace sedbridge::render
