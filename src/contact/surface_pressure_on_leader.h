#pragma once
// A surface pressure (sensors/surface_pressure_inversion.h: normal force per cell of a grid
// over the pad, one tangential force) pressed on the leader's fingertip as a traction field:
// each cell's force is split over the skin of the leader's contact patch under it (the
// skin faces of the candidate nodes at rest, seen along z_pad, barycentric shares of
// kSub x kSub points over the cell) and held on those nodes as the compliance method's
// sample loads (fem::ComplianceContact::SetSampleLoads); one step with no object gives the
// Merkel SED. The leader's own mechanics, the same model the benchmark's truth presses,
// not the pressure map's interpolation kernel. A cell whose points find no skin (past the
// leader's patch) loses its share: applied_force_N says what landed.
//
// Why not the pressure map's own path (ReducedLinearFeStep: u = U v over taxel values):
// its precompute has one column per taxel axis; one per 0.5 mm cell would be 1444 x 3
// columns of the mesh's size. The leader's compliance operator already maps forces on the
// contact nodes to the Merkel layer (G), and the grid's forces go there in one product.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "scene/fingertip_compliance.h"

namespace sedbridge::contact {

class SurfacePressureOnLeader {
 public:
  /// @param leader         the leader (must outlive this object); its warm start is reset by Press
  /// @param cells_pad_mm   cell centres in the leader's pad frame [mm], 2 x #cells
  /// @param cell_mm        a cell's side on the leader's pad [mm]
  SurfacePressureOnLeader(scene::FingertipCompliance& leader, const Eigen::Matrix2Xd& cells_pad_mm, double cell_mm);

  /// Presses normal forces per cell [N, >= 0, along -z_pad] and a tangential force [N, leader
  /// pad frame, spread in proportion to the normal force]; the SED is then leader.sed_Pa().
  /// False (error() says why) for a wrong size, a non-finite or negative force, or a failed
  /// step. The leader is left without loads and without a warm start.
  bool Press(const Eigen::VectorXd& cell_force_N, const Eigen::Vector2d& shear_pad_N);
  const std::string& error() const { return error_; }
  /// Normal force that reached the leader's skin in the last Press [N].
  double applied_force_N() const { return applied_N_; }
  /// Share of cell `cell`'s force that finds skin [-] (1 inside the leader's patch).
  double coverage(int cell) const;

 private:
  scene::FingertipCompliance& leader_;
  std::vector<std::vector<std::pair<int, double>>> shares_;  // per cell: (sample, share of its force)
  Eigen::Matrix3Xd loads_;
  std::string error_;
  double applied_N_ = 0;
};

}  // namespace sedbridge::contact
