#include "fem/linear_response_basis.h"

#include <stdexcept>

namespace sedbridge::fem {

LinearResponseBasis::LinearResponseBasis(const ElasticTetForce& elastic, LinearSolver& solver, const SystemMatrix& K,
                                         const std::vector<Eigen::VectorXd>& loads, std::vector<int> elements)
    : elastic_(elastic), num_basis_(int(loads.size())), elements_(std::move(elements)) {
  if (elastic.formulation() != ElasticFormulation::kLinear)
    throw std::invalid_argument("a linear response basis needs linear elasticity");
  const TetMesh& mesh = elastic.mesh();
  const int dofs = 3 * mesh.num_nodes();
  displacement_.resize(dofs, num_basis_);
  strain_.resize(6 * Eigen::Index(elements_.size()), num_basis_);
  for (int j = 0; j < num_basis_; ++j) {
    if (loads[size_t(j)].size() != dofs) throw std::invalid_argument("basis load has the wrong size");
    Eigen::VectorXd u = Eigen::VectorXd::Zero(dofs);
    const LinearSolveReport r = solver.Solve(K, loads[size_t(j)], u);
    if (!r.converged) throw std::runtime_error("linear response basis: solve " + std::to_string(j) + " failed");
    displacement_.col(j) = u;
    for (size_t k = 0; k < elements_.size(); ++k) {
      const Tet& n = mesh.tets[size_t(elements_[k])];
      const TetElement& e = elastic.elements()[size_t(elements_[k])];
      Eigen::Matrix3d grad = Eigen::Matrix3d::Zero();  // du/dX = sum_a u_a g_a^T
      for (int a = 0; a < 4; ++a) grad += u.segment<3>(3 * n[size_t(a)]) * e.shape_gradients.row(a);
      const Eigen::Matrix3d eps = 0.5 * (grad + grad.transpose());
      strain_.block<6, 1>(6 * Eigen::Index(k), j) << eps(0, 0), eps(1, 1), eps(2, 2), eps(0, 1), eps(1, 2), eps(2, 0);
    }
  }
}

void LinearResponseBasis::ElementSed(const Eigen::VectorXd& c, Eigen::VectorXd& sed) const {
  const Eigen::VectorXd eps = strain_ * c;
  sed.resize(Eigen::Index(elements_.size()));
  for (size_t k = 0; k < elements_.size(); ++k) {
    const TetElement& e = elastic_.elements()[size_t(elements_[k])];
    const auto s = eps.segment<6>(6 * Eigen::Index(k));
    const double tr = s[0] + s[1] + s[2];
    // 1/2 sigma:eps = mu eps:eps + lambda/2 tr^2, shear terms counted twice.
    const double eps_eps = s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
    sed[Eigen::Index(k)] = e.mu_Pa * eps_eps + 0.5 * e.lambda_Pa * tr * tr;
  }
}

Eigen::VectorXd LinearResponseBasis::Displacement(const Eigen::VectorXd& c) const { return displacement_ * c; }

}  // namespace sedbridge::fem
