#pragma once
// Symmetric system matrix with a fixed 3x3-block pattern, stored as row-major CSR so that
// assembly writes values in place (no triplets, no allocation per step) and the same
// arrays can be read as column-major by sparse Cholesky (the matrix is symmetric).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <utility>
#include <vector>

#include "common/no_copy_no_move.h"

namespace sedbridge::fem {

class SystemMatrix {
 public:
  using Csr = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

  // values_ points into csr_'s buffer: a copy (and Eigen 3.4's SparseMatrix has no move
  // constructor, so a "move" too) would point at the source's values.
  SEDBRIDGE_NO_COPY_NO_MOVE(SystemMatrix)
  SystemMatrix() = default;

  /// Pattern: the diagonal block of every node plus (i,j) and (j,i) for each pair given.
  void Build(int num_nodes, const std::vector<std::pair<int, int>>& coupled_nodes);

  /// Slot of block (i, j), or -1 if not in the pattern. O(log degree); call at setup.
  int Slot(int i, int j) const;
  int DiagonalSlot(int i) const { return diagonal_slot_[size_t(i)]; }

  /// Adds `scale * block` into slot s. Not synchronised: callers partition by block row.
  void AddBlock(int slot, const Eigen::Matrix3d& block, double scale = 1.0) { AddBlockTo(values_, slot, block, scale); }
  /// Same into another value array laid out like this matrix (per-thread partial sums).
  void AddBlockTo(double* values, int slot, const Eigen::Matrix3d& block, double scale) const {
    double* base = values + slot_base_[size_t(slot)];
    const int stride = slot_stride_[size_t(slot)];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) base[a * stride + b] += scale * block(a, b);
  }
  /// Adds a diagonal (s * I) to a block.
  void AddScaledIdentity(int slot, double s) {
    double* base = values_ + slot_base_[size_t(slot)];
    const int stride = slot_stride_[size_t(slot)];
    for (int a = 0; a < 3; ++a) base[a * stride + a] += s;
  }
  Eigen::Matrix3d Block(int slot) const;

  void SetZero();
  /// Zeroes the diagonal blocks only.
  void SetDiagonalZero();
  int num_nodes() const { return num_nodes_; }
  double* values() { return values_; }
  int num_values() const { return int(csr_.nonZeros()); }
  int num_blocks() const { return int(slot_base_.size()); }
  const Csr& csr() const { return csr_; }
  Csr& csr() { return csr_; }

  /// y = A x (OpenMP over rows).
  void Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// y = D x with D the diagonal blocks of A (y resized).
  void MultiplyDiagonalBlocks(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// The diagonal blocks, 9 values a node (row-major), into `packed` (resized). A block's
  /// rows lie a whole block row apart here (three cache lines a node); packed they are
  /// one, for solvers that read them several times a step.
  void GatherDiagonalBlocks(std::vector<double>& packed) const;
  /// y = D x with D given packed as by GatherDiagonalBlocks (y resized).
  static void MultiplyPackedBlocks(const std::vector<double>& packed, const Eigen::VectorXd& x, Eigen::VectorXd& y);

 private:
  /// f(node, its diagonal block's first value, the offset between the block's rows) for
  /// every node, on the OpenMP team from a thousand nodes.
  template <typename F>
  void ForEachDiagonalBlock(F&& f) const;

  int num_nodes_ = 0;
  Csr csr_;
  double* values_ = nullptr;
  std::vector<int> block_row_start_;  // per node: first slot of its block row (CSR of blocks)
  std::vector<int> block_cols_;       // per slot: block column
  std::vector<int> slot_base_;        // per slot: value offset of entry (0,0)
  std::vector<int> slot_stride_;      // per slot: value offset between rows of the block
  std::vector<int> diagonal_slot_;
};

}  // namespace sedbridge::fem
