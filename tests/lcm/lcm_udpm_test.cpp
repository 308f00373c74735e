// Real UDP multicast (udpm://, ttl=0) between two processes on this host, and lcm-logplayer
// replaying a log we wrote. Both skip, saying why, when multicast loopback does not work here
// (no multicast route, e.g. a container without one; fix: `sudo ip route add 224.0.0.0/4 dev lo`).
// The tests never change the machine's routing. Everything is bounded in time.

#include <gtest/gtest.h>

#include "tests/common/child_process.h"
#include "tests/common/lcm_multicast_probe.h"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "lcm/display_command_message.h"
#include "lcm/lcm_log_writer.h"
#include "lcm/lcm_publisher.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_display_command.hpp"

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
namespace {

using Clock = std::chrono::steady_clock;

// A port of our own so parallel runs and a live bridge on the default port don't cross.
std::string TestUrl() {
  return "udpm://239.255.76.67:" + std::to_string(20000 + ::getpid() % 20000) + "?ttl=0";
}

struct Counter {
  int count = 0;
  int64_t last_sequence = -1;
  float last_value = 0;
  void On(const lcm::ReceiveBuffer*, const std::string&, const lcmt_display_command* m) {
    ++count;
    last_sequence = m->sequence;
    last_value = m->num_actuators > 0 ? m->value[0] : -1;
  }
};

using sedbridge::testing::MulticastProblem;

// Child side: subscribe, signal readiness, collect for at most `budget_ms`.
[[noreturn]] void RunSubscriberChild(const std::string& url, int ready_fd, int result_fd,
                                     int budget_ms) {
  lcm::LCM lcm(url);
  Counter counter;
  if (lcm.good()) lcm.subscribe("SEDBRIDGE_TEST_COMMAND", &Counter::On, &counter);
  const char ready = lcm.good() ? 'R' : 'E';
  (void)!::write(ready_fd, &ready, 1);
  const auto end = Clock::now() + std::chrono::milliseconds(budget_ms);
  while (lcm.good() && counter.count < 5 && Clock::now() < end) lcm.handleTimeout(50);
  const int64_t report[3] = {counter.count, counter.last_sequence,
                             static_cast<int64_t>(counter.last_value * 1000)};
  (void)!::write(result_fd, report, sizeof(report));
  ::_exit(counter.count >= 5 ? 0 : 1);
}

bool WaitReadable(int fd, int timeout_ms) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) == 1;
}

TEST(LcmUdpm, RoundTripBetweenTwoProcesses) {
  const std::string url = TestUrl();
  if (const std::string why = MulticastProblem(url); !why.empty()) GTEST_SKIP() << why;

  int ready[2], result[2];
  ASSERT_EQ(::pipe(ready), 0);
  ASSERT_EQ(::pipe(result), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) RunSubscriberChild(url, ready[1], result[1], 5000);

  char r = 0;
  ASSERT_TRUE(WaitReadable(ready[0], 5000)) << "subscriber never started";
  ASSERT_EQ(::read(ready[0], &r, 1), 1);
  ASSERT_EQ(r, 'R');

  LcmChannels channels;
  channels.command = "SEDBRIDGE_TEST_COMMAND";
  LcmPublisher out(url, channels);
  DisplayCommand c;
  c.display_id = "suction_4x4";
  c.unit = "kPa";
  c.value = {12.5, 0.0};
  // UDP may drop: keep sending every 20 ms until the child has its five, for at most 6 s.
  int64_t seq = 0;
  const int status = sedbridge::testing::WaitExit(child, 6, [&] {
    c.sequence = seq;
    c.utime = 1000 + seq;
    ++seq;
    out.Publish(out.channels().command, ToLcm(c));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  });
  if (status == -1) FAIL() << "subscriber did not finish in time";
  int64_t report[3] = {0, 0, 0};
  ASSERT_TRUE(WaitReadable(result[0], 1000));
  ASSERT_EQ(::read(result[0], report, sizeof(report)), static_cast<ssize_t>(sizeof(report)));
  EXPECT_EQ(status, 0);
  EXPECT_GE(report[0], 5);
  EXPECT_GE(report[1], 4);  // sequences arrived in order from the publisher's counter
  EXPECT_EQ(report[2], 12500);
  for (int fd : {ready[0], ready[1], result[0], result[1]}) ::close(fd);
}

// A log written by LcmLogWriter is replayed by the stock lcm-logplayer onto udpm and arrives.
TEST(LcmUdpm, LcmLogplayerReplaysOurLog) {
  const char* player = "/usr/bin/lcm-logplayer";
  if (::access(player, X_OK) != 0) GTEST_SKIP() << player << " not installed (liblcm-bin)";
  const std::string url = TestUrl();
  if (const std::string why = MulticastProblem(url); !why.empty()) GTEST_SKIP() << why;

  const std::string path = (std::filesystem::temp_directory_path() /
                            ("sedbridge_replay_" + std::to_string(::getpid()) + ".lcmlog"))
                               .string();
  {
    LcmLogWriter log(path);
    for (int k = 0; k < 20; ++k) {
      DisplayCommand c;
      c.utime = 1'000'000 + k * 5'000;  // 5 ms apart: 0.1 s of replay
      c.sequence = k;
      c.value = {2.5};
      log.Write("SEDBRIDGE_TEST_COMMAND", ToLcm(c));
    }
  }
  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good());
  Counter counter;
  lcm.subscribe("SEDBRIDGE_TEST_COMMAND", &Counter::On, &counter);

  const pid_t child = sedbridge::testing::Spawn({player, "--lcm-url=" + url, path});
  ASSERT_GE(child, 0);
  int status = 0;
  bool exited = false;
  const auto end = Clock::now() + std::chrono::seconds(5);
  while (Clock::now() < end && counter.count < 20) {
    lcm.handleTimeout(50);
    if (!exited && ::waitpid(child, &status, WNOHANG) == child) exited = true;
  }
  // lcm-logplayer exits by itself at the end of the log; give it a moment, then stop it.
  if (!exited) sedbridge::testing::WaitExit(child, 2.0);
  std::filesystem::remove(path);
  // UDP on loopback rarely drops; most of the 20 must arrive, the last one in order.
  EXPECT_GE(counter.count, 15);
  EXPECT_GT(counter.last_sequence, 10);
  EXPECT_FLOAT_EQ(counter.last_value, 2.5f);
}

}  // namespace
}  // namespace sedbridge::lcm_io
