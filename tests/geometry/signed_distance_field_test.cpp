#include "common/geometry/signed_distance_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <random>

namespace sedbridge::geometry {
namespace {

// The normal must be the gradient of the distance: check by finite differences.
void ExpectNormalIsGradient(const SignedDistanceField& f, const Eigen::Vector3d& p, double tol) {
  const double h = 1e-7;
  Eigen::Vector3d g;
  for (int a = 0; a < 3; ++a) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[a] = h;
    g[a] = (f.Evaluate(p + e).distance_m - f.Evaluate(p - e).distance_m) / (2 * h);
  }
  EXPECT_NEAR((g - f.Evaluate(p).normal).norm(), 0.0, tol) << f.Describe() << " at " << p.transpose();
}

TEST(SignedDistanceField, SphereDistanceAndNormal) {
  SphereSdf s(0.005);
  EXPECT_NEAR(s.Evaluate({0, 0, 0.007}).distance_m, 0.002, 1e-15);
  EXPECT_NEAR(s.Evaluate({0, 0, 0.001}).distance_m, -0.004, 1e-15);
  EXPECT_TRUE(s.Evaluate({0, 0, 0}).normal.allFinite());
  ExpectNormalIsGradient(s, {0.001, 0.002, 0.006}, 1e-6);
}

// The shapes that say so are 1-Lipschitz (contact solves skip far points on that promise).
TEST(SignedDistanceField, LipschitzShapesKeepTheirPromise) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.012, 0.012);
  const SphereSdf sphere(0.005);
  const CylinderSdf rod(0.001, 0.004), infinite(0.0006, 0.0);
  const PlaneSdf plane;
  for (const SignedDistanceField* f : std::initializer_list<const SignedDistanceField*>{&sphere, &rod, &infinite, &plane}) {
    EXPECT_TRUE(f->lipschitz()) << f->Describe();
    for (int k = 0; k < 20000; ++k) {
      const Eigen::Vector3d p(u(rng), u(rng), u(rng)), q = p + 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      EXPECT_LE(std::abs(f->Evaluate(p).distance_m - f->Evaluate(q).distance_m), (p - q).norm() * (1 + 1e-12) + 1e-18)
          << f->Describe() << " at " << p.transpose();
    }
  }
  EXPECT_FALSE(BoxSdf(Eigen::Vector3d(0.001, 0.002, 0.003), 0.0).lipschitz());  // not promised
}

TEST(SignedDistanceField, PlaneIsHalfSpace) {
  PlaneSdf p;
  EXPECT_DOUBLE_EQ(p.Evaluate({1, 2, -0.003}).distance_m, -0.003);
  EXPECT_EQ(p.Evaluate({1, 2, 3}).normal, Eigen::Vector3d::UnitZ());
}

TEST(SignedDistanceField, CylinderAndCaps) {
  CylinderSdf inf(0.001, 0);
  EXPECT_NEAR(inf.Evaluate({5, 0, 0.003}).distance_m, 0.002, 1e-15);
  CylinderSdf fin(0.001, 0.01);
  EXPECT_NEAR(fin.Evaluate({0.012, 0, 0}).distance_m, 0.002, 1e-15);
  EXPECT_NEAR(fin.Evaluate({0.013, 0, 0.005}).distance_m, 0.005, 1e-12);  // 3-4-5 corner
  ExpectNormalIsGradient(fin, {0.004, 0.0005, 0.002}, 1e-6);
}

