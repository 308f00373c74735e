#pragma once
// The compliance method's dense column products (fem/compliance_contact.h): y += a few
// columns of a column-major matrix (W, its kept columns T, G, the SED's kept columns) times
// their coefficients. With few contacts these passes are most of a contact step, so each is
// a raw-pointer loop with an AVX2 clone (common/hot_clones.h), summing in double whatever
// the columns' precision; the row-block forms split one product over an OpenMP team with
// every row summed in the same order (the same bits with any team).

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <utility>
#include <vector>

namespace sedbridge::fem::column_products {

/// y[i] += a0[i] f0 + a1[i] f1 + a2[i] f2, i < rows.
void AddThreeColumns(int rows, const double* a0, const double* a1, const double* a2, double f0, double f1, double f2,
                     double* y);
/// The same from single-precision columns (summed in double).
void AddThreeColumns(int rows, const float* a0, const float* a1, const float* a2, double f0, double f1, double f2,
                     double* y);
/// y[i] = a0[i] f0 + a1[i] f1 + a2[i] f2, i < rows.
void SetThreeColumns(int rows, const double* a0, const double* a1, const double* a2, double f0, double f1, double f2,
                     double* y);
/// The same from and into single precision (summed in double, rounded once).
void SetThreeColumns(int rows, const float* a0, const float* a1, const float* a2, double f0, double f1, double f2,
                     float* y);
/// y += the four column triples a[3 t .. 3 t + 2] times f[3 t .. 3 t + 2], t = 0..3, in that
/// order: each row the same sums as four AddThreeColumns calls, with one pass over y
/// instead of four (y's loads and stores were as much traffic as G's columns).
void AddFourColumnTriples(int rows, const float* const* a, const double* f, double* y);
/// y += sum_t a[t] f[t], t = 0..7, eight single-precision columns a pass over y.
void AddEightColumns(int rows, const float* const* a, const double* f, double* y);

/// Row blocks [begin, end) of `rows` for thread `t` of `n`, in whole cache lines of doubles.
inline std::pair<Eigen::Index, Eigen::Index> RowBlock(Eigen::Index rows, int t, int n) {
  const Eigen::Index chunk = ((rows + n - 1) / n + 7) / 8 * 8;
  const Eigen::Index begin = std::min(rows, t * chunk);
  return {begin, std::min(rows, begin + chunk)};
}

/// Calls block(begin, end) for each non-empty row block of `rows` over a team of `team`
/// threads (team <= 1: once, [0, rows), on the caller's thread).
template <typename Block>
void ForEachRowBlock(Eigen::Index rows, int team, const Block& block) {
#pragma omp parallel num_threads(team) if (team > 1)
  {
    const auto [begin, end] = RowBlock(rows, omp_get_thread_num(), omp_get_num_threads());
    if (begin < end) block(begin, end);
  }
}

/// y += A.middleCols<3>(3 j) * f as one fused pass over the rows (Eigen's generic 3-column
/// product path was the largest cost of a step with many contacts).
template <typename Matrix>
void AddColumns3(const Matrix& A, int j, const Eigen::Vector3d& f, Eigen::VectorXd& y) {
  const Eigen::Index rows = A.rows();
  const auto* a = A.data() + 3 * Eigen::Index(j) * rows;
  AddThreeColumns(int(rows), a, a + rows, a + 2 * rows, f[0], f[1], f[2], y.data());
}

/// y += sum_k A.middleCols<3>(3 columns[k]) forces.col(k) (G's product for the SED), by row
/// blocks over `team` threads (1: the caller's thread).
void AddColumnsByRowBlocks(const Eigen::MatrixXf& A, const std::vector<int>& columns, const Eigen::Matrix3Xd& forces,
                           int team, Eigen::VectorXd& y);
/// y += sum_k coefficients[k] K.col(slots[k]) (the SED's kept columns), by row blocks over
/// `team` threads, eight columns a pass.
void AddKeptColumnsByRowBlocks(const Eigen::MatrixXf& K, const std::vector<int>& slots,
                               const std::vector<double>& coefficients, int team, Eigen::VectorXd& y);

}  // namespace sedbridge::fem::column_products
