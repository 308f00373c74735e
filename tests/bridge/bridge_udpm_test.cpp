// Real UDP multicast on loopback between two processes: `sedbridge replay --lcm-url udpm://...`
// publishes the example log's display commands; this process subscribes and checks them.
// Skips, saying why, when multicast does not loop back here (e.g. a container without a
// multicast route; fix: `sudo ip route add 224.0.0.0/4 dev lo`). Bounded in time.

#include <gtest/gtest.h>

#include "tests/common/child_process.h"
#include "tests/common/lcm_multicast_probe.h"

#include <unistd.h>

#include <filesystem>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "sedbridge/lcmt_display_command.hpp"

namespace {

std::string TestUrl() { return "udpm://239.255.76.67:" + std::to_string(20000 + (::getpid() + 7) % 20000) + "?ttl=0"; }

using sedbridge::testing::MulticastProblem;

struct Commands {
  int count = 0, out_of_order = 0, over_limit = 0, shutdown = 0, nonzero = 0;
  int64_t last_sequence = -1;
  void On(const lcm::ReceiveBuffer*, const std::string&, const sedbridge::lcmt_display_command* m) {
    ++count;
    if (m->sequence <= last_sequence) ++out_of_order;
    last_sequence = m->sequence;
    float peak = 0;
    for (float v : m->value) {
      if (v < 0 || v > 20.0f) ++over_limit;
      peak = std::max(peak, v);
    }
    if (peak > 0) ++nonzero;
    if (m->shutdown && peak == 0) ++shutdown;
  }
};

TEST(BridgeUdpm, ReplayPublishesToAnotherProcess) {
  const std::string url = TestUrl();
  if (const std::string why = MulticastProblem(url); !why.empty()) GTEST_SKIP() << why;
  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good());
  Commands got;
  lcm.subscribe("DISPLAY_COMMAND", &Commands::On, &got);

  const std::string out = (std::filesystem::temp_directory_path() / ("sedbridge_udpm_" + std::to_string(::getpid()))).string();
  const std::string root = SEDBRIDGE_SOURCE_DIR;
  // Paced at 4x the recorded rate so the subscriber is never flooded.
  const pid_t child = sedbridge::testing::Spawn({SEDBRIDGE_BINARY, "replay", root + "/config/bridge/example_press.log",
                                                 "--config", root + "/tests/bridge/data/b_coarse.yaml", "--speed", "4",
                                                 "--lcm-url", url, "--out", out, "--no-plots", "--quiet"});
  ASSERT_GE(child, 0);
  const int status = sedbridge::testing::WaitExit(child, 60, [&] { lcm.handleTimeout(20); });
  if (status == -1) FAIL() << "replay did not finish in 60 s";
  for (int i = 0; i < 10; ++i) lcm.handleTimeout(20);  // the tail still in the socket
  std::filesystem::remove_all(out);
  ASSERT_EQ(status, 0) << "replay failed";
  // 300 scan commands + 3 shutdown commands; UDP on loopback may still drop a few. A paced
  // replay also ticks the display (watchdog) whenever the log is silent for a tick period
  // (5 ms at 200 Hz): at most one per period of the ~0.75 s run.
  EXPECT_GE(got.count, 290);
  EXPECT_LE(got.count, 303 + 150);
  EXPECT_EQ(got.out_of_order, 0);
  EXPECT_EQ(got.over_limit, 0);
  EXPECT_GT(got.nonzero, 40);
  EXPECT_GE(got.shutdown, 1);
}

}  // namespace
