#pragma once
// Items that write the matrix rows (and force rows) of their nodes — elements, nodal
// patches — split for a team of threads so that no two threads ever write the same row:
// the nodes in slabs of equal count along the mesh's longest axis, an item in its slab's
// list when all its nodes lie in one slab, in boundary list k when it spans slabs k and
// k + 1 (even boundaries are disjoint from each other, odd ones too), the rest (items
// spanning more, when slabs are thin) in one serial list. The threads then write straight
// into the shared matrix: no per-thread copy of it to clear and sum every assembly.

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <functional>
#include <vector>

namespace sedbridge::fem {

struct SlabPartition {
  int threads = 0;
  std::vector<std::vector<int>> slab;      ///< per slab (thread): items within it
  std::vector<std::vector<int>> boundary;  ///< per boundary k: items spanning slabs k, k + 1
  std::vector<int> rest;                   ///< items spanning three or more slabs
};

/// @param positions_m  3 x #nodes (rest positions)
/// @param items        number of items
/// @param nodes_of     appends item i's nodes to the vector (duplicates allowed)
SlabPartition PartitionBySlabs(const Eigen::Matrix3Xd& positions_m, int threads, int items,
                               const std::function<void(int item, std::vector<int>& nodes)>& nodes_of);

/// Runs body(item, thread) for every item of `p`: the slabs concurrently (a team of
/// p.threads), then the even boundaries, then the odd ones, then the rest on one thread;
/// two barriers with two threads (after the slabs, after the boundary). A team smaller than
/// asked for (OMP_DYNAMIC) runs the missing slabs on one thread after the slabs.
template <typename Body>
void ForEachBySlabs(const SlabPartition& p, Body&& body) {
  const int slabs = int(p.slab.size()), boundaries = int(p.boundary.size());
#pragma omp parallel num_threads(p.threads)
  {
    const int tid = omp_get_thread_num(), team = omp_get_num_threads();
    if (tid < slabs)
      for (int i : p.slab[size_t(tid)]) body(i, tid);
#pragma omp barrier
    if (team < slabs) {  // the same branch on every thread of the team
#pragma omp single
      for (int k = team; k < slabs; ++k)
        for (int i : p.slab[size_t(k)]) body(i, tid);
    }
    for (int parity = 0; parity < std::min(2, boundaries); ++parity) {
#pragma omp for schedule(static, 1)
      for (int k = parity; k < boundaries; k += 2)
        for (int i : p.boundary[size_t(k)]) body(i, tid);
    }
#pragma omp single nowait
    for (int i : p.rest) body(i, tid);
  }
}

}  // namespace sedbridge::fem
