#include "fem/lumped_mass.h"

#include <Eigen/Dense>
#include "fem/tet_element.h"

namespace sedbridge::fem {

Eigen::VectorXd LumpedNodeMass(const TetMesh& mesh) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.num_nodes());
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& n = mesh.tets[size_t(t)];
    const double v = SignedVolume(mesh.rest_positions_m.col(n[0]), mesh.rest_positions_m.col(n[1]),
                                  mesh.rest_positions_m.col(n[2]), mesh.rest_positions_m.col(n[3]));
    const double rho = mesh.materials[size_t(mesh.tet_material[size_t(t)])].density_kg_m3;
    for (int a : n) m[a] += 0.25 * rho * v;
  }
  return m;
}

}  // namespace sedbridge::fem
