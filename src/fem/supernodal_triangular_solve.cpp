#include "fem/supernodal_triangular_solve.h"

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <functional>
#include <numeric>
#include <queue>

namespace sedbridge::fem {
namespace {

template <typename Scalar>
using ConstBlock = Eigen::Map<const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>, 0, Eigen::OuterStride<>>;
template <typename Scalar>
using VectorMap = Eigen::Map<Eigen::Matrix<Scalar, Eigen::Dynamic, 1>>;

// One supernode of L z = y: updates below it go to y, or to top_buffer for the top rows
// when given (top_slot: column -> buffer index, -1 = not top); scratch holds the
// off-diagonal rows.
template <typename Scalar>
void ForwardNode(const SupernodalFactorView& f, const Scalar* values, const std::vector<int>& top_slot, int j,
                 Scalar* y, Scalar* top_buffer, Scalar* scratch) {
  const int k1 = f.super[j], nscol = f.super[j + 1] - k1;
  const int p0 = f.pi[j], nsrow = f.pi[j + 1] - p0, m = nsrow - nscol;
  const ConstBlock<Scalar> L(values + f.px[j], nsrow, nscol, Eigen::OuterStride<>(nsrow));
  VectorMap<Scalar> z(y + k1, nscol);
  L.topRows(nscol).template triangularView<Eigen::Lower>().solveInPlace(z);
  if (m == 0) return;
  VectorMap<Scalar> t(scratch, m);
  t.noalias() = L.bottomRows(m) * z;
  const int* rows = f.s + p0 + nscol;
  if (!top_buffer) {
    for (int i = 0; i < m; ++i) y[rows[i]] -= t[i];
    return;
  }
  for (int i = 0; i < m; ++i) {
    const int slot = top_slot[size_t(rows[i])];
    if (slot < 0)
      y[rows[i]] -= t[i];
    else
      top_buffer[slot] += t[i];
  }
}

// One supernode of L^T w = z.
template <typename Scalar>
void BackwardNode(const SupernodalFactorView& f, const Scalar* values, int j, Scalar* w, Scalar* scratch) {
  const int k1 = f.super[j], nscol = f.super[j + 1] - k1;
  const int p0 = f.pi[j], nsrow = f.pi[j + 1] - p0, m = nsrow - nscol;
  const ConstBlock<Scalar> L(values + f.px[j], nsrow, nscol, Eigen::OuterStride<>(nsrow));
  VectorMap<Scalar> z(w + k1, nscol);
  if (m > 0) {
    VectorMap<Scalar> t(scratch, m);
    const int* rows = f.s + p0 + nscol;
    for (int i = 0; i < m; ++i) t[i] = w[rows[i]];
    z.noalias() -= L.bottomRows(m).transpose() * t;
  }
  L.topRows(nscol).template triangularView<Eigen::Lower>().transpose().solveInPlace(z);
}

// Longest-processing-time assignment of subtrees to threads: each subtree, heaviest first,
// to the least loaded thread. Returns the largest load; owner[k] = thread of roots[k].
double AssignSubtrees(const std::vector<int>& roots, const std::vector<double>& subtree_work, int threads,
                      std::vector<int>* owner) {
  std::vector<int> order(roots.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return subtree_work[size_t(roots[size_t(a)])] > subtree_work[size_t(roots[size_t(b)])];
  });
  using Load = std::pair<double, int>;
  std::priority_queue<Load, std::vector<Load>, std::greater<Load>> loads;
  for (int t = 0; t < threads; ++t) loads.push({0.0, t});
  if (owner) owner->assign(roots.size(), 0);
  double largest = 0;
  for (int k : order) {
    Load l = loads.top();
    loads.pop();
    l.first += subtree_work[size_t(roots[size_t(k)])];
    largest = std::max(largest, l.first);
    if (owner) (*owner)[size_t(k)] = l.second;
    loads.push(l);
  }
  return largest;
}

}  // namespace

