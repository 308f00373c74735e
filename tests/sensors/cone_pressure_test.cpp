#include "sensors/cone_pressure.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sensors/calibration_press.h"

namespace sedbridge::sensors {
namespace {

double Sum(const std::vector<SurfaceLoad>& loads) {
  double f = 0;
  for (const SurfaceLoad& l : loads) f += l.normal_N;
  return f;
}

// Sneddon's cone: F = (pi / 2) a^2 E* tan(beta) inverted, and the force within r the integral
// of p(r) = (E* tan(beta) / 2) arccosh(a / r) over the disc, integrated here numerically
// (midpoint rule on a fine radius grid, the log peak's integrable).
TEST(ConePressure, ContactRadiusAndShareAreSneddonsCone) {
  const double E_kPa = 313.4, tan_beta = kCubeCornerConeTan, F = 0.5;
  const double a = ConeContactRadius_mm(F, E_kPa, tan_beta);
  EXPECT_NEAR(0.5 * M_PI * a * a * E_kPa * 1e-3 * tan_beta, F, 1e-12);
  const double p0 = 0.5 * E_kPa * 1e-3 * tan_beta;  // N/mm^2
  const int n = 200000;
  double within = 0;
  for (int i = 0; i < n; ++i) {
    const double r = a * (i + 0.5) / n;
    within += 2 * M_PI * r * p0 * std::acosh(a / r) * (a / n);
    if (i + 1 == n / 4) {
      EXPECT_NEAR(within / F, ConeForceShareWithin(0.25 * a, a), 1e-4);
    }
    if (i + 1 == n / 2) {
      EXPECT_NEAR(within / F, ConeForceShareWithin(0.5 * a, a), 1e-4);
    }
  }
  EXPECT_NEAR(within, F, 1e-4 * F);
  EXPECT_EQ(ConeForceShareWithin(a, a), 1.0);
  EXPECT_EQ(ConeForceShareWithin(0, a), 0.0);
  // A cube corner's faces stand at acos(1 / sqrt(3)) to the pad; the cone of its section area
  // is blunter (tan 1.10 against the faces' sqrt(2)) and sharper than its edges' (1 / sqrt(2)).
  EXPECT_NEAR(1 / (kCubeCornerConeTan * kCubeCornerConeTan), 3 * std::sqrt(3.0) / (2 * M_PI), 1e-6);
}

// The splat on a fine grid (0.01 mm): every newton on the grid, centred on the tip, and the
// rings' shares the law's (within the bilinear spread of a cell).
TEST(ConePressure, TheSplatCarriesTheForceAsTheLaw) {
  const double a = 0.8, F = 0.3, h = 0.01;
  const int n = 2 * int(std::ceil((a + 2 * h) / h)) + 1;
  const Eigen::Vector2d origin(-h * (n / 2), -h * (n / 2));
  std::vector<SurfaceLoad> loads;
  SplatCone(0.0, 0.0, a, F, origin, h, n, &loads);
  EXPECT_NEAR(Sum(loads), F, 1e-12);
  double mx = 0, my = 0, within_half = 0;
  for (const SurfaceLoad& l : loads) {
    const Eigen::Vector2d c = origin + h * Eigen::Vector2d(l.cell % n, l.cell / n);
    mx += l.normal_N * c.x(), my += l.normal_N * c.y();
    if (c.norm() < 0.5 * a) within_half += l.normal_N;
  }
  EXPECT_NEAR(mx / F, 0, 1e-9);
  EXPECT_NEAR(my / F, 0, 1e-9);
  // The rings deposit at their mid-radii: the half radius is a ring boundary (6 of 12).
  EXPECT_NEAR(within_half / F, ConeForceShareWithin(0.5 * a, a), 0.01);
  // More than a Hertz dome of the same radius holds there (1 - (3/4)^1.5 = 0.35): the tip's peak.
  EXPECT_GT(within_half / F, 1 - std::pow(0.75, 1.5));
}

// The corner primitive in the forward model: the cone of the pad's contact modulus at its
// force, its loads summing to the force, its readings moving smoothly with its tip.
TEST(ConePressure, TheCornerPrimitiveIsTheConeOnTheModelsGrid) {
  const SensorProfile p = LoadNamedSensorProfile("uskin_4x4");
  const TactileForwardModel m(p, p.forward_model);
  ContactPrimitive c;
  c.shape = ContactShape::kCorner;
  c.x_mm = 0.7, c.y_mm = -0.4, c.radius_mm = 0, c.normal_force_N = 0.4;
  std::vector<SurfaceLoad> loads;
  m.Patch(c, &loads);
  EXPECT_NEAR(Sum(loads), 0.4, 1e-12);
  Eigen::VectorXd r0, r1;
  m.Predict(c, &r0);
  EXPECT_GT(r0.maxCoeff(), 0);
  c.x_mm += 0.01;
  m.Predict(c, &r1);
  EXPECT_LT((r1 - r0).norm(), 0.05 * r0.norm());
  EXPECT_GT(m.PatchCellsEstimate(c), 0);
}

}  // namespace
}  // namespace sedbridge::sensors