// A suction display's surface: the plate (z < 0) less two holes of radius 0.5 mm.
TEST(SignedDistanceField, PlateWithHolesIsThePlaneLessItsHoles) {
  const double r = 0.0005;
  const PlateWithHolesSdf plate({Eigen::Vector2d(0, 0), Eigen::Vector2d(0.002, 0)}, r);
  EXPECT_TRUE(plate.lipschitz());
  // Clear of the holes it is the plane, above and inside.
  EXPECT_DOUBLE_EQ(plate.Evaluate({0.001, 0.0015, 0.0003}).distance_m, 0.0003);
  EXPECT_DOUBLE_EQ(plate.Evaluate({0.001, 0.0015, -0.0002}).distance_m, -0.0002);
  EXPECT_EQ(plate.Evaluate({0.001, 0.0015, -0.0002}).normal, Eigen::Vector3d::UnitZ());
  // In a hole below the surface: the distance to its wall, the normal toward its axis.
  const SdfSample in_hole = plate.Evaluate({0.0021, 0, -0.003});
  EXPECT_NEAR(in_hole.distance_m, r - 0.0001, 1e-15);
  EXPECT_NEAR((in_hole.normal - Eigen::Vector3d(-1, 0, 0)).norm(), 0.0, 1e-12);
  // Inside the solid the nearer face wins: the wall 0.1 mm away, not the surface 0.3 mm up.
  const SdfSample by_wall = plate.Evaluate({0.0, 0.0006, -0.0003});
  EXPECT_NEAR(by_wall.distance_m, -0.0001, 1e-15);
  EXPECT_NEAR((by_wall.normal - Eigen::Vector3d(0, -1, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(plate.Evaluate({0.0, 0.0009, -0.0002}).distance_m, -0.0002, 1e-15);
  // Above a hole's centre the rim is nearest (sqrt(z^2 + r^2)): the distance is a lower bound.
  const double above = plate.Evaluate({0, 0, 0.0002}).distance_m;
  EXPECT_GT(above, 0.0);
  EXPECT_LE(above, std::hypot(0.0002, r));
  ExpectNormalIsGradient(plate, {0.0019, 0.0002, -0.001}, 1e-6);
  ExpectNormalIsGradient(plate, {0.0011, 0.0003, -0.0001}, 1e-6);
  // 1-Lipschitz, as it says.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.003, 0.003);
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng)), q = p + 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    EXPECT_LE(std::abs(plate.Evaluate(p).distance_m - plate.Evaluate(q).distance_m), (p - q).norm() * (1 + 1e-12) + 1e-18);
  }
}

TEST(SignedDistanceField, BoxInsideOutsideRounded) {
  BoxSdf b({0.01, 0.01, 0.01}, 0.0);
  EXPECT_NEAR(b.Evaluate({0, 0, 0.012}).distance_m, 0.002, 1e-15);
  EXPECT_NEAR(b.Evaluate({0, 0, 0.009}).distance_m, -0.001, 1e-15);
  EXPECT_EQ(b.Evaluate({0, 0, 0.009}).normal, Eigen::Vector3d::UnitZ());
  BoxSdf r({0.01, 0.01, 0.01}, 0.002);
  EXPECT_NEAR(r.Evaluate({0, 0, 0.012}).distance_m, 0.002, 1e-15);
  ExpectNormalIsGradient(r, {0.0105, 0.0, 0.0103}, 1e-6);
}

TEST(SignedDistanceField, GratingRidgesAndGrooves) {
  GratingSdf g(0.002, 0.001, 0.0005);
  EXPECT_NEAR(g.Evaluate({0, 0, 0.0001}).distance_m, 0.0001, 1e-12);        // above a ridge
  EXPECT_NEAR(g.Evaluate({0.001, 0, 0.0001}).distance_m, 0.0001 + 0.0, 1e-3);
  EXPECT_NEAR(g.Evaluate({0.001, 0, -0.0004}).distance_m, 0.0001, 1e-12);   // in a groove
  EXPECT_NEAR(g.Evaluate({0.004, 0, 0.0001}).distance_m, 0.0001, 1e-12);    // periodic
  EXPECT_LT(g.Evaluate({-0.004, 0, -0.0001}).distance_m, 0.0);
}

TEST(SignedDistanceField, GridMatchesSampledSphere) {
  SphereSdf s(0.004);
  GridSdf g = GridSdf::Sample(s, {41, 41, 41}, {-0.01, -0.01, -0.01}, 0.0005);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.009, 0.009);
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d p(u(rng), u(rng), u(rng));
    if (p.norm() < 0.001) continue;
    EXPECT_NEAR(g.Evaluate(p).distance_m, s.Evaluate(p).distance_m, 5e-5);
    EXPECT_GT(g.Evaluate(p).normal.dot(s.Evaluate(p).normal), 0.98);
  }
  // Outside the grid the distance keeps growing.
  EXPECT_GT(g.Evaluate({0, 0, 0.02}).distance_m, 0.015);
}

}  // namespace
}  // namespace sedbridge::geometry
