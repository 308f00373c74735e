// InterfaceFilterSource: one bus out of a `candump -l any` log.

#include <gtest/gtest.h>

#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "sensors/candump_log.h"
#include "sensors/interface_filter_source.h"

namespace sedbridge::sensors {
namespace {

std::unique_ptr<std::istream> MixedLog() {
  return std::make_unique<std::istringstream>(
      "(1700000000.000000) can0 710#01\n"
      "(1700000000.000100) can1 710#02\n"
      "(1700000000.000200) can0 711#03\n"
      "(1700000000.000300) vcan0 712#04\n");
}

TEST(InterfaceFilterSource, KeepsOnlyTheChosenInterface) {
  CandumpLogSource log(MixedLog(), "mixed");
  InterfaceFilterSource source(log, "can0");
  std::vector<uint8_t> first_bytes;
  while (!source.Done())
    if (auto f = source.Next(-1)) first_bytes.push_back(f->data[0]);
  EXPECT_EQ(first_bytes, (std::vector<uint8_t>{1, 3}));
  EXPECT_EQ(source.Stats().frames, 2);
  EXPECT_EQ(source.frames_skipped(), 2);
  EXPECT_EQ(source.interfaces_seen(), (std::set<std::string>{"can0", "can1", "vcan0"}));
}

TEST(InterfaceFilterSource, EmptyNameKeepsEverythingAndNotesTheInterfaces) {
  CandumpLogSource log(MixedLog(), "mixed");
  InterfaceFilterSource source(log, "");
  int n = 0;
  while (!source.Done())
    if (source.Next(-1)) ++n;
  EXPECT_EQ(n, 4);
  EXPECT_EQ(source.interfaces_seen().size(), 3u);
}

TEST(InterfaceFilterSource, ABoundedReadReturnsAfterASkippedFrameLikeATimeout) {
  CandumpLogSource log(MixedLog(), "mixed");
  InterfaceFilterSource source(log, "can1");
  EXPECT_FALSE(source.Next(0).has_value());  // can0 frame skipped: no wait beyond one read
  auto f = source.Next(0);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->data[0], 2);
}

}  // namespace
}  // namespace sedbridge::sensors
