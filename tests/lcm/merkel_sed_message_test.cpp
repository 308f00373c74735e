#include "lcm/merkel_sed_message.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
namespace {

TEST(LcmConversions, SedFieldRoundTripAndOverflowToInf) {
  SedField f;
  f.utime = 3;
  f.source_scan_utime = 2;
  f.model_id = "B";
  f.x_mm = {1.5};
  f.y_mm = {-2};
  f.z_mm = {-1.5};
  f.sed_Pa = {1e300};
  const SedField back = FromLcm(ToLcm(f));
  EXPECT_EQ(back.model_id, "B");
  EXPECT_EQ(back.source_scan_utime, 2);
  EXPECT_DOUBLE_EQ(back.z_mm[0], -1.5);
  EXPECT_TRUE(std::isinf(back.sed_Pa[0]));
}

}  // namespace
}  // namespace sedbridge::lcm_io
