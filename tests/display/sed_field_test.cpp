// The SED field handed from the FE side to the display: what CheckSedField counts and what
// MaxFiniteSed reads from untrusted contents.

#include "display/sed_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sedbridge::display {
namespace {

SedField ThreeVertices() {
  SedField f;
  f.x_mm = {0, 1, 2};
  f.y_mm = {0, 0, 1};
  f.z_mm = {0, 0, 0};
  f.sed_Pa = {10, 20, 5};
  return f;
}

TEST(SedField, HealthyFieldHasNothingToReport) {
  const SedFieldCheck c = CheckSedField(ThreeVertices());
  EXPECT_TRUE(c.consistent);
  EXPECT_TRUE(c.healthy());
  EXPECT_EQ(c.non_finite_sed + c.negative_sed + c.non_finite_position, 0u);
}

TEST(SedField, DepthMayBeUnknown) {
  SedField f = ThreeVertices();
  f.z_mm.clear();
  EXPECT_TRUE(CheckSedField(f).healthy());
  f.z_mm = {0, 0};  // present but short: inconsistent
  EXPECT_FALSE(CheckSedField(f).consistent);
}

TEST(SedField, CountsNonFiniteAndNegativeSedAndBadPositions) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  SedField f = ThreeVertices();
  f.sed_Pa = {nan, -1e-9, inf};
  f.y_mm[1] = inf;
  f.z_mm[2] = nan;
  const SedFieldCheck c = CheckSedField(f);
  EXPECT_TRUE(c.consistent);
  EXPECT_EQ(c.non_finite_sed, 2u);
  EXPECT_EQ(c.negative_sed, 1u);
  EXPECT_EQ(c.non_finite_position, 2u);
  EXPECT_FALSE(c.healthy());
}

TEST(SedField, MismatchedLengthsAreInconsistentAndPositionsAreNotRead) {
  SedField f = ThreeVertices();
  f.x_mm.pop_back();
  f.y_mm[0] = std::nan("");
  const SedFieldCheck c = CheckSedField(f);
  EXPECT_FALSE(c.consistent);
  EXPECT_FALSE(c.healthy());
  EXPECT_EQ(c.non_finite_position, 0u);  // not counted: the field is unusable as a whole
}

TEST(SedField, MaxFiniteSedSkipsNanAndInfAndIsZeroWhenEmpty) {
  SedField f = ThreeVertices();
  EXPECT_EQ(MaxFiniteSed(f), 20.0);
  f.sed_Pa = {std::nan(""), std::numeric_limits<double>::infinity(), 7.5, -3};
  EXPECT_EQ(MaxFiniteSed(f), 7.5);
  f.sed_Pa = {-3, -4};
  EXPECT_EQ(MaxFiniteSed(f), 0.0);  // never below zero
  EXPECT_EQ(MaxFiniteSed(SedField{}), 0.0);
}

}  // namespace
}  // namespace sedbridge::display
