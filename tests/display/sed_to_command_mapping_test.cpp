#include "display/sed_to_command_mapping.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sedbridge::display {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

MappingParams Params(SamplingMethod method) {
  MappingParams m;
  m.sampling = method;
  m.radius_mm = 1.0;
  m.threshold_Pa = 0;
  m.reference_Pa = 1000;
  m.gain = 10;
  m.exponent = 1;
  m.saturation = 20;
  return m;
}

// Two sites: (0,0) and (5,0).
SedToCommandMapping Mapping(MappingParams m) { return SedToCommandMapping({0, 5}, {0, 0}, m); }

SedField Field(std::vector<double> x, std::vector<double> y, std::vector<double> sed) {
  SedField f;
  f.utime = 1;
  f.x_mm = std::move(x);
  f.y_mm = std::move(y);
  f.sed_Pa = std::move(sed);
  return f;
}

TEST(SedToCommandMapping, MaxAndMeanWithinRadius) {
  const SedField f = Field({0.1, -0.5, 0.0, 3.0}, {0.0, 0.5, 0.9, 0.0}, {100, 300, 200, 9000});
  EXPECT_DOUBLE_EQ(Mapping(Params(SamplingMethod::kMaxWithinRadius)).Sample(f, 0), 300);
  EXPECT_DOUBLE_EQ(Mapping(Params(SamplingMethod::kMeanWithinRadius)).Sample(f, 0), 200);
  // nothing within 1 mm of (5, 0): no information means no stimulus.
  EXPECT_DOUBLE_EQ(Mapping(Params(SamplingMethod::kMaxWithinRadius)).Sample(f, 1), 0);
}

TEST(SedToCommandMapping, InterpolationReproducesAVertexOnTheSiteAndAverages) {
  const auto map = Mapping(Params(SamplingMethod::kInterpolate));
  EXPECT_NEAR(map.Sample(Field({0.0, 0.5}, {0.0, 0.0}, {400, 100}), 0), 400, 1e-2);
  // symmetric neighbours -> their mean
  EXPECT_DOUBLE_EQ(map.Sample(Field({-0.5, 0.5}, {0.0, 0.0}, {100, 300}), 0), 200);
  // nearer vertex weighs more (1/d^2)
  const double s = map.Sample(Field({-0.25, 0.5}, {0.0, 0.0}, {100, 300}), 0);
  EXPECT_NEAR(s, (100 * 16 + 300 * 4) / 20.0, 1e-9);
}

// Reads() names exactly the vertices Sample() uses: dropping every other vertex changes no
// sample, and dropping one it reads does.
TEST(SedToCommandMapping, ReadsExactlyTheVerticesItSamples) {
  MappingParams m = Params(SamplingMethod::kMeanWithinRadius);
  m.z_min_mm = -2;
  m.z_max_mm = 0.5;
  const SedToCommandMapping map = Mapping(m);
  SedField f = Field({0.1, -0.5, 0.0, 3.0, 5.9, 5.0, 0.2}, {0.0, 0.5, 0.9, 0.0, 0.0, 0.2, 0.1},
                     {100, 300, 200, 9000, 50, 70, 4000});
  f.z_mm = {-1.0, -0.5, 0.0, -1.0, -1.0, -1.9, -3.0};  // the last under the window (the nail side)
  const std::vector<bool> expected = {true, true, true, false, true, true, false};
  SedField kept;
  kept.utime = f.utime;
  for (size_t v = 0; v < f.size(); ++v) {
    EXPECT_EQ(map.Reads(f.x_mm[v], f.y_mm[v], f.z_mm[v]), expected[v]) << v;
    if (!map.Reads(f.x_mm[v], f.y_mm[v], f.z_mm[v])) continue;
    kept.x_mm.push_back(f.x_mm[v]);
    kept.y_mm.push_back(f.y_mm[v]);
    kept.z_mm.push_back(f.z_mm[v]);
    kept.sed_Pa.push_back(f.sed_Pa[v]);
  }
  for (SamplingMethod method :
       {SamplingMethod::kMaxWithinRadius, SamplingMethod::kMeanWithinRadius, SamplingMethod::kInterpolate}) {
    MappingParams p = m;
    p.sampling = method;
    const SedToCommandMapping mm = Mapping(p);
    for (size_t site = 0; site < mm.size(); ++site)
      EXPECT_EQ(mm.Sample(kept, site), mm.Sample(f, site)) << int(method) << " site " << site;
  }
  kept.x_mm.erase(kept.x_mm.begin());
  kept.y_mm.erase(kept.y_mm.begin());
  kept.z_mm.erase(kept.z_mm.begin());
  kept.sed_Pa.erase(kept.sed_Pa.begin());
  EXPECT_NE(map.Sample(kept, 0), map.Sample(f, 0));
}

TEST(SedToCommandMapping, TransferThresholdPowerSaturation) {
  MappingParams m = Params(SamplingMethod::kMaxWithinRadius);
  m.threshold_Pa = 100;
  m.exponent = 0.5;
  const auto map = Mapping(m);
  EXPECT_DOUBLE_EQ(map.Transfer(50, 0), 0);     // below threshold
  EXPECT_DOUBLE_EQ(map.Transfer(100, 0), 0);    // at threshold
  EXPECT_DOUBLE_EQ(map.Transfer(1100, 0), 10);  // reference above threshold -> gain
  EXPECT_NEAR(map.Transfer(350, 0), 10 * std::sqrt(0.25), 1e-12);
  EXPECT_DOUBLE_EQ(map.Transfer(1e9, 0), 20);   // saturation
  EXPECT_DOUBLE_EQ(map.Transfer(kInf, 0), 20);
  EXPECT_DOUBLE_EQ(map.Transfer(-kInf, 0), 0);
  EXPECT_TRUE(std::isnan(map.Transfer(kNaN, 0)));
}

