#include "fidelity/truth_resolution.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "sensors/sensor_profile.h"

namespace sedbridge::fidelity {
namespace {

TEST(TruthResolution, ShiftGridCoversTheCellFromTheOrigin) {
  const std::vector<Eigen::Vector2d> shifts = ShiftGrid(0.25, 3);
  ASSERT_EQ(shifts.size(), 9u);
  EXPECT_EQ(shifts.front(), Eigen::Vector2d(0, 0));
  EXPECT_EQ(shifts.back(), Eigen::Vector2d(0.5, 0.5));
  EXPECT_EQ(shifts[1], Eigen::Vector2d(0.25, 0));
  EXPECT_EQ(shifts[3], Eigen::Vector2d(0, 0.25));
}

TEST(TruthResolution, SpreadLeavesOutPressesThatDidNotReachTheForce) {
  std::vector<TruthShiftRow> rows(4);
  const double peak[4] = {100, 50, 80, 1e6}, sum[4] = {1000, 800, 900, 1};
  for (int i = 0; i < 4; ++i) rows[i].reached = i < 3, rows[i].peak_sed_Pa = peak[i], rows[i].sum_sed_Pa = sum[i];
  const TruthSpread s = SpreadOf(rows);
  EXPECT_EQ(s.shifts, 4);
  EXPECT_EQ(s.reached, 3);
  EXPECT_DOUBLE_EQ(s.peak_median_Pa, 80);
  EXPECT_DOUBLE_EQ(s.peak_min_over_max, 0.5);
  EXPECT_DOUBLE_EQ(s.sum_min_over_max, 0.8);
  EXPECT_EQ(SpreadOf({}).reached, 0);
}

// The Cramér–Rao bound is linear in the noise, and a harder press tells the radius better.
TEST(TruthResolution, RadiusLeftOpenScalesWithTheNoiseAndShrinksWithTheForce) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  sensors::ContactPrimitive sphere;
  sphere.radius_mm = 4, sphere.x_mm = -1, sphere.y_mm = 1, sphere.normal_force_N = 0.1;
  const double light = LogRadiusSigmaPerScan(profile, sphere, 2.0);
  EXPECT_GT(light, 0);
  EXPECT_NEAR(LogRadiusSigmaPerScan(profile, sphere, 4.0), 2 * light, 1e-6 * light);
  sphere.normal_force_N = 1.0;
  EXPECT_LT(LogRadiusSigmaPerScan(profile, sphere, 2.0), 0.5 * light);
  sensors::ContactPrimitive flat;
  flat.shape = sensors::ContactShape::kFlat;
  EXPECT_THROW(LogRadiusSigmaPerScan(profile, flat, 2.0), std::invalid_argument);
}

// Model B's skin carries contact points about 1 mm apart: a 4 mm sphere's patch at 0.1 N
// spans a few, and where it lands between them moves its peak SED far more than at 1 N
// (measured: min / max 0.51 against 0.84 with face contact; `sedbridge fidelity
// --truth-resolution B`).
TEST(TruthResolution, ALightTouchOnModelBIsLessResolvedThanAFirmOne) {
  sensors::ContactPrimitive sphere;
  sphere.radius_mm = 4, sphere.x_mm = -1, sphere.y_mm = 1;
  const std::vector<Eigen::Vector2d> shifts = ShiftGrid(0.25, 3);
  ShiftedTruthLeader leader("B", true, "");
  const TruthSpread light = SpreadOf(leader.PressAtShifts("sphere R4", sphere, 0.1, shifts));
  const TruthSpread firm = SpreadOf(leader.PressAtShifts("sphere R4", sphere, 1.0, shifts));
  ASSERT_EQ(light.reached, 9);
  ASSERT_EQ(firm.reached, 9);
  EXPECT_LT(light.peak_min_over_max, firm.peak_min_over_max - 0.15);
  EXPECT_GT(firm.peak_min_over_max, 0.75);
}

}  // namespace
}  // namespace sedbridge::fidelity
