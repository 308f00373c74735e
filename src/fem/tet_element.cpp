#include "fem/tet_element.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sedbridge::fem {

double SignedVolume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                    const Eigen::Vector3d& x2, const Eigen::Vector3d& x3) {
  return (x1 - x0).cross(x2 - x0).dot(x3 - x0) / 6.0;
}

std::vector<TetElement> PrecomputeElements(const TetMesh& mesh) {
  std::vector<TetElement> out(mesh.tets.size());
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& n = mesh.tets[t];
    Eigen::Vector3d X[4];
    for (int a = 0; a < 4; ++a) X[a] = mesh.rest_positions_m.col(n[a]);
    TetElement& e = out[t];
    e.volume_m3 = SignedVolume(X[0], X[1], X[2], X[3]);
    double max_edge = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) max_edge = std::max(max_edge, (X[a] - X[b]).norm());
    // A sliver with volume below 1e-6 of its edge cube would make K0 ill-conditioned.
    if (!(e.volume_m3 > 1e-6 * max_edge * max_edge * max_edge)) {
      throw std::invalid_argument("element " + std::to_string(t) +
                                  (e.volume_m3 < 0 ? " is inverted" : " has (near-)zero volume") +
                                  " (volume " + std::to_string(e.volume_m3 * 1e9) + " mm^3)");
    }
    Eigen::Matrix3d dm;
    dm << X[1] - X[0], X[2] - X[0], X[3] - X[0];
    e.rest_inverse = dm.inverse();
    // grad N_a: rows 1..3 are rows of Dm^-1; N_0 = 1 - N_1 - N_2 - N_3.
    e.shape_gradients.block<3, 3>(1, 0) = e.rest_inverse;
    e.shape_gradients.row(0) = -e.rest_inverse.colwise().sum();

    const auto& mat = mesh.materials.at(size_t(mesh.tet_material.at(t)));
    e.mu_Pa = mat.lame_mu_Pa();
    e.lambda_Pa = mat.lame_lambda_Pa();
  }
  return out;
}

Matrix12d RestStiffness(const TetElement& e) {
  Matrix12d k;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      const Eigen::Vector3d ga = e.shape_gradients.row(a).transpose(), gb = e.shape_gradients.row(b).transpose();
      k.block<3, 3>(3 * a, 3 * b) = StiffnessBlock(e, ga, gb, ga.dot(gb));
    }
  return k;
}

}  // namespace sedbridge::fem
