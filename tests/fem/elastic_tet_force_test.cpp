// The elastic term's parallel assembly (by slabs, fem/slab_partition.h) against one thread.
#include "fem/elastic_tet_force.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "fem/box_mesh.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

// Corotational, damped, with K v and inverted elements: 1, 2, 3 and 7 threads give the
// one-thread matrix, force and K v to 1e-12 and the same count of inverted elements.
TEST(ElasticTetForce, ThreadsGiveTheOneThreadAssembly) {
  const TetMesh mesh = MakeBoxMesh({0.006, 0.005, 0.008}, {6, 5, 8}, testing::Skin(1e5, 0.45));
  ElasticTetForce elastic(mesh, ElasticFormulation::kCorotational, 0.01);
  std::vector<std::pair<int, int>> pairs;
  elastic.AppendCoupledNodes(pairs);
  SystemMatrix matrix;
  matrix.Build(mesh.num_nodes(), pairs);
  elastic.BindMatrix(matrix);
  Eigen::VectorXd x(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  x += 2e-4 * Eigen::VectorXd::Random(x.size());
  // Invert element 0 (and its neighbours on that node): its first node through the opposite face.
  const Tet& t0 = mesh.tets[0];
  const Eigen::Vector3d centroid = (x.segment<3>(3 * t0[1]) + x.segment<3>(3 * t0[2]) + x.segment<3>(3 * t0[3])) / 3;
  x.segment<3>(3 * t0[0]) = centroid + 0.5 * (centroid - x.segment<3>(3 * t0[0]));
  const Eigen::VectorXd v = 1e-2 * Eigen::VectorXd::Random(x.size());
  int reference_inverted = 0;
  testing::ExpectThreadsGiveTheOneThreadAssembly(matrix, int(x.size()), [&](Eigen::VectorXd& f, Eigen::VectorXd& kv, int threads) {
    JacobianSink sink{&matrix, 1e-6, 1e-3, &v, &kv};
    elastic.AddForce({x, v, 0.0, true}, f, &sink);
    if (threads == 1) reference_inverted = elastic.inverted_elements();
    EXPECT_GE(reference_inverted, 1);
    EXPECT_EQ(elastic.inverted_elements(), reference_inverted) << threads << " threads";
  });
}

}  // namespace
}  // namespace sedbridge::fem
