#include "fem/surface_traction_force.h"

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem/mesh_topology.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

TEST(SurfaceTraction, ConsistentLoadIntegratesLinearTractionExactly) {
  const double a = 0.01, h = 0.004;
  const TetMesh mesh = MakeBoxMesh({a, a, h}, {5, 5, 2}, testing::Skin());
  std::vector<Triangle> top;
  for (const Triangle& f : BoundaryFaces(mesh.tets, mesh.rest_positions_m)) {
    bool on_top = true;
    for (int v : f) on_top = on_top && std::abs(mesh.rest_positions_m(2, v) - h) < 1e-12;
    if (on_top) top.push_back(f);
  }
  SurfaceTractionForce traction(mesh.rest_positions_m, top);
  // Pressure p(x) = p0 + g x and shear s(y) = s0 * y / a: integrals and first moment exact.
  const double p0 = 1000, g = 5e4, s0 = 300;
  Eigen::Matrix3Xd t(3, Eigen::Index(traction.nodes().size()));
  for (Eigen::Index k = 0; k < t.cols(); ++k) {
    const Eigen::Vector3d p = traction.node_rest_positions_m().col(k);
    t.col(k) = Eigen::Vector3d(s0 * p.y() / a, 0, -(p0 + g * p.x()));
  }
  traction.SetNodalTraction(t);
  const Eigen::Vector3d total = traction.TotalForce();
  EXPECT_NEAR(total.z(), -(p0 * a * a + g * a * a * a / 2), 1e-12);
  EXPECT_NEAR(total.x(), s0 * a * a / 2, 1e-12);
  const Eigen::Matrix3Xd nodal = traction.NodalForces();
  double moment_y = 0;  // sum x * f_z = -integral x p(x) dA
  for (Eigen::Index k = 0; k < nodal.cols(); ++k) moment_y += traction.node_rest_positions_m()(0, k) * nodal(2, k);
  EXPECT_NEAR(moment_y, -(p0 * a * a * a / 2 + g * a * a * a * a / 3), 1e-14);
}

TEST(SurfaceTraction, RejectsNonFiniteTractionAndKeepsThePrevious) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {1, 1, 1}, testing::Skin());
  SurfaceTractionForce traction(mesh.rest_positions_m, BoundaryFaces(mesh.tets, mesh.rest_positions_m));
  Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Constant(3, Eigen::Index(traction.nodes().size()), 10.0);
  traction.SetNodalTraction(t);
  const Eigen::Vector3d before = traction.TotalForce();
  t(1, 2) = std::nan("");
  EXPECT_THROW(traction.SetNodalTraction(t), std::invalid_argument);
  EXPECT_EQ(traction.TotalForce(), before);
  EXPECT_THROW(traction.SetNodalTraction(Eigen::Matrix3Xd::Zero(3, 2)), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::fem
