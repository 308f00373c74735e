#pragma once
// The step matrix A as an operator: what a Krylov solver needs of A (products, and the
// diagonal blocks its preconditioners read), without A's off-diagonal blocks assembled
// (until a direct fallback asks for them).
// A matrix-free step (NewtonSystem, fem/newton_system.h) assembles only the blocks of the
// terms that cannot apply their own Jacobian (ForceTerm::AppliesJacobian) and the mass;
// the element terms apply theirs from the element kernel. In a dynamic step that skips
// writing 16 blocks an element, the largest share of a step's assembly.

#include <Eigen/Core>

#include "fem/system_matrix.h"

namespace sedbridge::fem {

class StepOperator {
 public:
  virtual ~StepOperator() = default;
  /// y = A x (y resized).
  virtual void Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const = 0;
  /// Block (node, node) of A.
  virtual Eigen::Matrix3d DiagonalBlock(int node) const = 0;
  /// A with every block assembled, for a solver that must fall back to a direct solve
  /// (the blocks left out are added now; later products read the matrix).
  virtual const SystemMatrix& AssembledMatrix() = 0;
};

}  // namespace sedbridge::fem
