#pragma once
// Small fixtures shared by FE tests: materials and boundary springs for box meshes, and
// the one-thread-versus-teams check of parallel assemblies.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "fem/bone_coupling_force.h"
#include "fem/box_mesh.h"
#include "fem/system_matrix.h"

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

/// Zeroes `matrix` and assembles it with assemble(force, k_times_v, threads) (zeroed vectors
/// of `dofs`) on 1, 2, 3 and 7 OpenMP threads; expects every team's matrix values, force
/// and K v to equal one thread's to 1e-12 of their largest. The team size is restored.
template <typename Assemble>
void ExpectThreadsGiveTheOneThreadAssembly(SystemMatrix& matrix, int dofs, Assemble&& assemble) {
  const int saved = omp_get_max_threads();
  std::vector<double> reference_values;
  Eigen::VectorXd reference_kv, reference_f;
  for (int threads : {1, 2, 3, 7}) {
    omp_set_num_threads(threads);
    matrix.SetZero();
    Eigen::VectorXd kv = Eigen::VectorXd::Zero(dofs), f = Eigen::VectorXd::Zero(dofs);
    assemble(f, kv, threads);
    std::vector<double> values(matrix.values(), matrix.values() + matrix.num_values());
    if (threads == 1) {
      reference_values = values, reference_kv = kv, reference_f = f;
      continue;
    }
    double worst = 0, largest = 0;
    for (size_t k = 0; k < values.size(); ++k)
      worst = std::max(worst, std::abs(values[k] - reference_values[k])), largest = std::max(largest, std::abs(values[k]));
    EXPECT_LT(worst, 1e-12 * largest) << threads << " threads";
    EXPECT_LT((kv - reference_kv).norm(), 1e-12 * reference_kv.norm()) << threads << " threads";
    EXPECT_LT((f - reference_f).norm(), 1e-12 * reference_f.norm()) << threads << " threads";
  }
  omp_set_num_threads(saved);
}

}  // namespace sedbridge::fem::testing
