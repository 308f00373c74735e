// Which rendering the bridge's display gets (bridge/display_requests.h) and the inverse
// rendering in a replay: the example log through fingertip model B_coarse and the pin_6x4
// display rendered by inverse FE.

#include "bridge/display_requests.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "bridge_test_util.h"
#include "render/display_on_leader.h"
#include "render/display_rendering.h"
#include "sensors/candump_log.h"

namespace sedbridge::bridge {
namespace {

BridgeConfig ConfigFor(const std::string& display, const std::string& rendering = "") {
  BridgeConfig c = testing::TestConfig();
  c.display_profile = display;
  c.display_rendering.reset();  // the test config asks for the curve; here the default decides
  if (rendering == "inverse") c.display_rendering = RenderingMethod::kInverse;
  if (rendering == "curve") c.display_rendering = RenderingMethod::kCurve;
  return c;
}

RenderingChoice Choose(const BridgeConfig& c) {
  return ChooseRendering(c, display::LoadNamedDisplayProfile(c.display_profile));
}

TEST(DisplayRequests, DefaultIsInverseWhereTheFactoryHasALoadAndCurveOtherwise) {
  EXPECT_EQ(Choose(ConfigFor("pin_6x4")).method, RenderingMethod::kInverse);
  // Suction follows the factory: inverse the moment render::MakeDisplayOnLeader builds it.
  const RenderingChoice suction = Choose(ConfigFor("suction_4x4"));
  EXPECT_EQ(suction.method, render::HasMechanicalLoad(display::DisplayKind::kSuction) ? RenderingMethod::kInverse
                                                                                       : RenderingMethod::kCurve)
      << suction.why;
  const RenderingChoice electro = Choose(ConfigFor("electrotactile_4x4"));
  EXPECT_EQ(electro.method, RenderingMethod::kCurve);
  EXPECT_NE(electro.why.find("no mechanical load"), std::string::npos) << electro.why;
  // Asked for the curve: the curve, whatever the display.
  EXPECT_EQ(Choose(ConfigFor("pin_6x4", "curve")).method, RenderingMethod::kCurve);
  // The curve's Merkel subset is too small to fit: the default falls back and says so.
  BridgeConfig region = ConfigFor("pin_6x4");
  region.merkel_region = MerkelRegion::kDisplay;
  const RenderingChoice r = Choose(region);
  EXPECT_EQ(r.method, RenderingMethod::kCurve);
  EXPECT_NE(r.why.find("merkel_region"), std::string::npos) << r.why;
}

TEST(DisplayRequests, InverseAskedOfADisplayWithoutALoadIsRefusedWithTheReason) {
  BridgeConfig c = ConfigFor("electrotactile_4x4", "inverse");
  c.file = "bridge.yaml";
  try {
    Choose(c);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bridge.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("no mechanical load"), std::string::npos) << what;
  }
}

std::string Read(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(DisplayRequests, PinReplayByInverseFeWritesPeakDisplaySedWithinTheProfileLimits) {
  const BridgeConfig config = ConfigFor("pin_6x4", "inverse");
  const display::DisplayProfile pins = display::LoadNamedDisplayProfile("pin_6x4");
  const Eigen::VectorXd max = render::MaxCommands(pins);
  const auto dir = std::filesystem::temp_directory_path() / ("sedbridge_inverse_replay_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  ReplayOptions options;
  options.out_dir = dir.string();
  int over = 0, negative = 0, commands = 0;
  double largest = 0;
  options.on_scan = [&](const ScanOutcome&, BridgePipeline& p) {
    const display::DisplayCommand& c = p.last_command();
    ASSERT_EQ(c.value.size(), size_t(max.size()));
    for (size_t i = 0; i < c.value.size(); ++i) {
      over += c.value[i] > max[Eigen::Index(i)] ? 1 : 0;
      negative += c.value[i] < 0 ? 1 : 0;
      largest = std::max(largest, c.value[i]);
    }
    ++commands;
  };
  const ReplayResult r = testing::ReplayWithConfigProfiles(config, source, options);
  EXPECT_TRUE(r.inverse_rendering) << r.display_rendering;
  EXPECT_EQ(over, 0);
  EXPECT_EQ(negative, 0);
  EXPECT_GT(commands, 250);
  EXPECT_GT(largest, 0.0) << "the press was rendered";
  EXPECT_EQ(r.render_ms.count, r.counters.steps);
  ASSERT_TRUE(r.have_display_fidelity) << r.display_fidelity_error;
  EXPECT_GT(r.display_fidelity.peak_ratio, 0.05);
  EXPECT_LT(r.display_fidelity.peak_ratio, 20.0);
  EXPECT_TRUE(std::isfinite(r.display_fidelity.rel_l2));

  // The display's SED: the same vertices as the bridge's, finite, something delivered.
  std::ifstream csv(dir / "peak_display_sed.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "vertex,x_mm,y_mm,z_mm,sed_Pa");
  std::ifstream merkel(dir / "peak_merkel_sed.csv");
  std::string merkel_line;
  std::getline(merkel, merkel_line);
  int rows = 0;
  double peak = 0;
  while (std::getline(csv, line)) {
    ASSERT_TRUE(std::getline(merkel, merkel_line)) << "more display rows than Merkel vertices";
    int vertex = -1;
    double x, y, z, sed, mx, my, mz, msed;
    char comma;
    std::istringstream in(line), m(merkel_line);
    in >> vertex >> comma >> x >> comma >> y >> comma >> z >> comma >> sed;
    m >> mx >> comma >> my >> comma >> mz >> comma >> msed;
    EXPECT_EQ(vertex, rows);
    EXPECT_DOUBLE_EQ(x, mx);
    EXPECT_DOUBLE_EQ(y, my);
    EXPECT_DOUBLE_EQ(z, mz);
    EXPECT_TRUE(std::isfinite(sed)) << line;
    peak = std::max(peak, sed);
    ++rows;
  }
  EXPECT_FALSE(std::getline(merkel, merkel_line)) << "fewer display rows than Merkel vertices";
  EXPECT_GT(rows, 100);
  EXPECT_GT(peak, 1.0);
  EXPECT_LT(peak, 1e6);
  std::filesystem::remove_all(dir);
}

TEST(DisplayRequests, CurveReplayWritesNoDisplaySed) {
  const auto dir = std::filesystem::temp_directory_path() / ("sedbridge_curve_replay_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "peak_display_sed.csv") << "stale\n";  // an earlier inverse run's
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  ReplayOptions options;
  options.out_dir = dir.string();
  const ReplayResult r = testing::ReplayWithConfigProfiles(ConfigFor("pin_6x4", "curve"), source, options);
  EXPECT_FALSE(r.inverse_rendering);
  EXPECT_NE(r.display_rendering.find("curve"), std::string::npos) << r.display_rendering;
  EXPECT_FALSE(std::filesystem::exists(dir / "peak_display_sed.csv"));
  EXPECT_GT(Read((dir / "peak_command.csv").string()).size(), 30u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sedbridge::bridge
