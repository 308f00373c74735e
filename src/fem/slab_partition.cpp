#include "fem/slab_partition.h"

#include <algorithm>
#include <numeric>

namespace sedbridge::fem {

SlabPartition PartitionBySlabs(const Eigen::Matrix3Xd& x, int threads, int items,
                               const std::function<void(int, std::vector<int>&)>& nodes_of) {
  SlabPartition p;
  p.threads = std::max(1, threads);
  const int nodes = int(x.cols());
  Eigen::Index axis = 0;
  if (nodes > 0) (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).maxCoeff(&axis);
  std::vector<int> order(static_cast<size_t>(nodes)), slab(static_cast<size_t>(nodes));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return x(axis, a) < x(axis, b); });
  for (int r = 0; r < nodes; ++r) slab[size_t(order[size_t(r)])] = int(int64_t(r) * p.threads / nodes);
  p.slab.assign(size_t(p.threads), {});
  p.boundary.assign(size_t(p.threads - 1), {});
  std::vector<int> item_nodes;
  for (int i = 0; i < items; ++i) {
    item_nodes.clear();
    nodes_of(i, item_nodes);
    int lo = p.threads, hi = -1;
    for (int n : item_nodes) lo = std::min(lo, slab[size_t(n)]), hi = std::max(hi, slab[size_t(n)]);
    if (hi < 0) continue;  // no nodes: nothing to write
    if (lo == hi) p.slab[size_t(lo)].push_back(i);
    else if (hi == lo + 1) p.boundary[size_t(lo)].push_back(i);
    else p.rest.push_back(i);
  }
  return p;
}

}  // namespace sedbridge::fem
