#pragma once
// Cholesky factorization and solve of a small dense SPD matrix (the compliance method's
// contact QP, m up to a few hundred rows), in double precision.
//
// Why not Eigen's LLT: the project compiles for the x86-64 baseline, so Eigen's kernels
// run on 2-double SSE2 packets; this kernel is a right-looking factorization with 8-column
// panels whose trailing update is one fused, contiguous loop, built as an AVX2/FMA clone
// beside the baseline (common/hot_clones.h). Factor + solve against Eigen's LLT, two runs
// of build/tests/bench/dense_cholesky_benchmark on the 2-core VM: 1.0-2.5x faster for
// m = 20-200, about even at m = 300 (docs/lab-notes/2026-11-28-fe-step-speed-later-runs.md,
// "the contact QP on kept columns and an updatable factor").

#include <cstddef>
#include <vector>

namespace sedbridge::fem {

/// A = L L^T in place: `a` is n x n, column-major with leading dimension lda >= n; its
/// lower triangle (diagonal included) is read and overwritten by L; the strict upper
/// triangle is neither read nor written. Returns false (a partly overwritten) when a
/// pivot is not positive and finite: A is not positive definite (to rounding), or holds
/// NaN/Inf.
bool CholeskyFactorLower(int n, double* a, int lda);

/// Solves L L^T x = b in place (b: n values) with L from CholeskyFactorLower.
void CholeskySolveLower(int n, const double* l, int lda, double* b);

/// A Cholesky factor L L^T = A of a dense SPD matrix whose rows and columns come and go:
/// appending one costs a triangular solve and removing one a rank-one update, O(n^2) each
/// instead of the O(n^3 / 3) of factoring anew (an active set changing by a row or two).
class UpdatableCholesky {
 public:
  int size() const { return n_; }
  void Clear() { n_ = 0; }
  /// Factors the n x n matrix `a` (column-major, leading dimension lda, lower triangle
  /// read). False (and size 0) if it is not positive definite.
  bool Factor(int n, const double* a, int lda);
  /// Appends a row and column: `column` holds A(0..n-1, new) then A(new, new). False (the
  /// factor unchanged) if the new pivot is not positive, or below relative_pivot times
  /// A(new, new): the row is nearly dependent on the others, factor anew.
  bool Append(const double* column, double relative_pivot = 1e-10);
  /// Removes row and column k (0 <= k < size()); the others keep their order.
  void Remove(int k);
  /// x = A^-1 b in place (size() values).
  void Solve(double* b) const;
  /// L(i, j), i >= j (for tests).
  double L(int i, int j) const { return l_[std::size_t(i) + std::size_t(j) * std::size_t(lda_)]; }

 private:
  void Reserve(int n);
  std::vector<double> l_;  // column-major, leading dimension lda_
  int lda_ = 0, n_ = 0;
  std::vector<double> scratch_;
};

}  // namespace sedbridge::fem
