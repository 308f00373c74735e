#pragma once
// Surface traction (pressure and shear) on skin triangles -> consistent nodal forces.
// The traction is given per surface node (linear over each triangle); the consistent
// load of a linear triangle is f_a = A/12 * sum_b (1 + delta_ab) t_b. Dead load on the
// rest configuration: no stiffness contribution, so a traction-only scene keeps a
// constant system matrix. The bridge drives this term from sensor scans.

#include <vector>

#include "fem/force_term.h"
#include "fem/tet_mesh.h"

namespace sedbridge::fem {

class SurfaceTractionForce final : public ForceTerm {
 public:
  /// @param rest_positions_m  rest positions of all mesh nodes
  /// @param triangles         loaded surface triangles (mesh node indices)
  SurfaceTractionForce(const Eigen::Matrix3Xd& rest_positions_m, std::vector<Triangle> triangles);

  std::string name() const override { return "surface_traction"; }
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  bool JacobianIsConstant() const override { return true; }

  /// Surface nodes (sorted, unique); traction is given per entry of this list.
  const std::vector<int>& nodes() const { return nodes_; }
  /// Rest positions of nodes() [m], 3 x nodes().size().
  const Eigen::Matrix3Xd& node_rest_positions_m() const { return node_rest_positions_m_; }
  /// Sets the traction [Pa] at each of nodes() (model frame). Non-finite entries are
  /// rejected with std::invalid_argument (nothing is applied).
  void SetNodalTraction(const Eigen::Matrix3Xd& traction_Pa);
  void ClearTraction() { traction_Pa_.setZero(); }
  /// Total applied force [N] (sum of consistent nodal forces).
  Eigen::Vector3d TotalForce() const;
  /// Consistent nodal forces for the current traction, 3 x nodes().size() [N].
  Eigen::Matrix3Xd NodalForces() const;

 private:
  std::vector<int> nodes_;
  Eigen::Matrix3Xd node_rest_positions_m_;
  Eigen::Matrix3Xd traction_Pa_;
  // Consistent-load weights: nodal force k = sum over (k, j, w) of w * traction j.
  std::vector<int> row_start_;
  std::vector<std::pair<int, double>> weights_;
};

}  // namespace sedbridge::fem
