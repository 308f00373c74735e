#pragma once
// Reduced quasi-static response for loads that are linear combinations of fixed nodal
// load vectors: with linear elasticity and a constant system matrix K (bone springs,
// no contact), u = sum_j c_j K^-1 f_j exactly. The strain of every basis response is
// precomputed on the elements that matter (e.g. around the Merkel layer), so a step is
// one small dense product instead of a sparse solve: the bridge's fast path, where each
// f_j is the load of one taxel axis.

#include <Eigen/Core>
#include <vector>

#include "fem/elastic_tet_force.h"
#include "fem/linear_solver.h"

namespace sedbridge::fem {

class LinearResponseBasis {
 public:
  /// @param elastic        linear elastic term (its mesh and elements)
  /// @param solver         prepared (factorized) for the scene's constant matrix K
  /// @param K              that matrix
  /// @param basis_loads_N  nodal load vectors f_j (3 * #nodes each) [N per unit c_j]
  /// @param elements       elements whose strain is wanted
  LinearResponseBasis(const ElasticTetForce& elastic, LinearSolver& solver, const SystemMatrix& K,
                      const std::vector<Eigen::VectorXd>& basis_loads_N, std::vector<int> elements);

  int num_basis() const { return num_basis_; }
  const std::vector<int>& elements() const { return elements_; }

  /// Element SED [Pa] of elements() for coefficients c (size num_basis()).
  void ElementSed(const Eigen::VectorXd& c, Eigen::VectorXd& element_sed_Pa) const;
  /// Nodal displacement of the response [m] (3 * #nodes): a full product, for checks and
  /// visualisation, not for the hot path.
  Eigen::VectorXd Displacement(const Eigen::VectorXd& c) const;

 private:
  const ElasticTetForce& elastic_;
  int num_basis_ = 0;
  std::vector<int> elements_;
  // 6 strain components (xx yy zz xy yz zx) of each element (rows) for each basis (cols).
  Eigen::MatrixXd strain_;
  Eigen::MatrixXd displacement_;  // 3n x num_basis
};

}  // namespace sedbridge::fem
