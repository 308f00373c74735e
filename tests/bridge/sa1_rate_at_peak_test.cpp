// An electrotactile display has no mechanical load: the replay reads its commands against the
// SA1 rate estimate at each electrode (bridge/sa1_rate_at_peak.h), labelled as an estimate;
// a display with a mechanical load gets no such file.

#include "bridge/sa1_rate_at_peak.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "bridge/display_requests.h"
#include "bridge_test_util.h"
#include "display/sed_to_command_mapping.h"
#include "sensors/candump_log.h"

namespace sedbridge::bridge {
namespace {

TEST(Sa1RateAtPeak, TheEstimateIsTheRateOfTheSedTheCurveSamplesAtEachSite) {
  const display::DisplayProfile p = display::LoadNamedDisplayProfile("electrotactile_4x4");
  display::SedField field;
  // A bump of 3 kPa at the pad's centre, 1.5 mm deep (the Merkel layer's depth).
  for (double x = -5; x <= 5; x += 0.5)
    for (double y = -5; y <= 5; y += 0.5) {
      field.x_mm.push_back(x), field.y_mm.push_back(y), field.z_mm.push_back(-1.5);
      field.sed_Pa.push_back(3000 * std::exp(-(x * x + y * y) / 8));
    }
  const Sa1RateAtSites e = EstimateSa1RateAtSites(p, field);
  const std::vector<double> sampled = display::SedToCommandMapping(p).Map(field).sed_at_site_Pa;
  ASSERT_EQ(e.sed_at_site_Pa, sampled);
  ASSERT_EQ(e.rate_Hz.size(), p.size());
  for (size_t i = 0; i < p.size(); ++i) EXPECT_EQ(e.rate_Hz[i], display::EstimateSa1Rate(sampled[i]));
  ASSERT_GE(e.peak_site, 0);
  // The inner 2x2 electrodes (5, 6, 9, 10) sit nearest the bump.
  EXPECT_TRUE(e.peak_site == 5 || e.peak_site == 6 || e.peak_site == 9 || e.peak_site == 10) << e.peak_site;
}

TEST(Sa1RateAtPeak, AnElectrotactileReplayWritesTheEstimateAndAPinReplayDoesNot) {
  const auto dir = std::filesystem::temp_directory_path() / ("sedbridge_sa1_replay_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  BridgeConfig c = testing::TestConfig();
  c.display_profile = "electrotactile_4x4";
  c.display_rendering.reset();  // the default: the curve, electrotactile has no mechanical load
  ReplayOptions options;
  options.out_dir = dir.string();
  {
    sensors::CandumpLogSource source(testing::ExampleLogPath());
    const ReplayResult r = testing::ReplayWithConfigProfiles(c, source, options);
    EXPECT_FALSE(r.inverse_rendering);
    EXPECT_NE(r.display_rendering.find("no mechanical load"), std::string::npos) << r.display_rendering;
    ASSERT_TRUE(r.have_sa1_estimate);
    EXPECT_GT(r.sa1_peak_rate_estimate_Hz, 0.0);
    EXPECT_EQ(r.sa1_peak_rate_estimate_Hz, display::EstimateSa1Rate(r.sa1_peak_site_sed_Pa));
    std::ifstream in(dir / "peak_sa1_rate_estimate.csv");
    std::string header;
    std::getline(in, header);
    EXPECT_EQ(header, "electrode,x_mm,y_mm,sed_at_site_Pa,sa1_rate_estimate_Hz,command_mA");
    int rows = 0;
    for (std::string line; std::getline(in, line);) ++rows;
    EXPECT_EQ(rows, 16);
  }
  c.display_profile = "pin_6x4";
  c.display_rendering = RenderingMethod::kCurve;
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  const ReplayResult r = testing::ReplayWithConfigProfiles(c, source, options);
  EXPECT_FALSE(r.have_sa1_estimate);
  EXPECT_FALSE(std::filesystem::exists(dir / "peak_sa1_rate_estimate.csv"));  // the electrotactile run's, removed
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sedbridge::bridge
