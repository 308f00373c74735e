#include "lcm/tactile_scan_message.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sedbridge::lcm_io {
namespace {

TEST(TactileScanMessage, OneNormalRawValuePerTaxelPressureInKpa) {
  sensors::Scan s;
  s.utime = 5;
  s.sequence = 3;
  s.sensor_counter = 41;
  s.num_taxels = 2;
  s.num_axes = 3;
  s.raw_counts = {1, 2, 30, 4, 5, 60};  // x, y, z per taxel
  s.pressure_Pa = {1500.0, 1e60};
  s.valid = {1, 0};
  const lcmt_tactile_scan m = ToLcm(s, "uskin_4x4");
  EXPECT_EQ(m.utime, 5);
  EXPECT_EQ(m.sequence, 41);  // the sensor's own counter wins
  EXPECT_EQ(m.sensor_id, "uskin_4x4");
  ASSERT_EQ(m.num_taxels, 2);
  EXPECT_EQ(m.raw_counts, (std::vector<int32_t>{30, 60}));
  EXPECT_FLOAT_EQ(m.pressure_kPa[0], 1.5f);
  EXPECT_TRUE(std::isinf(m.pressure_kPa[1]));
  EXPECT_EQ(m.valid, (std::vector<int8_t>{1, 0}));
  EXPECT_EQ(m.num_shear, 0);  // no shear in the scan: none in the message
  s.sensor_counter = -1;
  EXPECT_EQ(ToLcm(s, "x").sequence, 3);
}

TEST(TactileScanMessage, AThreeAxisScansShearPerTaxelInKpa) {
  sensors::Scan s;
  s.num_taxels = 2;
  s.num_axes = 3;
  s.raw_counts = {1, 2, 30, 4, 5, 60};
  s.pressure_Pa = {1500.0, 0.0};
  s.shear_x_Pa = {250.0, -500.0};
  s.shear_y_Pa = {0.0, 125.0};
  s.valid = {1, 1};
  const lcmt_tactile_scan m = ToLcm(s, "uskin_4x4");
  ASSERT_EQ(m.num_shear, 2);
  EXPECT_EQ(m.shear_x_kPa, (std::vector<float>{0.25f, -0.5f}));
  EXPECT_EQ(m.shear_y_kPa, (std::vector<float>{0.0f, 0.125f}));
}

}  // namespace
}  // namespace sedbridge::lcm_io
