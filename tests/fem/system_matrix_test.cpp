#include "fem/system_matrix.h"

#include <gtest/gtest.h>

#include <type_traits>

namespace sedbridge::fem {
namespace {

// values_ points into the CSR's own buffer: a copy or move would point at the source's.
static_assert(!std::is_copy_constructible_v<SystemMatrix> && !std::is_copy_assignable_v<SystemMatrix>);
static_assert(!std::is_move_constructible_v<SystemMatrix> && !std::is_move_assignable_v<SystemMatrix>);

TEST(SystemMatrix, BlocksLandWhereDenseAssemblyPutsThem) {
  SystemMatrix A;
  A.Build(4, {{0, 2}, {1, 3}, {2, 3}});
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(12, 12);
  int seed = 1;
  auto block = [&seed]() {
    Eigen::Matrix3d b;
    for (int k = 0; k < 9; ++k) b(k / 3, k % 3) = ++seed;
    return b;
  };
  for (auto [i, j] : std::vector<std::pair<int, int>>{{0, 0}, {0, 2}, {2, 0}, {3, 2}, {1, 3}, {3, 3}}) {
    const Eigen::Matrix3d b = block();
    A.AddBlock(A.Slot(i, j), b);
    dense.block<3, 3>(3 * i, 3 * j) += b;
  }
  EXPECT_EQ(A.Slot(0, 1), -1);
  EXPECT_LT((Eigen::MatrixXd(A.csr()) - dense).norm(), 1e-12);
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(12, -1, 2), y;
  A.Multiply(x, y);
  EXPECT_LT((y - dense * x).norm(), 1e-9);
  A.SetZero();
  EXPECT_EQ(Eigen::MatrixXd(A.csr()).norm(), 0.0);
}

}  // namespace
}  // namespace sedbridge::fem
