// Items split by slabs (fem/slab_partition.h): every item once, and what runs at the same
// time never shares a node.
#include "fem/slab_partition.h"

#include <gtest/gtest.h>

#include <set>

#include "fem/box_mesh.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

std::set<int> NodesOf(const TetMesh& mesh, const std::vector<int>& items) {
  std::set<int> nodes;
  for (int t : items)
    for (int n : mesh.tets[size_t(t)]) nodes.insert(n);
  return nodes;
}

bool Disjoint(const std::set<int>& a, const std::set<int>& b) {
  for (int n : a)
    if (b.count(n)) return false;
  return true;
}

TEST(SlabPartition, EveryItemOnceAndConcurrentListsShareNoNode) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.004, 0.006}, {10, 4, 6}, testing::Skin());
  for (int threads : {1, 2, 3, 8}) {
    SCOPED_TRACE(threads);
    const SlabPartition p = PartitionBySlabs(mesh.rest_positions_m, threads, mesh.num_tets(),
                                             [&](int t, std::vector<int>& nodes) {
                                               for (int n : mesh.tets[size_t(t)]) nodes.push_back(n);
                                             });
    ASSERT_EQ(int(p.slab.size()), threads);
    ASSERT_EQ(int(p.boundary.size()), threads - 1);
    std::vector<int> seen(size_t(mesh.num_tets()), 0);
    auto count = [&](const std::vector<int>& items) {
      for (int t : items) ++seen[size_t(t)];
    };
    for (const auto& s : p.slab) count(s);
    for (const auto& b : p.boundary) count(b);
    count(p.rest);
    for (int t = 0; t < mesh.num_tets(); ++t) EXPECT_EQ(seen[size_t(t)], 1) << "element " << t;
    // Slabs run together, then even boundaries together, then odd ones.
    for (int a = 0; a < threads; ++a)
      for (int b = a + 1; b < threads; ++b)
        EXPECT_TRUE(Disjoint(NodesOf(mesh, p.slab[size_t(a)]), NodesOf(mesh, p.slab[size_t(b)]))) << a << " " << b;
    for (int a = 0; a < threads - 1; ++a)
      for (int b = a + 2; b < threads - 1; b += 2)
        EXPECT_TRUE(Disjoint(NodesOf(mesh, p.boundary[size_t(a)]), NodesOf(mesh, p.boundary[size_t(b)]))) << a << " " << b;
    if (threads == 2) EXPECT_GT(p.slab[0].size(), 2 * p.boundary[0].size());  // most of the work runs in parallel
  }
}

// ForEachBySlabs visits every item once, on a team of the partition's size, even when the
// team is smaller than asked for.
TEST(SlabPartition, ForEachVisitsEveryItemOnce) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.004, 0.004}, {12, 3, 3}, testing::Skin());
  const SlabPartition p = PartitionBySlabs(mesh.rest_positions_m, 4, mesh.num_tets(), [&](int t, std::vector<int>& nodes) {
    for (int n : mesh.tets[size_t(t)]) nodes.push_back(n);
  });
  for (bool dynamic_team : {false, true}) {
    omp_set_dynamic(dynamic_team);
    std::vector<int> visits(size_t(mesh.num_tets()), 0);
    ForEachBySlabs(p, [&](int t, int) {
#pragma omp atomic
      ++visits[size_t(t)];
    });
    for (int t = 0; t < mesh.num_tets(); ++t) EXPECT_EQ(visits[size_t(t)], 1) << t;
  }
  omp_set_dynamic(false);
}

}  // namespace
}  // namespace sedbridge::fem
