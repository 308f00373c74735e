#pragma once
// The soft-tissue volume mesh the FE engine works on: linear tetrahedra, SI units.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "fem/linear_elastic_material.h"

namespace sedbridge::fem {

using Tet = std::array<int, 4>;
using Triangle = std::array<int, 3>;

struct TetMesh {
  /// 3 x #nodes rest positions [m].
  Eigen::Matrix3Xd rest_positions_m;
  /// Node indices of each tetrahedron, positively oriented
  /// ((x1-x0) x (x2-x0)) . (x3-x0) > 0.
  std::vector<Tet> tets;
  /// Index into `materials` for each tet.
  std::vector<int> tet_material;
  std::vector<LinearElasticMaterial> materials;

  int num_nodes() const { return static_cast<int>(rest_positions_m.cols()); }
  int num_tets() const { return static_cast<int>(tets.size()); }
};

}  // namespace sedbridge::fem
