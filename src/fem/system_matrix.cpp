#include "fem/system_matrix.h"

#include <algorithm>

namespace sedbridge::fem {

// Below this a product takes ~0.2 ms: a parallel region costs more than it saves, and far
// more when the machine is loaded (each barrier may wait a scheduler time slice; the step's
// ThreadTeamChooser then keeps one thread). B_fine's and B_x4's step matrices are above it.
constexpr long kParallelMinNonZeros = 200'000;
// Passes over the diagonal blocks only: a parallel region costs a few microseconds, one
// thread's pass over B's 1793 nodes 30-60 (the blocks are scattered over the matrix).
constexpr int kParallelMinNodes = 1000;

void SystemMatrix::Build(int n, const std::vector<std::pair<int, int>>& pairs) {
  num_nodes_ = n;
  std::vector<std::vector<int>> cols(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) cols[size_t(i)].push_back(i);
  for (const auto& [i, j] : pairs) {
    cols[size_t(i)].push_back(j);
    cols[size_t(j)].push_back(i);
  }
  block_row_start_.assign(size_t(n) + 1, 0);
  block_cols_.clear();
  for (int i = 0; i < n; ++i) {
    auto& c = cols[size_t(i)];
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    block_row_start_[size_t(i) + 1] = block_row_start_[size_t(i)] + int(c.size());
    block_cols_.insert(block_cols_.end(), c.begin(), c.end());
  }
  const int num_slots = block_row_start_.back();
  const int nnz = 9 * num_slots;
  csr_.resize(3 * n, 3 * n);
  csr_.resizeNonZeros(nnz);
  int* outer = csr_.outerIndexPtr();
  int* inner = csr_.innerIndexPtr();
  slot_base_.resize(size_t(num_slots));
  slot_stride_.resize(size_t(num_slots));
  diagonal_slot_.resize(size_t(n));
  int offset = 0;
  for (int i = 0; i < n; ++i) {
    const int first = block_row_start_[size_t(i)], last = block_row_start_[size_t(i) + 1];
    const int stride = 3 * (last - first);
    for (int a = 0; a < 3; ++a) {
      outer[3 * i + a] = offset + a * stride;
      for (int s = first; s < last; ++s)
        for (int b = 0; b < 3; ++b) inner[offset + a * stride + 3 * (s - first) + b] = 3 * block_cols_[size_t(s)] + b;
    }
    for (int s = first; s < last; ++s) {
      slot_base_[size_t(s)] = offset + 3 * (s - first);
      slot_stride_[size_t(s)] = stride;
      if (block_cols_[size_t(s)] == i) diagonal_slot_[size_t(i)] = s;
    }
    offset += 3 * stride;
  }
  outer[3 * n] = offset;
  values_ = csr_.valuePtr();
  SetZero();
}

int SystemMatrix::Slot(int i, int j) const {
  const auto first = block_cols_.begin() + block_row_start_[size_t(i)];
  const auto last = block_cols_.begin() + block_row_start_[size_t(i) + 1];
  const auto it = std::lower_bound(first, last, j);
  return (it != last && *it == j) ? int(it - block_cols_.begin()) : -1;
}

Eigen::Matrix3d SystemMatrix::Block(int slot) const {
  Eigen::Matrix3d m;
  const double* base = values_ + slot_base_[size_t(slot)];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) m(a, b) = base[a * slot_stride_[size_t(slot)] + b];
  return m;
}

void SystemMatrix::SetZero() { std::fill(values_, values_ + csr_.nonZeros(), 0.0); }

template <typename F>
void SystemMatrix::ForEachDiagonalBlock(F&& f) const {
#pragma omp parallel for schedule(static) if (num_nodes_ >= kParallelMinNodes)
  for (int i = 0; i < num_nodes_; ++i) {
    const int slot = diagonal_slot_[size_t(i)];
    f(i, values_ + slot_base_[size_t(slot)], slot_stride_[size_t(slot)]);
  }
}

void SystemMatrix::SetDiagonalZero() {
  ForEachDiagonalBlock([](int, double* base, int stride) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) base[a * stride + b] = 0.0;
  });
}

void SystemMatrix::MultiplyDiagonalBlocks(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.resize(3 * num_nodes_);
  ForEachDiagonalBlock([&](int i, const double* base, int stride) {
    for (int a = 0; a < 3; ++a)
      y[3 * i + a] = base[a * stride] * x[3 * i] + base[a * stride + 1] * x[3 * i + 1] + base[a * stride + 2] * x[3 * i + 2];
  });
}

void SystemMatrix::GatherDiagonalBlocks(std::vector<double>& packed) const {
  packed.resize(9 * size_t(num_nodes_));
  ForEachDiagonalBlock([&](int i, const double* base, int stride) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) packed[9 * size_t(i) + size_t(3 * a + b)] = base[a * stride + b];
  });
}

void SystemMatrix::MultiplyPackedBlocks(const std::vector<double>& packed, const Eigen::VectorXd& x,
                                        Eigen::VectorXd& y) {
  const int n = int(packed.size() / 9);
  y.resize(3 * n);
#pragma omp parallel for schedule(static) if (n >= kParallelMinNodes)
  for (int i = 0; i < n; ++i) {
    const double* d = packed.data() + 9 * size_t(i);
    const double x0 = x[3 * i], x1 = x[3 * i + 1], x2 = x[3 * i + 2];
    for (int a = 0; a < 3; ++a) y[3 * i + a] = d[3 * a] * x0 + d[3 * a + 1] * x1 + d[3 * a + 2] * x2;
  }
}

void SystemMatrix::Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  const int rows = int(csr_.rows());
  y.resize(rows);
  const int* outer = csr_.outerIndexPtr();
  const int* inner = csr_.innerIndexPtr();
  const double* v = csr_.valuePtr();
#pragma omp parallel for schedule(static) if (csr_.nonZeros() > kParallelMinNonZeros)
  for (int r = 0; r < rows; ++r) {
    double s = 0;
    for (int k = outer[r]; k < outer[r + 1]; ++k) s += v[k] * x[inner[k]];
    y[r] = s;
  }
}

}  // namespace sedbridge::fem
