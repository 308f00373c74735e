// The contact QP's dense Cholesky (fem/dense_cholesky.h) against Eigen's LLT: factor,
// solve, the panel edges (sizes around multiples of 8), a leading dimension larger than
// n, and matrices that are not positive definite.

#include "fem/dense_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <random>

namespace sedbridge::fem {
namespace {

// A random SPD matrix with condition number ~1e4 (a contact QP's N^T W N + I/k is of that
// order on model B).
Eigen::MatrixXd RandomSpd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd q = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(rng); });
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(q);
  const Eigen::MatrixXd Q = qr.householderQ();
  Eigen::VectorXd eigenvalues(n);
  for (int i = 0; i < n; ++i) eigenvalues[i] = std::pow(1e4, n > 1 ? double(i) / (n - 1) : 0.0);
  return Q * eigenvalues.asDiagonal() * Q.transpose();
}

TEST(DenseCholesky, FactorAndSolveMatchEigenAcrossPanelEdges) {
  for (int n : {1, 2, 7, 8, 9, 15, 16, 17, 63, 64, 65, 150, 221}) {
    const Eigen::MatrixXd A = RandomSpd(n, unsigned(n));
    Eigen::MatrixXd L = A;
    ASSERT_TRUE(CholeskyFactorLower(n, L.data(), n)) << n;
    const Eigen::MatrixXd lower = L.triangularView<Eigen::Lower>();
    EXPECT_LT((lower * lower.transpose() - A).norm(), 1e-12 * A.norm()) << n;
    const Eigen::MatrixXd eigen_L = A.llt().matrixL();
    EXPECT_LT((lower - eigen_L).norm(), 1e-10 * eigen_L.norm()) << n;

    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    Eigen::VectorXd x = b;
    CholeskySolveLower(n, L.data(), n, x.data());
    EXPECT_LT((A * x - b).norm(), 1e-10 * b.norm() * 1e4) << n;
    EXPECT_LT((x - A.llt().solve(b)).norm(), 1e-9 * x.norm()) << n;
  }
}

TEST(DenseCholesky, LeadingDimensionAndUpperTriangleUntouched) {
  const int n = 19, lda = 23;
  const Eigen::MatrixXd A = RandomSpd(n, 7);
  Eigen::MatrixXd storage = Eigen::MatrixXd::Constant(lda, n, 12345.0);
  storage.topRows(n).triangularView<Eigen::Lower>() = A;
  ASSERT_TRUE(CholeskyFactorLower(n, storage.data(), lda));
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < j; ++i) EXPECT_EQ(storage(i, j), 12345.0) << i << "," << j;
    for (int i = n; i < lda; ++i) EXPECT_EQ(storage(i, j), 12345.0) << i << "," << j;
  }
  const Eigen::MatrixXd L = storage.topRows(n).triangularView<Eigen::Lower>();
  EXPECT_LT((L * L.transpose() - A).norm(), 1e-12 * A.norm());
}

TEST(DenseCholesky, NotPositiveDefiniteOrNaNIsRefused) {
  for (int n : {3, 12, 40}) {
    Eigen::MatrixXd A = RandomSpd(n, 3);
    A(n - 1, n - 1) = -1.0;  // a later pivot goes negative
    Eigen::MatrixXd L = A;
    EXPECT_FALSE(CholeskyFactorLower(n, L.data(), n)) << n;
    Eigen::MatrixXd B = RandomSpd(n, 4);
    B(n - 1, 0) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(CholeskyFactorLower(n, B.data(), n)) << n;
    Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(n, n);  // semidefinite: a zero pivot
    EXPECT_FALSE(CholeskyFactorLower(n, Z.data(), n)) << n;
  }
  EXPECT_TRUE(CholeskyFactorLower(0, nullptr, 1));
}

// Rows join and leave as an active set's do: after every change the factor is that of the
// current rows' submatrix (in their current order), and solves match Eigen's.
TEST(UpdatableCholesky, AppendAndRemoveKeepTheFactorOfTheCurrentRows) {
  const int total = 60;
  const Eigen::MatrixXd A = RandomSpd(total, 11);
  std::mt19937 rng(5);
  std::vector<int> rows = {3, 17, 4, 40, 22};
  Eigen::MatrixXd start(rows.size(), rows.size());
  for (size_t a = 0; a < rows.size(); ++a)
    for (size_t b = 0; b < rows.size(); ++b) start(Eigen::Index(a), Eigen::Index(b)) = A(rows[a], rows[b]);
  UpdatableCholesky f;
  ASSERT_TRUE(f.Factor(int(rows.size()), start.data(), int(rows.size())));
  int appended = 0, removed = 0;
  for (int change = 0; change < 200; ++change) {
    const bool add = rows.size() < 3 || (rows.size() < 45 && rng() % 3 != 0);
    if (add) {
      int r;
      do r = int(rng() % total); while (std::find(rows.begin(), rows.end(), r) != rows.end());
      std::vector<double> column;
      for (int q : rows) column.push_back(A(q, r));
      column.push_back(A(r, r));
      ASSERT_TRUE(f.Append(column.data()));
      rows.push_back(r);
      ++appended;
    } else {
      const int k = int(rng() % rows.size());
      f.Remove(k);
      rows.erase(rows.begin() + k);
      ++removed;
    }
    const int n = int(rows.size());
    ASSERT_EQ(f.size(), n);
    Eigen::MatrixXd sub(n, n), L = Eigen::MatrixXd::Zero(n, n);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        sub(a, b) = A(rows[size_t(a)], rows[size_t(b)]);
        if (a >= b) L(a, b) = f.L(a, b);
      }
    ASSERT_LT((L * L.transpose() - sub).norm(), 1e-11 * sub.norm()) << change;
    Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, 1.0, -2.0);
    const Eigen::VectorXd expected = sub.llt().solve(x);
    f.Solve(x.data());
    ASSERT_LT((x - expected).norm(), 1e-8 * expected.norm()) << change;
  }
  EXPECT_GT(appended, 50);
  EXPECT_GT(removed, 50);
}

TEST(UpdatableCholesky, ADependentRowIsRefusedAndTheFactorKept) {
  const Eigen::MatrixXd A = RandomSpd(6, 2);
  UpdatableCholesky f;
  ASSERT_TRUE(f.Factor(6, A.data(), 6));
  // Row 2 again: A with it appended is singular.
  std::vector<double> column(A.col(2).data(), A.col(2).data() + 6);
  column.push_back(A(2, 2));
  EXPECT_FALSE(f.Append(column.data()));
  EXPECT_EQ(f.size(), 6);
  Eigen::VectorXd x = Eigen::VectorXd::Ones(6);
  f.Solve(x.data());
  EXPECT_LT((A * x - Eigen::VectorXd::Ones(6)).norm(), 1e-9);
  Eigen::MatrixXd not_spd = A;
  not_spd(5, 5) = -1;
  EXPECT_FALSE(f.Factor(6, not_spd.data(), 6));
  EXPECT_EQ(f.size(), 0);
}

}  // namespace
}  // namespace sedbridge::fem