void SupernodalTriangularSolve::Analyze(const SupernodalFactorView& f, int max_threads) {
  n_ = f.n;
  top_nodes_.clear();
  thread_nodes_.clear();
  top_columns_.clear();
  top_slot_.assign(size_t(f.n), -1);
  const int ns = f.nsuper;
  std::vector<int> super_of_column(static_cast<size_t>(f.n), -1);
  size_t largest_offdiagonal = 0;
  for (int j = 0; j < ns; ++j) {
    for (int c = f.super[j]; c < f.super[j + 1]; ++c) super_of_column[size_t(c)] = j;
    largest_offdiagonal =
        std::max(largest_offdiagonal, size_t(f.pi[j + 1] - f.pi[j] - (f.super[j + 1] - f.super[j])));
  }
  // Supernodal elimination tree: the parent holds the first row below the diagonal block.
  std::vector<int> parent(static_cast<size_t>(ns), -1);
  std::vector<double> work(static_cast<size_t>(ns));
  bool topological = true;
  for (int j = 0; j < ns; ++j) {
    const int nscol = f.super[j + 1] - f.super[j];
    const int nsrow = f.pi[j + 1] - f.pi[j];
    work[size_t(j)] = double(nsrow) * double(nscol);
    if (nsrow > nscol) parent[size_t(j)] = super_of_column[size_t(f.s[f.pi[j] + nscol])];
    if (parent[size_t(j)] >= 0 && parent[size_t(j)] <= j) topological = false;
  }
  const double total = std::accumulate(work.begin(), work.end(), 0.0);
  largest_offdiagonal_ = largest_offdiagonal;
  max_threads_ = std::max(1, max_threads);
  double_ = {};
  single_ = {};
  std::vector<int> all(static_cast<size_t>(ns));
  std::iota(all.begin(), all.end(), 0);
  if (max_threads <= 1 || !topological || ns < 2) {
    thread_nodes_.push_back(all);  // one serial sweep in column order
    serial_fraction_ = 1.0;
    return;
  }
  std::vector<double> subtree = work;  // becomes each supernode's subtree total below
  std::vector<std::vector<int>> children(static_cast<size_t>(ns));
  std::vector<int> roots;
  for (int j = 0; j < ns; ++j) {
    const int p = parent[size_t(j)];
    if (p >= 0) {
      subtree[size_t(p)] += subtree[size_t(j)];
      children[size_t(p)].push_back(j);
    } else {
      roots.push_back(j);
    }
  }
  // Move the heaviest subtree's root to the serial top while that shortens the estimated
  // time (top work + the most loaded thread's subtrees); keep the best split seen.
  std::vector<char> on_top(static_cast<size_t>(ns), 0);
  double top_work = 0;
  double best = AssignSubtrees(roots, subtree, max_threads, nullptr);
  std::vector<int> best_roots = roots;
  std::vector<char> best_top = on_top;
  for (int split = 0; split < 512; ++split) {
    auto heaviest = std::max_element(roots.begin(), roots.end(),
                                     [&](int a, int b) { return subtree[size_t(a)] < subtree[size_t(b)]; });
    const int r = *heaviest;
    if (children[size_t(r)].empty() || subtree[size_t(r)] < total / (16.0 * max_threads)) break;
    roots.erase(heaviest);
    roots.insert(roots.end(), children[size_t(r)].begin(), children[size_t(r)].end());
    on_top[size_t(r)] = 1;
    top_work += work[size_t(r)];
    const double estimate = top_work + AssignSubtrees(roots, subtree, max_threads, nullptr);
    if (estimate < best) {
      best = estimate;
      best_roots = roots;
      best_top = on_top;
    }
  }
  std::vector<int> owner;
  AssignSubtrees(best_roots, subtree, max_threads, &owner);
  std::vector<std::vector<int>> lists(static_cast<size_t>(max_threads));
  for (size_t k = 0; k < best_roots.size(); ++k) {
    std::vector<int> stack{best_roots[k]};
    auto& list = lists[size_t(owner[k])];
    while (!stack.empty()) {
      const int j = stack.back();
      stack.pop_back();
      list.push_back(j);
      for (int c : children[size_t(j)]) stack.push_back(c);
    }
  }
  for (auto& l : lists)
    if (!l.empty()) {
      std::sort(l.begin(), l.end());
      thread_nodes_.push_back(std::move(l));
    }
  double serial = 0;
  for (int j = 0; j < ns; ++j)
    if (best_top[size_t(j)]) {
      top_nodes_.push_back(j);
      serial += work[size_t(j)];
      for (int c = f.super[j]; c < f.super[j + 1]; ++c) {
        top_slot_[size_t(c)] = int(top_columns_.size());
        top_columns_.push_back(c);
      }
    }
  serial_fraction_ = total > 0 ? serial / total : 0.0;
}

