// The Merkel layer's SED evaluator against the definition, element by element.

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/rotation_extraction.h"
#include "fem/strain_energy_density.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

// A smooth, non-uniform deformation (every element strained differently) turned by `angle`.
Eigen::VectorXd Deformed(const TetMesh& mesh, double angle) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, -2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd x(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    const Eigen::Vector3d p = mesh.rest_positions_m.col(i);
    const Eigen::Vector3d u(0.03 * p.y() * std::sin(200 * p.z()), -0.05 * p.x() * p.x() / 0.01, 0.04 * p.z() * std::cos(150 * p.x()));
    x.segment<3>(3 * i) = R * (p + u);
  }
  return x;
}

// The evaluator's element SED against `expected(element, F)` on every element around a third
// of a 7x7x7 box's nodes (over 1000 elements, above the evaluator's parallel threshold, and
// not a multiple of 4), on 1 and 2 threads, for calls at the deformations `angles` (one
// evaluator per thread count: warm starts carry over between its calls). Largest error
// relative to the largest SED must stay below `tolerance`.
template <typename Expected>
void ExpectElementSeds(ElasticFormulation formulation, const std::vector<double>& angles, double tolerance,
                       Expected expected) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {7, 7, 7}, testing::Skin());
  std::vector<int> vertices;
  for (int i = 0; i < mesh.num_nodes(); i += 3) vertices.push_back(i);
  const ElasticTetForce elastic(mesh, formulation);
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    VertexSedEvaluator sed(elastic, vertices);
    ASSERT_GT(sed.elements().size(), 1000u);
    ASSERT_NE(sed.elements().size() % 4, 0u);
    Eigen::VectorXd vertex_sed;
    for (size_t call = 0; call < angles.size(); ++call) {
      const Eigen::VectorXd x = Deformed(mesh, angles[call]);
      sed.Evaluate(x, vertex_sed);
      double worst = 0, largest = 0;
      for (size_t k = 0; k < sed.elements().size(); ++k) {
        const int t = sed.elements()[k];
        const Tet& n = mesh.tets[size_t(t)];
        const TetElement& e = elastic.elements()[size_t(t)];
        const Eigen::Matrix3d F = DeformationGradient(e, x.segment<3>(3 * n[0]), x.segment<3>(3 * n[1]),
                                                      x.segment<3>(3 * n[2]), x.segment<3>(3 * n[3]));
        const double want = expected(e, F);
        worst = std::max(worst, std::abs(sed.element_sed_Pa()[Eigen::Index(k)] - want));
        largest = std::max(largest, std::abs(want));
      }
      EXPECT_GT(largest, 10.0);
      EXPECT_LT(worst, tolerance * largest) << threads << " threads, call " << call;
      EXPECT_TRUE(vertex_sed.allFinite());
      EXPECT_GT(vertex_sed.maxCoeff(), 0.0);
    }
  }
  omp_set_num_threads(1);
}

// Corotational element SED = sigma:eps/2 at F's polar rotation, through the warm-started
// path (the first call from the identity, later ones one polar step each, four elements at
// a time).
TEST(VertexSedEvaluator, CorotationalSedIsTheElementSedAtThePolarRotation) {
  ExpectElementSeds(ElasticFormulation::kCorotational, {0.7, 0.7 + 5e-5, 0.7 + 1e-4, 0.7 + 1.5e-4}, 1e-9,
                    [](const TetElement& e, const Eigen::Matrix3d& F) { return ElementSed(e, F, PolarRotationSvd(F)); });
}

// The linear path (four elements at a time, the remainder by ElementSed) is ElementSed of
// the strain sym(F) - I.
TEST(VertexSedEvaluator, LinearSedIsTheElementSedOfTheSmallStrain) {
  ExpectElementSeds(ElasticFormulation::kLinear, {0.3, 0.5}, 1e-12, [](const TetElement& e, const Eigen::Matrix3d& F) {
    return ElementSed(e, F, Eigen::Matrix3d::Identity());
  });
}

}  // namespace
}  // namespace sedbridge::fem
