#pragma once
// Columns of K^-1 for a set of loads, computed once for the operators that answer a linear,
// quasi-static model by superposition: the compliance method's W and G (one unit load per
// contact dof, fem/compliance_operator.h) and the reduced taxel-load step (one load per
// taxel and axis). One sparse factorization, then one back-substitution per load on an
// OpenMP team (the solves only read the factor).

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "fem/system_matrix.h"

namespace sedbridge::fem {

/// Sets the load vector of load `index` into b (3 #nodes, zero on entry; only the entries it
/// sets are cleared again after the solve: list them in `touched`).
using LoadOf = std::function<void(int index, Eigen::VectorXd& b, std::vector<int>& touched)>;
/// Receives u = K^-1 b of load `index` [m per unit load]; called on the solving thread
/// (each index once, any order: write only into that load's own slots).
using TakeSolution = std::function<void(int index, const Eigen::VectorXd& u)>;

/// Solves K u = b for `count` loads. threads <= 0: OpenMP's default team. Returns false when
/// a solve fails or gives a non-finite u (K singular: no fixed support).
bool SolveForLoads(const SystemMatrix& K, int count, const LoadOf& load_of, const TakeSolution& take, int threads);

/// The same for unit loads on single dofs: load i is 1 at dofs[i] (3 node + axis).
bool SolveForUnitDofs(const SystemMatrix& K, const std::vector<int>& dofs, const TakeSolution& take, int threads);

}  // namespace sedbridge::fem