template <typename Scalar>
void SupernodalTriangularSolve::Allocate(Workspace<Scalar>& ws) const {
  if (ws.y.size() == size_t(n_)) return;
  ws.y.assign(size_t(n_), Scalar(0));
  ws.scratch.assign(size_t(max_threads_), std::vector<Scalar>(largest_offdiagonal_));
  ws.top_buffers.assign(thread_nodes_.size(), std::vector<Scalar>(top_columns_.size()));
}

void SupernodalTriangularSolve::Solve(const SupernodalFactorView& f, const double* b, double* x) {
  SolveWith(f, f.x, double_, b, x);
}

void SupernodalTriangularSolve::SolveSingle(const SupernodalFactorView& f, const float* values_single,
                                            const double* b, double* x) {
  SolveWith(f, values_single, single_, b, x);
}

template <typename Scalar>
void SupernodalTriangularSolve::SolveWith(const SupernodalFactorView& f, const Scalar* values, Workspace<Scalar>& ws,
                                          const double* b, double* x) {
  Allocate(ws);
  Scalar* y = ws.y.data();
  for (int k = 0; k < n_; ++k) y[k] = Scalar(b[f.perm ? f.perm[k] : k]);
  const int lists = int(thread_nodes_.size());
  const int threads = std::min({omp_get_max_threads(), lists, max_threads_});
  if (threads <= 1) {
    // Serial: every supernode in column order (a topological order), then back.
    Scalar* scratch = ws.scratch[0].data();
    for (const auto& list : thread_nodes_)
      for (int j : list) ForwardNode(f, values, top_slot_, j, y, static_cast<Scalar*>(nullptr), scratch);
    for (int j : top_nodes_) ForwardNode(f, values, top_slot_, j, y, static_cast<Scalar*>(nullptr), scratch);
    for (auto it = top_nodes_.rbegin(); it != top_nodes_.rend(); ++it) BackwardNode(f, values, *it, y, scratch);
    for (auto l = thread_nodes_.rbegin(); l != thread_nodes_.rend(); ++l)
      for (auto it = l->rbegin(); it != l->rend(); ++it) BackwardNode(f, values, *it, y, scratch);
  } else {
#pragma omp parallel num_threads(threads)
    {
      const int tid = omp_get_thread_num(), team = omp_get_num_threads();
      for (int l = tid; l < lists; l += team) {
        auto& buffer = ws.top_buffers[size_t(l)];
        std::fill(buffer.begin(), buffer.end(), Scalar(0));
        for (int j : thread_nodes_[size_t(l)])
          ForwardNode(f, values, top_slot_, j, y, buffer.data(), ws.scratch[size_t(tid)].data());
      }
    }
    for (const auto& buffer : ws.top_buffers)
      for (size_t k = 0; k < top_columns_.size(); ++k) y[top_columns_[k]] -= buffer[k];
    Scalar* scratch = ws.scratch[0].data();
    for (int j : top_nodes_) ForwardNode(f, values, top_slot_, j, y, static_cast<Scalar*>(nullptr), scratch);
    for (auto it = top_nodes_.rbegin(); it != top_nodes_.rend(); ++it) BackwardNode(f, values, *it, y, scratch);
#pragma omp parallel num_threads(threads)
    {
      const int tid = omp_get_thread_num(), team = omp_get_num_threads();
      for (int l = tid; l < lists; l += team) {
        const auto& list = thread_nodes_[size_t(l)];
        for (auto it = list.rbegin(); it != list.rend(); ++it)
          BackwardNode(f, values, *it, y, ws.scratch[size_t(tid)].data());
      }
    }
  }
  for (int k = 0; k < n_; ++k) x[f.perm ? f.perm[k] : k] = double(y[k]);
}

}  // namespace sedbridge::fem
