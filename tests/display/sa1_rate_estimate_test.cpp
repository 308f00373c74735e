#include "display/sa1_rate_estimate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sedbridge::display {
namespace {

TEST(Sa1RateEstimate, MonotonicSaturatingHalfRateAtParameter) {
  Sa1RateParams p;
  EXPECT_DOUBLE_EQ(EstimateSa1Rate(0, p), 0);
  EXPECT_DOUBLE_EQ(EstimateSa1Rate(p.threshold_Pa, p), 0);
  EXPECT_NEAR(EstimateSa1Rate(p.threshold_Pa + p.half_rate_sed_Pa, p), p.max_rate_Hz / 2, 1e-9);
  double prev = 0;
  for (double s = 20; s < 1e7; s *= 1.7) {
    const double r = EstimateSa1Rate(s, p);
    EXPECT_GT(r, prev);
    EXPECT_LT(r, p.max_rate_Hz);
    prev = r;
  }
  EXPECT_DOUBLE_EQ(EstimateSa1Rate(std::numeric_limits<double>::infinity(), p), p.max_rate_Hz);
  EXPECT_NEAR(EstimateSa1Rate(std::numeric_limits<double>::max(), p), p.max_rate_Hz, 1e-9);
}

TEST(Sa1RateEstimate, UntrustedInput) {
  EXPECT_TRUE(std::isnan(EstimateSa1Rate(std::nan(""))));
  EXPECT_DOUBLE_EQ(EstimateSa1Rate(-1e9), 0);
  Sa1RateParams bad;
  bad.half_rate_sed_Pa = 0;
  EXPECT_THROW(EstimateSa1Rate(1, bad), std::invalid_argument);
  EXPECT_EQ(EstimateSa1Rates({1, 2, 3}).size(), 3u);
}

}  // namespace
}  // namespace sedbridge::display
