// contact::ContactReport -> lcmt_contact_estimate: the taxels the fit weighed travel with it.

#include "lcm/contact_estimate_message.h"

#include <gtest/gtest.h>

#include <vector>

namespace sedbridge::lcm_io {
namespace {

TEST(ContactEstimateMessage, SaysWhichTaxelsTheFitUsed) {
  contact::ContactReport report;
  report.scan_utime = 42;
  report.estimate.contact = true;
  report.estimate.ok = true;
  report.estimate.primitive.normal_force_N = 0.5;
  using contact::TaxelUse;
  report.estimate.taxel_use = {TaxelUse::kUsed, TaxelUse::kLeftOut, TaxelUse::kSaturated, TaxelUse::kUsed};
  report.estimate.taxels_used = 3;
  const lcmt_contact_estimate m = ToLcm(report);
  EXPECT_EQ(m.shape, 1);
  ASSERT_EQ(m.num_taxels, 4);
  EXPECT_EQ(m.taxel_used, (std::vector<int8_t>{1, 0, 2, 1}));
  EXPECT_EQ(m.num_taxels_used, 3);
}

TEST(ContactEstimateMessage, AScanThatNeverReachedTheFitHasNoTaxels) {
  const lcmt_contact_estimate m = ToLcm(contact::ContactReport{});
  EXPECT_EQ(m.num_taxels, 0);
  EXPECT_TRUE(m.taxel_used.empty());
  EXPECT_EQ(m.num_taxels_used, 0);
}

TEST(ContactEstimateMessage, APunchSaysItsSidesAndAnInadequateModelIsSaid) {
  contact::ContactReport report;
  report.estimate.contact = true;
  report.estimate.ok = true;
  report.estimate.model_inadequate = true;
  report.estimate.primitive.shape = sensors::ContactShape::kPunch;
  report.estimate.primitive.half_size_mm[0] = 2.5;
  report.estimate.primitive.half_size_mm[1] = 1.0;
  const lcmt_contact_estimate m = ToLcm(report);
  EXPECT_EQ(m.shape, 5);
  EXPECT_EQ(m.length_mm, 5.0f);
  EXPECT_EQ(m.width_mm, 2.0f);
  EXPECT_EQ(m.model_inadequate, 1);
  EXPECT_EQ(ToLcm(contact::ContactReport{}).model_inadequate, 0);
}

}  // namespace
}  // namespace sedbridge::lcm_io
