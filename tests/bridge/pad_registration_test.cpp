#include "bridge/pad_registration.h"

#include <gtest/gtest.h>

#include "bridge/taxel_values.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {
namespace {

std::vector<sensors::TaxelPosition> Grid() {  // 2x2 grid centred at (10, 20)
  return {{8, 18}, {12, 18}, {8, 22}, {12, 22}};
}

TEST(PadRegistration, DefaultCentresTheSensorOnThePadOrigin) {
  PadRegistration r(Grid());
  EXPECT_TRUE(r.ToPad({10, 20}).isZero(1e-12));
  EXPECT_TRUE(r.ToPad({12, 22}).isApprox(Eigen::Vector2d(2, 2)));
}

TEST(PadRegistration, OffsetRotationScaleAndInverse) {
  PadRegistrationParams p;
  p.offset_mm = {1, -2};
  p.rotation_deg = 90;
  p.scale = 2;
  PadRegistration r(Grid(), p);
  // (12, 20) is +2 mm along sensor x from the centre: rotated to +y, scaled to 4 mm.
  EXPECT_TRUE(r.ToPad({12, 20}).isApprox(Eigen::Vector2d(1, 2), 1e-12));
  for (const Eigen::Vector2d& q : {Eigen::Vector2d(3, 4), Eigen::Vector2d(-7, 0.5)})
    EXPECT_TRUE(r.ToSensor(r.ToPad(q)).isApprox(q, 1e-12));
  // Shear rotates with the sensor, keeps its magnitude.
  EXPECT_TRUE(r.RotateToPad({1, 0}).isApprox(Eigen::Vector2d(0, 1), 1e-12));
}

TEST(PadRegistration, RejectsBadScale) {
  PadRegistrationParams p;
  p.scale = 0;
  EXPECT_THROW(PadRegistration(Grid(), p), std::invalid_argument);
  p.scale = std::nan("");
  EXPECT_THROW(PadRegistration(Grid(), p), std::invalid_argument);
}

TEST(PadRegistration, SmallestSpacing) { EXPECT_DOUBLE_EQ(SmallestTaxelSpacing_mm(Grid()), 4.0); }

}  // namespace
}  // namespace sedbridge::bridge
