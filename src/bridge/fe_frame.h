#pragma once
// What an FE step can show of itself after a step: the deformed leader mesh and point
// fields on it, for VTU frames (`replay --vtu-every`, ParaView). Each FeStep fills it from
// its own state, so replay writes frames without knowing which step it runs.

#include <Eigen/Core>
#include <vector>

#include "fem/tet_mesh.h"
#include "scene/vtu_writer.h"

namespace sedbridge::bridge {

struct FeFrame {
  const fem::TetMesh* mesh = nullptr;       ///< soft mesh (rest positions [m]); outlives the step
  Eigen::VectorXd positions_m;              ///< every node's position [m], 3 per node
  std::vector<scene::VtuField> point_fields;  ///< e.g. merkel_sed_Pa, traction_pad_Pa
};

/// The Merkel-layer SED as a point field on the whole mesh ("merkel_sed_Pa"): vertex k of
/// the layer is mesh node merkel_nodes[k]; 0 elsewhere and past the end of `sed_Pa`.
scene::VtuField MerkelSedPointField(int num_nodes, const std::vector<int>& merkel_nodes, const Eigen::VectorXd& sed_Pa);

}  // namespace sedbridge::bridge
