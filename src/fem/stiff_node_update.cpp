#include "fem/stiff_node_update.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <omp.h>

namespace sedbridge::fem {

namespace {
// Rows of the update's dense columns below which one thread does them (a parallel region
// costs a few microseconds; B's 5379 rows times ~20 columns take tens).
constexpr Eigen::Index kParallelMinRows = 3000;
}  // namespace

StiffNodeUpdate::StiffNodeUpdate(double column_budget_bytes, double relative_threshold)
    : budget_bytes_(column_budget_bytes), threshold_(relative_threshold) {}

void StiffNodeUpdate::SetRestMatrix(const SystemMatrix& A0) {
  rest_diagonal_.resize(size_t(A0.num_nodes()));
  for (int i = 0; i < A0.num_nodes(); ++i) rest_diagonal_[size_t(i)] = A0.Block(A0.DiagonalSlot(i));
  columns_.clear();
  slot_of_node_.clear();
  node_of_slot_.clear();
  last_used_.clear();
  pairs_.clear();
}

int StiffNodeUpdate::CachedColumns(int node, const RestSolve& rest_solve) {
  const auto found = slot_of_node_.find(node);
  if (found != slot_of_node_.end()) {
    last_used_[size_t(found->second)] = stamp_;
    return found->second;
  }
  const Eigen::Index n3 = 3 * Eigen::Index(rest_diagonal_.size());
  const size_t capacity = size_t(std::max(0.0, budget_bytes_ / (3.0 * double(n3) * sizeof(double))));
  int slot = -1;
  if (columns_.size() < capacity) {
    slot = int(columns_.size());
    columns_.emplace_back(n3, 3);
    node_of_slot_.push_back(-1);
    last_used_.push_back(0);
  } else {
    // Evict the least recently used node that this step does not need.
    long oldest = stamp_;
    for (size_t s = 0; s < last_used_.size(); ++s)
      if (last_used_[s] < oldest) {
        oldest = last_used_[s];
        slot = int(s);
      }
    if (slot < 0) return -1;
    slot_of_node_.erase(node_of_slot_[size_t(slot)]);
  }
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n3), x;
  for (int a = 0; a < 3; ++a) {
    e[3 * node + a] = 1.0;
    rest_solve(e, x);
    columns_[size_t(slot)].col(a) = x;
    e[3 * node + a] = 0.0;
  }
  column_solves_ += 3;
  node_of_slot_[size_t(slot)] = node;
  slot_of_node_[node] = slot;
  last_used_[size_t(slot)] = stamp_;
  return slot;
}

void StiffNodeUpdate::Prepare(const SystemMatrix& A, const std::vector<int>& nodes,
                              const std::vector<Eigen::Matrix3d>& rotations, const RestSolve& rest_solve) {
  Prepare(A.num_nodes(), [&](int i) { return A.Block(A.DiagonalSlot(i)); }, nodes, rotations, rest_solve);
}

void StiffNodeUpdate::Prepare(int num_nodes, const DiagonalBlockOf& diagonal_block, const std::vector<int>& nodes,
                              const std::vector<Eigen::Matrix3d>& rotations, const RestSolve& rest_solve) {
  ++stamp_;
  pairs_.clear();
  if (rest_diagonal_.size() != size_t(num_nodes)) return;  // no rest matrix yet
  std::vector<int> unique = nodes;
  std::sort(unique.begin(), unique.end());
  unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  std::vector<Pair> wanted;
  for (int i : unique) {
    if (i < 0 || i >= num_nodes) continue;
    const Eigen::Matrix3d& a0 = rest_diagonal_[size_t(i)];
    Eigen::Matrix3d c = diagonal_block(i);
    if (!rotations.empty()) c = rotations[size_t(i)].transpose() * c * rotations[size_t(i)];
    c -= a0;
    c = 0.5 * (c + c.transpose()).eval();
    if (!c.allFinite()) continue;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(c);
    const double floor = threshold_ * a0.trace() / 3.0;
    for (int k = 0; k < 3; ++k)
      if (eig.eigenvalues()[k] > floor) wanted.push_back({i, eig.eigenvectors().col(k), eig.eigenvalues()[k]});
  }
  // Mark the cached nodes this step needs before any eviction can pick them.
  for (const Pair& p : wanted) {
    const auto found = slot_of_node_.find(p.node);
    if (found != slot_of_node_.end()) last_used_[size_t(found->second)] = stamp_;
  }
  std::vector<int> slots;
  left_out_ = 0;
  for (const Pair& p : wanted) {
    const int slot = CachedColumns(p.node, rest_solve);
    if (slot < 0) {
      ++left_out_;
      continue;
    }
    pairs_.push_back(p);
    slots.push_back(slot);
  }
  const Eigen::Index k = Eigen::Index(pairs_.size());
  if (k == 0) return;
  const Eigen::Index rows = 3 * Eigen::Index(rest_diagonal_.size());
  z_.resize(rows, k);
  // By row ranges, each thread its own (k rest columns of 3 rows a node: megabytes on B).
#pragma omp parallel if (rows >= kParallelMinRows)
  {
    const Eigen::Index threads = omp_get_num_threads(), tid = omp_get_thread_num();
    const Eigen::Index begin = rows * tid / threads, end = rows * (tid + 1) / threads;
    for (Eigen::Index b = 0; b < k; ++b)
      z_.col(b).segment(begin, end - begin).noalias() =
          columns_[size_t(slots[size_t(b)])].middleRows(begin, end - begin) * pairs_[size_t(b)].direction;
  }
  Eigen::MatrixXd s(k, k);
  for (Eigen::Index a = 0; a < k; ++a)
    for (Eigen::Index b = 0; b < k; ++b)
      s(a, b) = pairs_[size_t(a)].direction.dot(z_.col(b).segment<3>(3 * pairs_[size_t(a)].node));
  s = 0.5 * (s + s.transpose()).eval();
  for (Eigen::Index a = 0; a < k; ++a) s(a, a) += 1.0 / pairs_[size_t(a)].stiffness;
  s_factor_.compute(s);
  if (s_factor_.info() != Eigen::Success) pairs_.clear();  // no update rather than a wrong one
}

void StiffNodeUpdate::Apply(Eigen::VectorXd& y) const {
  const Eigen::Index k = Eigen::Index(pairs_.size());
  if (k == 0) return;
  t_.resize(k);
  for (Eigen::Index a = 0; a < k; ++a) t_[a] = pairs_[size_t(a)].direction.dot(y.segment<3>(3 * pairs_[size_t(a)].node));
  s_ = s_factor_.solve(t_);
  const Eigen::Index rows = z_.rows();
#pragma omp parallel if (rows >= kParallelMinRows)
  {
    const Eigen::Index threads = omp_get_num_threads(), tid = omp_get_thread_num();
    const Eigen::Index begin = rows * tid / threads, end = rows * (tid + 1) / threads;
    y.segment(begin, end - begin).noalias() -= z_.middleRows(begin, end - begin) * s_;
  }
}

}  // namespace sedbridge::fem