TEST(SedToCommandMapping, CalibrationAppliesOnlyWhenOn) {
  MappingParams m = Params(SamplingMethod::kMaxWithinRadius);
  m.calibration_gain = {2.0, 1.0};
  m.calibration_offset = {0.5, 0.0};
  const auto map = Mapping(m);
  EXPECT_DOUBLE_EQ(map.Transfer(0, 0), 0);         // off stays off (no offset)
  EXPECT_DOUBLE_EQ(map.Transfer(500, 0), 2 * 5 + 0.5);
  EXPECT_DOUBLE_EQ(map.Transfer(500, 1), 5);
}

TEST(SedToCommandMapping, SampleIsNaNOnlyWhereTheBadValueIs) {
  const auto map = Mapping(Params(SamplingMethod::kMaxWithinRadius));
  const SedField f = Field({0.0, 0.2, 5.0}, {0.0, 0.0, 0.0}, {100, kNaN, 200});
  EXPECT_TRUE(std::isnan(map.Sample(f, 0)));
  EXPECT_DOUBLE_EQ(map.Sample(f, 1), 200);
  EXPECT_TRUE(std::isnan(map.Sample(Field({0.0}, {0.0}, {kInf}), 0)));
}

TEST(SedToCommandMapping, ANonFiniteValueAnywhereRejectsTheWholeField) {
  const auto map = Mapping(Params(SamplingMethod::kMaxWithinRadius));
  // the NaN is 50 mm away from both sites
  const auto r = map.Map(Field({0.0, 50.0, 5.0}, {0.0, 0.0, 0.0}, {100, kNaN, 200}));
  EXPECT_EQ(r.check.non_finite_sed, 1u);
  EXPECT_TRUE(std::isnan(r.requested[0]));
  EXPECT_TRUE(std::isnan(r.requested[1]));
  const auto healthy = map.Map(Field({0.0, 50.0, 5.0}, {0.0, 0.0, 0.0}, {100, 0, 200}));
  EXPECT_DOUBLE_EQ(healthy.requested[1], 2.0);
}

TEST(SedToCommandMapping, NegativeSedReadsAsZeroAndIsCounted) {
  const auto map = Mapping(Params(SamplingMethod::kMeanWithinRadius));
  const auto r = map.Map(Field({0.0, 0.1}, {0.0, 0.0}, {-500, 300}));
  EXPECT_DOUBLE_EQ(r.sed_at_site_Pa[0], 150);
  EXPECT_EQ(r.check.negative_sed, 1u);
}

TEST(SedToCommandMapping, BadPositionsAreSkippedBySampleAndRejectedByMap) {
  const auto map = Mapping(Params(SamplingMethod::kMaxWithinRadius));
  const SedField f = Field({kNaN, 0.0, 0.1}, {0.0, kInf, 0.0}, {900, 800, 50});
  EXPECT_DOUBLE_EQ(map.Sample(f, 0), 50);
  const auto r = map.Map(f);
  EXPECT_EQ(r.check.non_finite_position, 2u);
  EXPECT_TRUE(std::isnan(r.requested[0]));
}

TEST(SedToCommandMapping, MismatchedLengthsMakeEveryRequestNaN) {
  const auto map = Mapping(Params(SamplingMethod::kMaxWithinRadius));
  const auto r = map.Map(Field({0.0, 1.0}, {0.0}, {100, 100}));
  EXPECT_FALSE(r.check.consistent);
  EXPECT_TRUE(std::isnan(r.requested[0]));
  EXPECT_TRUE(std::isnan(r.requested[1]));
}

TEST(SedToCommandMapping, ZWindowDropsTheFarSideOfTheFinger) {
  MappingParams m = Params(SamplingMethod::kMaxWithinRadius);
  m.z_min_mm = -5;
  m.z_max_mm = 0.5;
  SedField f = Field({0.0, 0.0}, {0.0, 0.0}, {100, 5000});
  f.z_mm = {-1.5, -14.0};  // pad side, nail side
  EXPECT_DOUBLE_EQ(Mapping(m).Sample(f, 0), 100);
}

TEST(SedToCommandMapping, HugeFiniteSedSaturatesInsteadOfOverflowing) {
  const double huge = std::numeric_limits<double>::max();
  for (auto method : {SamplingMethod::kInterpolate, SamplingMethod::kMaxWithinRadius,
                      SamplingMethod::kMeanWithinRadius}) {
    const auto r = Mapping(Params(method)).Map(Field({0.0, 0.1}, {0.0, 0.0}, {huge, huge}));
    EXPECT_DOUBLE_EQ(r.requested[0], 20);
  }
}

TEST(SedToCommandMapping, RejectsInvalidParameters) {
  MappingParams m = Params(SamplingMethod::kMaxWithinRadius);
  m.gain = 0;
  EXPECT_THROW(Mapping(m), std::invalid_argument);
  m = Params(SamplingMethod::kMaxWithinRadius);
  m.calibration_gain = {1.0};
  EXPECT_THROW(Mapping(m), std::invalid_argument);
  m = Params(SamplingMethod::kMaxWithinRadius);
  m.radius_mm = std::nan("");
  EXPECT_THROW(Mapping(m), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::display
