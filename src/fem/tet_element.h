#pragma once
// Per-tetrahedron quantities computed once from the rest shape: shape-function gradients,
// volume and the rest stiffness K0 (12x12, linear elasticity, constant strain).

#include <Eigen/Core>
#include <vector>

#include "fem/tet_mesh.h"

namespace sedbridge::fem {

using Matrix12d = Eigen::Matrix<double, 12, 12>;

struct TetElement {
  Eigen::Matrix3d rest_inverse;  ///< Dm^-1, Dm = [X1-X0, X2-X0, X3-X0]
  Eigen::Matrix<double, 4, 3> shape_gradients;  ///< row a = grad N_a [1/m]
  double volume_m3 = 0;
  double mu_Pa = 0, lambda_Pa = 0;
};

/// Block (a, b) of the stiffness R K0 R^T [N/m] for rotated gradients h = R g:
/// V (lambda h_a h_b^T + mu h_b h_a^T + mu (g_a . g_b) I). Inline: returned through memory
/// from an out-of-line call, the block's scalar stores stalled the caller's vector loads
/// (store forwarding), a tenth of a corotational assembly.
inline Eigen::Matrix3d StiffnessBlock(const TetElement& e, const Eigen::Vector3d& h_a, const Eigen::Vector3d& h_b,
                                      double ga_dot_gb) {
  Eigen::Matrix3d k = (e.volume_m3 * e.lambda_Pa) * h_a * h_b.transpose() + (e.volume_m3 * e.mu_Pa) * h_b * h_a.transpose();
  k.diagonal().array() += e.volume_m3 * e.mu_Pa * ga_dot_gb;
  return k;
}

/// The full rest stiffness K0 (12x12) of one element; blocks (a,b) at (3a, 3b).
Matrix12d RestStiffness(const TetElement& e);

/// Deformation gradient F = Ds Dm^-1 from current positions of the tet's nodes.
inline Eigen::Matrix3d DeformationGradient(const TetElement& e, const Eigen::Vector3d& x0,
                                           const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                                           const Eigen::Vector3d& x3) {
  Eigen::Matrix3d ds;
  ds << x1 - x0, x2 - x0, x3 - x0;
  return ds * e.rest_inverse;
}

/// Precomputes all elements. Throws std::invalid_argument naming the element index when a
/// tet is inverted or has (near-)zero volume (relative to its edge length cubed).
std::vector<TetElement> PrecomputeElements(const TetMesh& mesh);

/// Signed volume (positive for the orientation convention of TetMesh).
double SignedVolume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                    const Eigen::Vector3d& x2, const Eigen::Vector3d& x3);

}  // namespace sedbridge::fem
