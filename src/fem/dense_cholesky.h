#pragma once
// Cholesky factorization and solve of a small dense SPD matrix (the compliance method's
// contact QP, m up to a few hundred rows), in double precision.
//
// Why not Eigen's LLT: the project compiles for the x86-64 baseline, so Eigen's kernels
// run on 2-double SSE2 packets; this kernel is a right-looking factorization with 8-column
// panels whose trailing update is one fused, contiguous loop, built as an AVX2/FMA clone
// beside the baseline (common/hot_clones.h). Measured 2-4x faster than Eigen's LLT for
// m = 50-300 on the 2-core VM (dense_cholesky_benchmark).

namespace sedbridge::fem {

/// A = L L^T in place: `a` is n x n, column-major with leading dimension lda >= n; its
/// lower triangle (diagonal included) is read and overwritten by L; the strict upper
/// triangle is neither read nor written. Returns false (a partly overwritten) when a
/// pivot is not positive and finite: A is not positive definite (to rounding), or holds
/// NaN/Inf.
bool CholeskyFactorLower(int n, double* a, int lda);

/// Solves L L^T x = b in place (b: n values) with L from CholeskyFactorLower.
void CholeskySolveLower(int n, const double* l, int lda, double* b);

}  // namespace sedbridge::fem
