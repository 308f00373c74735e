#pragma once
// Supernodal sparse Cholesky L L^T (CHOLMOD from SuiteSparse, through Eigen's
// CholmodSupport) with a fill-reducing ordering, behind the LinearSolver interface.
// Supernodes are dense column blocks factorized by BLAS (OpenBLAS); with more than one
// OpenMP thread the two triangular solves run on elimination-tree subtrees in parallel
// (SupernodalTriangularSolve; CHOLMOD's own solve is serial). BLAS threads: 1 by
// default (the first CholmodSolver sets it: OpenBLAS's spinning workers cost far more than
// they bring on these models, docs/performance.md), OPENBLAS_NUM_THREADS when set, or
// SetBlasThreads below.
// CHOLMOD's headers stay in the .cpp, so users of this header need no SuiteSparse paths.

#include <memory>
#include <string>

#include "common/no_copy_no_move.h"
#include "fem/linear_solver.h"

namespace sedbridge::fem {

/// Fill-reducing ordering for the symbolic analysis (done once, on the first Prepare).
enum class CholmodOrdering {
  kBest,   ///< try AMD and METIS nested dissection; CHOLMOD keeps the better (less fill, fewer flops)
  kAmd,    ///< approximate minimum degree (what Eigen's SimplicialLDLT uses)
  kMetis,  ///< METIS nested dissection
};

/// How Solve runs the two triangular solves.
enum class CholmodSolvePath {
  kAuto,      ///< kSubtrees when omp_get_max_threads() > 1 outside a parallel region, else kCholmod
  kCholmod,   ///< CHOLMOD's own solve (serial supernode sweep, BLAS kernels)
  kSubtrees,  ///< SupernodalTriangularSolve: elimination-tree subtrees on the OpenMP team
};

class CholmodSolver final : public LinearSolver {
 public:
  // Impl holds CHOLMOD's factor and workspace.
  SEDBRIDGE_NO_COPY_NO_MOVE(CholmodSolver)
  explicit CholmodSolver(CholmodOrdering ordering = CholmodOrdering::kBest);
  ~CholmodSolver() override;

  std::string name() const override { return "cholmod"; }
  /// Factorizes A (symmetric; its lower triangle is read). The pattern is analysed on the
  /// first call only: later matrices must have the same pattern (SystemMatrix's is fixed).
  void Prepare(const SystemMatrix& A) override;
  /// Solves with the last factor; A is not read. converged = false (x untouched) when the
  /// last Prepare found A not positive definite. Not thread-safe: reuses workspace.
  LinearSolveReport Solve(const SystemMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) override;

  /// Solve in single precision (SupernodalTriangularSolve::SolveSingle with a float copy
  /// of L made at each Prepare): ~7 significant digits, for a preconditioner's solves.
  /// Takes effect at the next Prepare. Default false.
  void set_single_precision(bool single) { single_precision_ = single; }
  /// Which triangular solve Solve uses (default kAuto).
  void set_solve_path(CholmodSolvePath path) { solve_path_ = path; }
  /// Share of the solve's work that the subtree schedule leaves serial (the top
  /// separators), for the thread count of the last subtree solve; 1 before one.
  double solve_serial_fraction() const;

  /// True when the last Prepare produced a usable factor.
  bool factor_ok() const { return ok_; }
  /// Non-zeros of L (its exact pattern, diagonal included); 0 before the first Prepare.
  double factor_nonzeros() const;
  /// Entries CHOLMOD stores for L (supernodes are dense blocks, so >= factor_nonzeros()).
  double factor_stored_entries() const;
  /// Floating-point operations of one factorization, as counted by the analysis.
  double factor_flops() const;
  /// The ordering the analysis used: "amd", "metis", "nesdis", "natural", ... ("" before).
  std::string ordering_used() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool ok_ = false;
  CholmodSolvePath solve_path_ = CholmodSolvePath::kAuto;
  bool single_precision_ = false;
};

/// Sets the BLAS thread count CHOLMOD's supernode kernels use (OpenBLAS, process-wide;
/// overrides the environment and the default of 1). Returns false, and does nothing, with
/// a BLAS that cannot be told.
bool SetBlasThreads(int threads);
/// The BLAS thread count in effect (OpenBLAS), or 0 if the BLAS cannot say.
int BlasThreads();

}  // namespace sedbridge::fem
