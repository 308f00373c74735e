#include "fem/column_products.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace sedbridge::fem::column_products {
namespace {

Eigen::MatrixXf Columns(int rows, int cols) {
  Eigen::MatrixXf a(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) a(i, j) = float(std::sin(0.37 * i + 1.3 * j) + 0.01 * j);
  return a;
}

// Row blocks tile [0, rows) in order, each starting on a whole cache line of doubles.
TEST(ColumnProducts, RowBlocksTileTheRows) {
  for (const int rows : {0, 1, 7, 8, 9, 100, 4074})
    for (const int n : {1, 2, 3, 8}) {
      Eigen::Index next = 0;
      for (int t = 0; t < n; ++t) {
        const auto [begin, end] = RowBlock(rows, t, n);
        EXPECT_EQ(begin, next) << rows << " " << n;
        EXPECT_LE(begin, end);
        if (begin < rows) EXPECT_EQ(begin % 8, 0);
        next = end;
      }
      EXPECT_EQ(next, rows) << rows << " " << n;
    }
}

// G's product four contacts a pass (and the rest one by one) is the plain product, and a
// team of 3 (uneven blocks) gives one thread's bits.
TEST(ColumnProducts, ColumnTriplesByRowBlocksAreTheProductWithAnyTeam) {
  const int rows = 203;
  const Eigen::MatrixXf A = Columns(rows, 3 * 9);
  const std::vector<int> columns = {4, 0, 7, 2, 8, 1, 5};  // 4 + 3 left over
  Eigen::Matrix3Xd forces(3, columns.size());
  for (Eigen::Index k = 0; k < forces.cols(); ++k) forces.col(k) = Eigen::Vector3d(0.5 + k, -0.25 * k, 1.0 / (1 + k));
  Eigen::VectorXd expected = Eigen::VectorXd::Constant(rows, 0.125);
  for (size_t k = 0; k < columns.size(); ++k)
    expected += A.middleCols<3>(3 * columns[k]).cast<double>() * forces.col(Eigen::Index(k));
  Eigen::VectorXd one = Eigen::VectorXd::Constant(rows, 0.125), three = one;
  AddColumnsByRowBlocks(A, columns, forces, 1, one);
  AddColumnsByRowBlocks(A, columns, forces, 3, three);
  EXPECT_LT((one - expected).norm(), 1e-13 * expected.norm());
  EXPECT_EQ(one, three);
}

// The kept columns eight a pass, a pass padded with zero coefficients, are the plain sum.
TEST(ColumnProducts, KeptColumnsByRowBlocksAreTheSumWithAnyTeam) {
  const int rows = 77;
  const Eigen::MatrixXf K = Columns(rows, 16);
  const std::vector<int> slots = {3, 15, 0, 9, 4, 11, 2, 7, 12, 1, 6};  // 8 + 3
  std::vector<double> coefficients;
  for (size_t k = 0; k < slots.size(); ++k) coefficients.push_back(1.0 - 0.3 * double(k));
  Eigen::VectorXd expected = Eigen::VectorXd::Ones(rows);
  for (size_t k = 0; k < slots.size(); ++k) expected += coefficients[k] * K.col(slots[k]).cast<double>();
  Eigen::VectorXd one = Eigen::VectorXd::Ones(rows), three = one;
  AddKeptColumnsByRowBlocks(K, slots, coefficients, 1, one);
  AddKeptColumnsByRowBlocks(K, slots, coefficients, 3, three);
  EXPECT_LT((one - expected).norm(), 1e-13 * expected.norm());
  EXPECT_EQ(one, three);
  Eigen::VectorXd none = Eigen::VectorXd::Ones(rows);
  AddKeptColumnsByRowBlocks(K, {}, {}, 1, none);
  EXPECT_EQ(none, Eigen::VectorXd::Ones(rows));
}

}  // namespace
}  // namespace sedbridge::fem::column_products
