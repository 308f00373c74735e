// `sedbridge press` with a scene that loads a display (`display: {profile, commands}`), end to
// end (runs the built program): its Merkel SED is DisplayOnLeader's full contact answer for
// the same commands, and a display off the leader's pad is refused naming the profile's
// file:line:column.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_on_leader.h"
#include "scene/fingertip_compliance.h"
#include "tests/common/child_process.h"

namespace sedbridge::render {
namespace {

std::string TempDir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("sedbridge_display_press_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}

// A display press on B_coarse (the tests' leader: seconds, not minutes), bone as the
// display rendering's leader has it (scene::FingertipComplianceOptions's default, 200 N/m).
std::string WriteScene(const std::string& dir, const std::string& display) {
  const std::string path = dir + "/scene.yaml";
  std::ofstream(path) << "model: B_coarse\n"
                         "elasticity: linear\n"
                         "dynamics: {integrator: quasi_static, steps: 1}\n"
                         "solver: {type: compliance}\n"
                         "bone: {mode: fixed}\n"
                      << display;
  return path;
}

// merkel_sed.csv's sed_Pa column.
std::vector<double> ReadSed(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "vertex,x_mm,y_mm,z_mm,sed_Pa");
  std::vector<double> sed;
  while (std::getline(in, line)) sed.push_back(std::stod(line.substr(line.rfind(',') + 1)));
  return sed;
}

TEST(DisplayPressCli, TheMerkelSedIsTheDisplaysFullContactAnswer) {
  const std::string dir = TempDir("suction");
  const std::vector<double> commands{0, 0, 0, 0, 0, 12, 4, 0, 0, 7, 0, 0, 20, 0, 0, 0};
  std::string list;
  for (double c : commands) list += (list.empty() ? "" : ", ") + std::to_string(c);
  const std::string scene = WriteScene(dir, "display:\n  profile: suction_4x4\n  commands: [" + list + "]\n");
  const sedbridge::testing::ShellResult r = sedbridge::testing::RunShell(std::string(SEDBRIDGE_BINARY) + " press --scene " + scene +
                                                   " --no-plots --quiet --out " + dir + "/out");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("display suction_4x4"), std::string::npos) << r.output;
  for (const char* f : {"merkel_sed.csv", "display_added_sed.csv", "display_commands.csv", "display_press.csv",
                        "display_press.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/" + f)) << f;
  const std::vector<double> pressed = ReadSed(dir + "/out/merkel_sed.csv");

  const model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  scene::FingertipCompliance leader(model, DisplayLeaderOptions());
  const display::DisplayProfile profile = display::LoadNamedDisplayProfile("suction_4x4");
  const auto on_leader = MakeDisplayOnLeader(leader, profile.device);
  Eigen::VectorXd sed;
  ASSERT_TRUE(on_leader->Press(Eigen::Map<const Eigen::VectorXd>(commands.data(), Eigen::Index(commands.size())), sed))
      << on_leader->error();
  ASSERT_EQ(pressed.size(), size_t(sed.size()));
  double peak = 0;
  for (Eigen::Index v = 0; v < sed.size(); ++v) peak = std::max(peak, sed[v]);
  // merkel_sed.csv keeps 8 significant digits.
  for (Eigen::Index v = 0; v < sed.size(); ++v) EXPECT_NEAR(pressed[size_t(v)], sed[v], 1e-7 * peak) << "vertex " << v;
}

TEST(DisplayPressCli, ADisplayOffTheLeadersPadIsRefusedNamingTheProfilesLine) {
  const std::string dir = TempDir("wide");
  // pin_8x8 moved 5 mm toward the tip: its tip row at y = 8.5 mm (+0.4 mm pin), beyond
  // B_coarse's candidate contact patch (y up to 6.0 mm).
  std::string pins;
  {
    std::ifstream in(std::string(SEDBRIDGE_SOURCE_DIR) + "/config/displays/pin_8x8.yaml");
    std::stringstream s;
    s << in.rdbuf();
    pins = s.str();
  }
  const std::string centre = "center_mm: [0.0, 0.0]";
  ASSERT_NE(pins.find(centre), std::string::npos);
  pins.replace(pins.find(centre), centre.size(), "center_mm: [0.0, 5.0]");
  std::ofstream(dir + "/pin_tip.yaml") << pins;
  int actuators_line = 0, n = 0;
  {
    std::istringstream in(pins);
    for (std::string line; std::getline(in, line);)
      if (++n, line.rfind("actuators:", 0) == 0) actuators_line = n;
  }
  std::string zeros;
  for (int i = 0; i < 64; ++i) zeros += i ? ", 0" : "0";
  const std::string scene = WriteScene(dir, "display:\n  profile: " + dir + "/pin_tip.yaml\n  commands: [" + zeros + "]\n");
  const sedbridge::testing::ShellResult r = sedbridge::testing::RunShell(std::string(SEDBRIDGE_BINARY) + " press --scene " + scene +
                                                   " --no-plots --quiet --out " + dir + "/out");
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(dir + "/pin_tip.yaml:" + std::to_string(actuators_line) + ":1: actuator 0 at (-3.5, 8.5) mm "
                              "with its 0.4 mm pin"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("is not on the finger's pad"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("model B_coarse"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/merkel_sed.csv"));
}

}  // namespace
}  // namespace sedbridge::render
