// The bridge subcommands end to end (runs the built program): simulate and run.

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/common/child_process.h"

namespace {

// Output (stdout and stderr) of `command`; its exit status in *status.
std::string RunCommand(const std::string& command, int* status) {
  const sedbridge::testing::ShellResult r = sedbridge::testing::RunShell(command);
  *status = r.status;
  return r.output;
}

std::string TempDir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("sedbridge_cli_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}

// B_coarse, memq (nothing leaves the process).
std::string WriteConfig(const std::string& dir) {
  const std::string path = dir + "/bridge.yaml";
  std::ofstream(path) << "fe: {model: B_coarse, preset: fast}\nlcm: {url: \"memq://\"}\n";
  return path;
}

TEST(BridgeCli, SimulateRunsTheSimulatedSensorThroughThePipeline) {
  const std::string dir = TempDir("simulate");
  int status = -1;
  const std::string out = RunCommand(std::string(SEDBRIDGE_BINARY) + " simulate " + SEDBRIDGE_SOURCE_DIR +
                                  "/config/scenes/sensor_sphere_press.yaml --config " + WriteConfig(dir) +
                                  " --duration-s 0.5 --no-plots --quiet --out " + dir,
                              &status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("scans: 50 (stepped 50, rejected 0)"), std::string::npos) << out;
  std::ifstream f(dir + "/summary.csv");
  int lines = 0;
  for (std::string l; std::getline(f, l);) ++lines;
  EXPECT_EQ(lines, 51);
  EXPECT_TRUE(std::filesystem::exists(dir + "/bridge.lcmlog"));
  std::filesystem::remove_all(dir);
}

TEST(BridgeCli, RunOnARecordingStopsAfterItsDurationWithTheDisplayAtZero) {
  const std::string dir = TempDir("run");
  int status = -1;
  const std::string out = RunCommand(std::string(SEDBRIDGE_BINARY) + " run --config " + WriteConfig(dir) + " --log-input " +
                                  SEDBRIDGE_SOURCE_DIR + "/config/bridge/example_press.log --duration-s 0.6",
                              &status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("stopped (duration)"), std::string::npos) << out;
  EXPECT_NE(out.find("display driven to zero"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

// A hand (B_coarse, memq): thumb on can0, middle on can1, the shipped two-bus example log.
std::string WriteHandConfig(const std::string& dir) {
  const std::string path = dir + "/hand.yaml";
  std::ofstream(path) << "fe: {model: B_coarse, preset: fast}\nlcm: {url: \"memq://\"}\nfingers:\n"
                         "  - {name: thumb, sensor: {profile: uskin_4x4, interface: can0}}\n"
                         "  - {name: middle, sensor: {profile: uskin_4x4, interface: can1}}\n";
  return path;
}

TEST(BridgeCli, RunOfAHandOnARecordingDrivesEachFingerAndZeroesEveryDisplay) {
  const std::string dir = TempDir("run_hand");
  int status = -1;
  const std::string out = RunCommand(std::string(SEDBRIDGE_BINARY) + " run --config " + WriteHandConfig(dir) +
                                         " --log-input " + SEDBRIDGE_SOURCE_DIR +
                                         "/config/bridge/example_hand.log --duration-s 0.8",
                                     &status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("stopped (duration)"), std::string::npos) << out;
  EXPECT_NE(out.find("== finger thumb (can0) =="), std::string::npos) << out;
  EXPECT_NE(out.find("== finger middle (can1) =="), std::string::npos) << out;
  const size_t first = out.find("display driven to zero");
  ASSERT_NE(first, std::string::npos) << out;
  EXPECT_NE(out.find("display driven to zero", first + 1), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

TEST(BridgeCli, RunOfAHandRefusesInterfaceAndSaysWhyWithoutSocketCan) {
  const std::string dir = TempDir("run_hand_can");
  int status = -1;
  std::string out = RunCommand(std::string(SEDBRIDGE_BINARY) + " run --config " + WriteHandConfig(dir) +
                                   " --interface can0 --duration-s 0.2",
                               &status);
  EXPECT_NE(status, 0) << out;
  EXPECT_NE(out.find("fingers:"), std::string::npos) << out;
  // Live buses: either no AF_CAN here, or no can0/can1: an error naming the cause, no hang.
  out = RunCommand(std::string(SEDBRIDGE_BINARY) + " run --config " + WriteHandConfig(dir) + " --duration-s 0.2",
                   &status);
  EXPECT_NE(status, 0) << out;
  EXPECT_TRUE(out.find("SocketCAN") != std::string::npos || out.find("can0") != std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

// `fidelity` refuses what it cannot run before building anything: a pad model without the
// kernels, an unknown one (the choices listed), a negative --random or --through-press,
// --random with --rig-on-pad, --random-ranges without --random or with an unknown name, a
// --truth-resolution without models or with a shift step out of range, and a config with a
// key out of range (file, line and column).
TEST(BridgeCli, FidelityRefusesABadPadOrConfigSayingWhere) {
  const std::string dir = TempDir("fidelity");
  const std::string fidelity = std::string(SEDBRIDGE_BINARY) + " fidelity --no-plots --out " + dir;
  // Each refused with a non-zero exit and a message naming what is wrong.
  auto refused = [&](const std::string& options, const std::string& says) {
    int status = -1;
    const std::string out = RunCommand(fidelity + " " + options, &status);
    EXPECT_NE(status, 0) << options << ": " << out;
    EXPECT_NE(out.find(says), std::string::npos) << options << ": " << out;
  };
  refused("--synthetic --pad winkler", "--pad");
  refused("--synthetic --pad bogus", "winkler, kernel, halfspace, layer");
  refused("--synthetic --random -3", "--random");
  refused("--rig-on-pad --random 3", "--rig-on-pad and --random");
  refused("--synthetic --random-ranges wide", "--random-ranges needs --random");
  refused("--rig-on-pad --random-ranges wide", "--random-ranges");
  refused("--synthetic --random 3 --random-ranges huge", "rig, wide");
  refused("--through-press -5", "--through-press");
  refused("--truth-resolution B --shift-step 0", "--shift-step");
  refused("--truth-resolution , ", "--truth-resolution MODELS");
  const std::string config = dir + "/bad.yaml";
  std::ofstream(config) << "fe:\n  contact_tolerance: 5\n";
  refused("--config " + config, config + ":2:22");
  std::filesystem::remove_all(dir);
}

// `fit-sensor --evaluate-pad`: the rig-fitted layer beside the forward model, press by press
// and summed up; a pad without kernels and a Poisson ratio out of range are refused.
TEST(BridgeCli, FitSensorEvaluatesASimulatedPadAgainstTheRig) {
  const std::string fit = std::string(SEDBRIDGE_BINARY) + " fit-sensor --cases " + SEDBRIDGE_SOURCE_DIR +
                          "/config/sensors/rig_uskin_4x4/cases.json --evaluate-pad";
  int status = -1;
  std::string out = RunCommand(fit + " layer --pad-thickness-mm 2.5 --pad-youngs-kPa 230 --pad-poisson 0.2", &status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("press_17.log"), std::string::npos) << out;
  // Presses 00-20 and 25-28 (the punches and the pair have no primitive yet: left out).
  EXPECT_NE(out.find("within 1 sigma on every axis: 24, 21 and 24 of 25"), std::string::npos) << out;
  EXPECT_NE(out.find("press_22.log: a punch, which the forward model has no primitive for: left out"), std::string::npos) << out;
  out = RunCommand(fit + " winkler", &status);
  EXPECT_NE(status, 0) << out;
  EXPECT_NE(out.find("winkler"), std::string::npos) << out;
  out = RunCommand(fit + " layer --pad-poisson 0.5", &status);
  EXPECT_NE(status, 0) << out;
  EXPECT_NE(out.find("--pad-poisson"), std::string::npos) << out;
}

TEST(BridgeCli, RunWithoutSocketCanSaysWhy) {
  int status = -1;
  const std::string out =
      RunCommand(std::string(SEDBRIDGE_BINARY) + " run --interface sedbridge_none --duration-s 0.2", &status);
  // Either the kernel lacks AF_CAN (this machine) or the interface does not exist: an error, no hang.
  EXPECT_NE(status, 0) << out;
}

}  // namespace
