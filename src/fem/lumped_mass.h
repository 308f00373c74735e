#pragma once
// Lumped (diagonal) mass from density: each tet gives rho V / 4 to each of its nodes.

#include <Eigen/Core>

#include "fem/tet_mesh.h"

namespace sedbridge::fem {

/// Mass per node [kg].
Eigen::VectorXd LumpedNodeMass(const TetMesh& mesh);

}  // namespace sedbridge::fem
