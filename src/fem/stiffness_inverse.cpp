#include "fem/stiffness_inverse.h"

#include <omp.h>

#include "fem/linear_solver.h"

namespace sedbridge::fem {

bool SolveForLoads(const SystemMatrix& K, int count, const LoadOf& load_of, const TakeSolution& take, int threads) {
  DirectLdltSolver solver;
  solver.Prepare(K);
  bool ok = true;
  const int team = threads > 0 ? threads : omp_get_max_threads();
  // DirectLdltSolver::Solve only reads the factor, so threads may share it.
#pragma omp parallel num_threads(team) reduction(&& : ok)
  {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(K.num_nodes() * 3), x;
    std::vector<int> touched;
#pragma omp for schedule(dynamic, 8)
    for (int i = 0; i < count; ++i) {
      touched.clear();
      load_of(i, b, touched);
      x.setZero(b.size());
      const LinearSolveReport r = solver.Solve(K, b, x);
      for (int dof : touched) b[dof] = 0.0;
      ok = ok && r.converged && x.allFinite();
      take(i, x);
    }
  }
  return ok;
}

bool SolveForUnitDofs(const SystemMatrix& K, const std::vector<int>& dofs, const TakeSolution& take, int threads) {
  return SolveForLoads(
      K, int(dofs.size()),
      [&](int i, Eigen::VectorXd& b, std::vector<int>& touched) {
        b[dofs[size_t(i)]] = 1.0;
        touched.push_back(dofs[size_t(i)]);
      },
      take, threads);
}

}  // namespace sedbridge::fem
