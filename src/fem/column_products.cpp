#include "fem/column_products.h"

#include <omp.h>

#include "common/hot_clones.h"

namespace sedbridge::fem::column_products {

SEDBRIDGE_HOT_CLONES
void AddThreeColumns(int rows, const double* a0, const double* a1, const double* a2, double f0, double f1, double f2,
                     double* y) {
  for (int i = 0; i < rows; ++i) y[i] += a0[i] * f0 + a1[i] * f1 + a2[i] * f2;
}

// y = a0 f0 + a1 f1 + a2 f2.
SEDBRIDGE_HOT_CLONES
void SetThreeColumns(int rows, const double* a0, const double* a1, const double* a2, double f0, double f1, double f2,
                     double* y) {
  for (int i = 0; i < rows; ++i) y[i] = a0[i] * f0 + a1[i] * f1 + a2[i] * f2;
}

SEDBRIDGE_HOT_CLONES
void SetThreeColumns(int rows, const float* a0, const float* a1, const float* a2, double f0, double f1, double f2,
                     float* y) {
  for (int i = 0; i < rows; ++i) y[i] = float(double(a0[i]) * f0 + double(a1[i]) * f1 + double(a2[i]) * f2);
}

// The same from single-precision columns (summed in double).
SEDBRIDGE_HOT_CLONES
void AddThreeColumns(int rows, const float* a0, const float* a1, const float* a2, double f0, double f1, double f2,
                     double* y) {
  for (int i = 0; i < rows; ++i) y[i] += double(a0[i]) * f0 + double(a1[i]) * f1 + double(a2[i]) * f2;
}

// y += the four column triples a[3 t .. 3 t + 2] times f[3 t .. 3 t + 2], t = 0..3, in that
// order: each row the same sums as four AddThreeColumns calls, with one pass over y
// instead of four (y's loads and stores were as much traffic as G's columns).
SEDBRIDGE_HOT_CLONES
void AddFourColumnTriples(int rows, const float* const* a, const double* f, double* y) {
  const float *a0 = a[0], *a1 = a[1], *a2 = a[2], *b0 = a[3], *b1 = a[4], *b2 = a[5];
  const float *c0 = a[6], *c1 = a[7], *c2 = a[8], *d0 = a[9], *d1 = a[10], *d2 = a[11];
  const double fa0 = f[0], fa1 = f[1], fa2 = f[2], fb0 = f[3], fb1 = f[4], fb2 = f[5];
  const double fc0 = f[6], fc1 = f[7], fc2 = f[8], fd0 = f[9], fd1 = f[10], fd2 = f[11];
  for (int i = 0; i < rows; ++i) {
    double s = y[i];
    s += double(a0[i]) * fa0 + double(a1[i]) * fa1 + double(a2[i]) * fa2;
    s += double(b0[i]) * fb0 + double(b1[i]) * fb1 + double(b2[i]) * fb2;
    s += double(c0[i]) * fc0 + double(c1[i]) * fc1 + double(c2[i]) * fc2;
    s += double(d0[i]) * fd0 + double(d1[i]) * fd1 + double(d2[i]) * fd2;
    y[i] = s;
  }
}

// y += sum_t a[t] f[t], t = 0..7 (the SED's kept columns, eight a pass over y: y's loads
// and stores in doubles weigh as much as four single-precision columns). Single precision
// like G's, summed in double: the kept columns are a plane step's largest read.
SEDBRIDGE_HOT_CLONES
void AddEightColumns(int rows, const float* const* a, const double* f, double* y) {
  const float *a0 = a[0], *a1 = a[1], *a2 = a[2], *a3 = a[3], *a4 = a[4], *a5 = a[5], *a6 = a[6], *a7 = a[7];
  const double f0 = f[0], f1 = f[1], f2 = f[2], f3 = f[3], f4 = f[4], f5 = f[5], f6 = f[6], f7 = f[7];
  for (int i = 0; i < rows; ++i)
    y[i] += (double(a0[i]) * f0 + double(a1[i]) * f1 + double(a2[i]) * f2 + double(a3[i]) * f3) +
            (double(a4[i]) * f4 + double(a5[i]) * f5 + double(a6[i]) * f6 + double(a7[i]) * f7);
}

// y += sum_k coefficients[k] K.col(slots[k]) by row blocks over the team, as
// AddColumnsByRowBlocks (the same sums with any team).
void AddKeptColumnsByRowBlocks(const Eigen::MatrixXf& K, const std::vector<int>& slots,
                               const std::vector<double>& coefficients, int team, Eigen::VectorXd& y) {
  const Eigen::Index rows = K.rows();
  ForEachRowBlock(rows, team, [&](Eigen::Index begin, Eigen::Index end) {
    for (size_t k = 0; k < slots.size(); k += 8) {
      const float* a[8];
      double f[8];
      for (size_t t = 0; t < 8; ++t) {  // past the end: the first column again, times 0
        const bool in = k + t < slots.size();
        a[t] = K.data() + Eigen::Index(slots[in ? k + t : k]) * rows + begin;
        f[t] = in ? coefficients[k + t] : 0.0;
      }
      AddEightColumns(int(end - begin), a, f, y.data() + begin);
    }
  });
}

// y += sum_k A.middleCols<3>(3 columns[k]) forces.col(k): G's product for the SED, by row
// blocks over the caller's team when it is large (it runs at one core's memory bandwidth,
// docs/performance.md). Each row sums its columns in the same order with any team: the same
// bits.
void AddColumnsByRowBlocks(const Eigen::MatrixXf& A, const std::vector<int>& columns, const Eigen::Matrix3Xd& forces,
                           int team, Eigen::VectorXd& y) {
  const Eigen::Index rows = A.rows();
  ForEachRowBlock(rows, team, [&](Eigen::Index begin, Eigen::Index end) {
    size_t k = 0;
    for (; k + 4 <= columns.size(); k += 4) {
      const float* a[12];
      double f[12];
      for (int t = 0; t < 4; ++t) {
        const float* column = A.data() + 3 * Eigen::Index(columns[k + size_t(t)]) * rows + begin;
        for (int q = 0; q < 3; ++q) {
          a[3 * t + q] = column + q * rows;
          f[3 * t + q] = forces(q, Eigen::Index(k) + t);
        }
      }
      AddFourColumnTriples(int(end - begin), a, f, y.data() + begin);
    }
    for (; k < columns.size(); ++k) {
      const float* a = A.data() + 3 * Eigen::Index(columns[k]) * rows + begin;
      const auto f = forces.col(Eigen::Index(k));
      AddThreeColumns(int(end - begin), a, a + rows, a + 2 * rows, f[0], f[1], f[2], y.data() + begin);
    }
  });
}

}  // namespace sedbridge::fem::column_products
