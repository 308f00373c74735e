#pragma once
// Linear solvers for the symmetric positive definite step system A x = b.
//  - DirectLdltSolver: sparse LDL^T (Eigen, AMD ordering); symbolic analysis once.
//  - CholmodSolver (fem/cholmod_solver.h): supernodal L L^T (CHOLMOD, METIS/AMD ordering).
//  - PcgSolver: preconditioned conjugate gradients with warm start and a counted fallback
//    to the direct solver when it does not converge. Preconditioners: block Jacobi, or a
//    "warped" factorization of the rest matrix rotated per node (SOFA's
//    WarpPreconditioner idea): exact for linear FEM, close for corotational.

#include <Eigen/Core>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <memory>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/no_copy_no_move.h"
#include "fem/node_rotation_source.h"
#include "fem/stiff_node_source.h"
#include "fem/step_operator.h"
#include "fem/stiff_node_update.h"
#include "fem/system_matrix.h"

namespace sedbridge::fem {

struct LinearSolveReport {
  int iterations = 0;            ///< PCG iterations (0 for direct)
  double relative_residual = 0;  ///< |b - A x| / |b| where computed
  bool converged = true;
  bool used_fallback = false;    ///< PCG gave up and the direct solver answered
  int preconditioner_applications = 0;  ///< PCG: one per iteration it used, none wasted at a cap
};

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual std::string name() const = 0;
  /// Called after A's values changed (before Solve).
  virtual void Prepare(const SystemMatrix& A) = 0;
  /// Solves A x = b; x holds the initial guess on entry.
  virtual LinearSolveReport Solve(const SystemMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
  /// The system matrix at rest (for factor-reusing preconditioners). Default: ignored.
  virtual void SetReferenceMatrix(const SystemMatrix& A0) {}
  /// True when SetReferenceMatrix should be called with the first assembled matrix.
  virtual bool wants_reference_matrix() const { return false; }
  /// True when Solve needs only products with A and its diagonal blocks, which it then
  /// takes from the operator given to SetOperator (fem/step_operator.h), not from the
  /// SystemMatrix argument: the caller may leave blocks out of that matrix (a fallback to
  /// a direct solve asks the operator for them).
  virtual bool accepts_operator() const { return false; }
  /// The operator Prepare and Solve read A from (kept by pointer; null = the matrix).
  virtual void SetOperator(StepOperator* op) {}
};

/// Which direct factorization a solver uses (the PCG's rest factor and fallback too).
enum class DirectSolverKind { kLdlt, kCholmod };

/// A direct solver: DirectLdltSolver or CholmodSolver.
std::unique_ptr<LinearSolver> MakeDirectSolver(DirectSolverKind kind);

class DirectLdltSolver final : public LinearSolver {
 public:
  SEDBRIDGE_NO_COPY_NO_MOVE(DirectLdltSolver)
  DirectLdltSolver() = default;
  std::string name() const override { return "ldlt"; }
  void Prepare(const SystemMatrix& A) override;
  LinearSolveReport Solve(const SystemMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) override;

