#pragma once
// The two triangular solves of a supernodal Cholesky factor (L L^T = P A P^T, as CHOLMOD
// stores it) on several cores. CHOLMOD's own solve walks the supernodes one after another:
// on these models a step's preconditioner solves were the serial part that kept a second
// core from helping (docs/performance.md). Supernodes in disjoint subtrees of the
// elimination tree do not depend on each other, so each thread takes whole subtrees (a
// nested-dissection ordering makes two big ones at the top) and the few supernodes above
// them (the top separators) run on one thread:
//   forward  L z = P b: subtrees in parallel (their updates to the top rows go to
//            per-thread buffers, summed after), then the top in order;
//   backward L^T w = z: the top in reverse order, then the subtrees in parallel;
//   x = P^T w.
// Same arithmetic as the serial sweep up to the order of the sums into the top rows.
// Dense blocks through Eigen (vectorized; no BLAS threads involved).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sedbridge::fem {

/// A supernodal L (CHOLMOD's cholmod_factor with is_super, is_ll, int indices, real
/// double): supernode j holds columns super[j] .. super[j+1]-1, row indices
/// s[pi[j] .. pi[j+1]) (its own columns first), values as a column-major block of
/// (pi[j+1]-pi[j]) rows at x + px[j]; perm[k] = the row of A that is L's row k.
struct SupernodalFactorView {
  int n = 0;
  int nsuper = 0;
  const int* super = nullptr;
  const int* pi = nullptr;
  const int* px = nullptr;
  const int* s = nullptr;
  const double* x = nullptr;
  const int* perm = nullptr;  ///< null = identity
};

class SupernodalTriangularSolve {
 public:
  /// Builds the subtree schedule for up to max_threads threads from the factor's pattern
  /// (values are not read; call again only when the pattern changes).
  void Analyze(const SupernodalFactorView& factor, int max_threads);
  /// x = A^-1 b with the factor's current values, on omp_get_max_threads() threads (at
  /// most the analysed count; 1 = a plain serial sweep). b and x must not alias.
  void Solve(const SupernodalFactorView& factor, const double* b, double* x);
  /// The same in single precision with `values_single`, L's values (factor.x) rounded to
  /// float: half the memory traffic of the double solve, which is memory-bound; about 7
  /// significant digits, for preconditioners (b and x stay double).
  void SolveSingle(const SupernodalFactorView& factor, const float* values_single, const double* b, double* x);

  /// Share of the triangular-solve work (stored entries of L) done serially at the top
  /// of the tree when the analysed thread count is used [0, 1].
  double serial_fraction() const { return serial_fraction_; }

 private:
  // Per value type: the permuted right-hand side, per-thread off-diagonal products and
  // per-list buffers for the top rows.
  template <typename Scalar>
  struct Workspace {
    std::vector<Scalar> y;
    std::vector<std::vector<Scalar>> scratch, top_buffers;
  };
  template <typename Scalar>
  void SolveWith(const SupernodalFactorView& f, const Scalar* values, Workspace<Scalar>& ws, const double* b,
                 double* x);
  template <typename Scalar>
  void Allocate(Workspace<Scalar>& ws) const;

  int n_ = 0;
  double serial_fraction_ = 1.0;
  std::vector<int> top_nodes_;                  // ascending
  std::vector<std::vector<int>> thread_nodes_;  // per thread, ascending
  std::vector<int> top_slot_;                   // per column: index into a top buffer, -1 = not top
  std::vector<int> top_columns_;                // columns of the top supernodes
  size_t largest_offdiagonal_ = 0;
  int max_threads_ = 1;
  Workspace<double> double_;
  Workspace<float> single_;
};

}  // namespace sedbridge::fem
