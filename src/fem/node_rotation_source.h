#pragma once
// Where a warped preconditioner takes its per-node rotations from. The elastic term
// implements it (fem/elastic_tet_force.h); a linear solver is handed one at construction,
// so nothing has to look for the elastic term among the force terms.

#include <Eigen/Core>
#include <vector>

namespace sedbridge::fem {

class NodeRotationSource {
 public:
  virtual ~NodeRotationSource() = default;
  /// Rotation of each node (3x3, one per mesh node) at the last force assembly.
  virtual void ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const = 0;
};

}  // namespace sedbridge::fem