 private:
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
  bool analyzed_ = false;
  bool ok_ = false;
};

/// kWarpedRestFactor: exact factorization (PcgSettings::direct) of the rest matrix, rotated
/// per node (few iterations, each a full triangular solve). kWarpedRestIncompleteCholesky: the same with an
/// incomplete Cholesky (cheaper iterations, more of them).
enum class PreconditionerKind { kBlockJacobi, kWarpedRestFactor, kWarpedRestIncompleteCholesky };

struct PcgSettings {
  double relative_tolerance = 1e-6;
  int max_iterations = 200;
  PreconditionerKind preconditioner = PreconditionerKind::kWarpedRestFactor;
  bool fallback_to_direct = true;
  /// Factorization for the warped rest factor and the fallback. CHOLMOD, the faster one on
  /// the shipped models (measured: docs/performance.md, "Supernodal Cholesky").
  DirectSolverKind direct = DirectSolverKind::kCholmod;
  /// Warped rest factor only: add the stiff nodes' extra diagonal blocks (contact springs)
  /// to the preconditioner by a low-rank update (fem/stiff_node_update.h).
  bool stiff_node_update = true;
  /// Memory for that update's cached columns of the rest factor's inverse [MB].
  double stiff_node_budget_MB = 64.0;
  /// Warped rest factor by CHOLMOD: its solves in single precision (a float copy of L;
  /// CholmodSolver::set_single_precision): the solve is memory-bound, and a preconditioner
  /// needs no more digits (same PCG iterations on the contact press, docs/performance.md).
  /// The PCG's own vectors, and the fallback, stay double.
  bool single_precision_factor = true;
  /// The PCG takes its products with the step matrix from the element terms (matrix-free,
  /// fem/step_operator.h), so their blocks are not assembled unless a direct fallback needs
  /// them. The same answer to round-off.
  bool matrix_free = true;
};

class PcgSolver final : public LinearSolver {
 public:
  SEDBRIDGE_NO_COPY_NO_MOVE(PcgSolver)
  /// @param settings  tolerance, preconditioner, fallback
  /// @param rotations where the warped preconditioners take the per-node rotations from,
  ///                  read at each Prepare (kept by pointer; null = the rest factor unrotated)
  /// @param stiff_nodes which nodes' extra stiffness the warped rest factor is updated with
  ///                  at each Prepare (kept by pointer; null = none)
  explicit PcgSolver(PcgSettings settings, const NodeRotationSource* rotations = nullptr,
                     const StiffNodeSource* stiff_nodes = nullptr);
  std::string name() const override;
  /// Block Jacobi: inverts the diagonal blocks. Warped: takes the node rotations.
  void Prepare(const SystemMatrix& A) override;
  LinearSolveReport Solve(const SystemMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  void SetReferenceMatrix(const SystemMatrix& A0) override;
  bool wants_reference_matrix() const override { return warped(); }
  bool accepts_operator() const override { return settings_.matrix_free; }
  void SetOperator(StepOperator* op) override { op_ = accepts_operator() ? op : nullptr; }
  int fallbacks() const { return fallbacks_; }
  /// Rank of the stiff-node update at the last Prepare (0 = none).
  int stiff_node_rank() const { return stiff_update_.rank(); }

 private:
  void ApplyPreconditioner(const SystemMatrix& A, const Eigen::VectorXd& r, Eigen::VectorXd& z);
  void Multiply(const SystemMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    if (op_) op_->Multiply(x, y);
    else A.Multiply(x, y);
  }
  Eigen::Matrix3d DiagonalBlock(const SystemMatrix& A, int node) const {
    return op_ ? op_->DiagonalBlock(node) : A.Block(A.DiagonalSlot(node));
  }
  bool warped() const { return settings_.preconditioner != PreconditionerKind::kBlockJacobi; }

  PcgSettings settings_;
  StepOperator* op_ = nullptr;
  const NodeRotationSource* rotation_source_ = nullptr;
  const StiffNodeSource* stiff_source_ = nullptr;
  StiffNodeUpdate stiff_update_;
  std::vector<int> stiff_nodes_;
  std::vector<Eigen::Matrix3d> block_inverse_;
  std::unique_ptr<LinearSolver> rest_factor_;  // direct solver holding the rest matrix's factor
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>> rest_incomplete_;
  bool has_rest_factor_ = false;
  std::vector<Eigen::Matrix3d> rotations_;  // per node, from rotation_source_ at Prepare
  std::unique_ptr<LinearSolver> fallback_;
  int fallbacks_ = 0;
  Eigen::VectorXd r_, z_, p_, q_, tmp_;
};

/// The linear solvers MakeLinearSolver builds, by name (LinearSolverNames()).
enum class LinearSolverKind { kLdlt, kCholmod, kPcgJacobi, kPcgWarp, kPcgWarpLdlt, kPcgWarpIchol };
/// "ldlt", "cholmod", "pcg_jacobi", "pcg_warp" (rest factor and fallback by CHOLMOD),
/// "pcg_warp_ldlt" (the same by Eigen's LDL^T), "pcg_warp_ichol": the one list of names.
const config::EnumNames<LinearSolverKind>& NamesOf(LinearSolverKind);
/// Every solver name, in the order messages list them.
std::vector<std::string> LinearSolverNames();

/// Builds a solver by name (NamesOf(LinearSolverKind)); pcg_jacobi and pcg_warp_ichol fall
/// back to pcg.direct. Throws std::invalid_argument for an unknown name, listing the names.
/// `rotations`: the warped PCGs' rotation source (normally the elastic term; kept by
/// pointer, null = none). `stiff_nodes`: the warped PCGs' stiff-node source (normally the
/// penalty contact term; null = none).
std::unique_ptr<LinearSolver> MakeLinearSolver(const std::string& name, const PcgSettings& pcg,
                                               const NodeRotationSource* rotations = nullptr,
                                               const StiffNodeSource* stiff_nodes = nullptr);

}  // namespace sedbridge::fem
