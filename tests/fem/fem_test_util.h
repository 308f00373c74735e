#pragma once
// Small fixtures shared by FE tests: materials and boundary springs for box meshes.

#include <memory>
#include <vector>

#include "fem/bone_coupling_force.h"
#include "fem/box_mesh.h"

namespace sedbridge::fem::testing {

inline LinearElasticMaterial Skin(double E_Pa = 1e5, double nu = 0.3, double rho = 1000) {
  return {"test", E_Pa, nu, rho};
}

inline std::vector<int> NodesWhere(const TetMesh& mesh, int axis, double value) {
  std::vector<int> out;
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (std::abs(mesh.rest_positions_m(axis, i) - value) < 1e-12) out.push_back(i);
  return out;
}

/// Springs that hold a block's bottom face (z = 0) in z only, plus pins that remove the
/// remaining rigid motions without restraining lateral expansion.
inline void AddRollerSupport(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>>& terms, double k = 1e9) {
  const auto bottom = NodesWhere(mesh, 2, 0.0);
  terms.push_back(std::make_unique<BoneCouplingForce>(
      mesh.rest_positions_m, bottom, std::vector<Eigen::Vector3d>(bottom.size(), Eigen::Vector3d::UnitZ()),
      SpringDamperParams{k, 0.0, 0.0}));
  int origin = -1, x_end = -1;
  double xmax = mesh.rest_positions_m.row(0).maxCoeff();
  for (int i : bottom) {
    const Eigen::Vector3d p = mesh.rest_positions_m.col(i);
    if (p.x() == 0 && p.y() == 0) origin = i;
    if (p.x() == xmax && p.y() == 0) x_end = i;
  }
  terms.push_back(std::make_unique<BoneCouplingForce>(mesh.rest_positions_m, std::vector<int>{origin},
                                                      std::vector<Eigen::Vector3d>{}, SpringDamperParams{k, 0.0, 1.0}));
  terms.push_back(std::make_unique<BoneCouplingForce>(
      mesh.rest_positions_m, std::vector<int>{x_end}, std::vector<Eigen::Vector3d>{Eigen::Vector3d::UnitY()},
      SpringDamperParams{k, 0.0, 0.0}));
}

}  // namespace sedbridge::fem::testing
