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
#include "fem/system_matrix.h"

namespace sedbridge::fem {

struct LinearSolveReport {
  int iterations = 0;            ///< PCG iterations (0 for direct)
  double relative_residual = 0;  ///< |b - A x| / |b| where computed
  bool converged = true;
  bool used_fallback = false;    ///< PCG gave up and the direct solver answered
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
  /// Per-node rotations (for the warped preconditioner), updated before each Prepare.
  virtual void SetNodeRotations(const std::vector<Eigen::Matrix3d>* rotations) {}
  virtual bool wants_node_rotations() const { return false; }
};

/// Which direct factorization a solver uses (the PCG's rest factor and fallback too).
enum class DirectSolverKind { kLdlt, kCholmod };

/// A direct solver: DirectLdltSolver or CholmodSolver.
std::unique_ptr<LinearSolver> MakeDirectSolver(DirectSolverKind kind);

class DirectLdltSolver final : public LinearSolver {
 public:
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
  /// Factorization for the warped rest factor and the fallback. CHOLMOD: on model B its
  /// solves are ~3x and its factorization ~7x faster than the LDL^T (docs/performance.md).
  DirectSolverKind direct = DirectSolverKind::kCholmod;
};

class PcgSolver final : public LinearSolver {
 public:
  explicit PcgSolver(PcgSettings settings);
  std::string name() const override;
  void Prepare(const SystemMatrix& A) override;
  LinearSolveReport Solve(const SystemMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  void SetReferenceMatrix(const SystemMatrix& A0) override;
  void SetNodeRotations(const std::vector<Eigen::Matrix3d>* rotations) override { rotations_ = rotations; }
  bool wants_node_rotations() const override { return settings_.preconditioner != PreconditionerKind::kBlockJacobi; }
  int fallbacks() const { return fallbacks_; }

 private:
  void ApplyPreconditioner(const SystemMatrix& A, const Eigen::VectorXd& r, Eigen::VectorXd& z);

  PcgSettings settings_;
  std::vector<Eigen::Matrix3d> block_inverse_;
  std::unique_ptr<LinearSolver> rest_factor_;  // direct solver holding the rest matrix's factor
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>> rest_incomplete_;
  bool has_rest_factor_ = false;
  const std::vector<Eigen::Matrix3d>* rotations_ = nullptr;
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
std::unique_ptr<LinearSolver> MakeLinearSolver(const std::string& name, const PcgSettings& pcg);

}  // namespace sedbridge::fem
