#include "common/geometry/trajectory.h"

#include <gtest/gtest.h>

namespace sedbridge::geometry {
namespace {

TEST(Trajectory, LinearKeyframesAndHold) {
  PoseKeyframe a, b;
  b.t_s = 1.0;
  b.position_m = {0, 0, -0.002};
  Trajectory t({a, b});
  EXPECT_NEAR(t.Pose(0.5).translation().z(), -0.001, 1e-15);
  EXPECT_NEAR(t.Pose(2.0).translation().z(), -0.002, 1e-15);
  EXPECT_NEAR(t.Pose(-1.0).translation().z(), 0.0, 1e-15);
  EXPECT_NEAR(t.PointVelocity({0, 0, 0}, 0.5).z(), -0.002, 1e-9);
}

TEST(Trajectory, VibrationVelocity) {
  Vibration v{0.0001, 300, {0, 0, 1}};
  Trajectory t({PoseKeyframe{}}, v);
  const double w = 2 * M_PI * 300;
  EXPECT_NEAR(t.PointVelocity({0, 0, 0}, 0.0).z(), 0.0001 * w, 1e-6);
}

TEST(Trajectory, RejectsNonIncreasingTimes) {
  PoseKeyframe a, b;
  EXPECT_THROW(Trajectory({a, b}), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::geometry
