// MergedFrameSource: several sources as one, in time order.

#include <gtest/gtest.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "sensors/candump_log.h"
#include "sensors/merged_frame_source.h"

namespace sedbridge::sensors {
namespace {

std::unique_ptr<FrameSource> Log(const std::string& text, const std::string& name) {
  return std::make_unique<CandumpLogSource>(std::make_unique<std::istringstream>(text), name);
}

TEST(MergedFrameSource, HandsOutTheSourcesFramesInTimeOrderTiesToTheFirstListed) {
  std::vector<std::unique_ptr<FrameSource>> sources;
  sources.push_back(Log("(1700000000.000100) can0 710#01\n(1700000000.000300) can0 711#03\n"
                        "(1700000000.000500) can0 712#05\n", "a"));
  sources.push_back(Log("(1700000000.000000) can1 710#00\n(1700000000.000300) can1 711#04\n", "b"));
  MergedFrameSource merged(std::move(sources));
  std::vector<int> order;
  std::vector<std::string> buses;
  while (!merged.Done())
    if (auto f = merged.Next(-1)) order.push_back(f->data[0]), buses.push_back(f->Interface());
  EXPECT_EQ(order, (std::vector<int>{0, 1, 3, 4, 5}));
  EXPECT_EQ(buses, (std::vector<std::string>{"can1", "can0", "can0", "can1", "can0"}));
  EXPECT_EQ(merged.Stats().frames, 5);
  EXPECT_FALSE(merged.Next(0).has_value());
}

TEST(MergedFrameSource, CloseEndsEverySourceAndNoSourceIsRefused) {
  std::vector<std::unique_ptr<FrameSource>> sources;
  sources.push_back(Log("(1700000000.000100) can0 710#01\n", "a"));
  MergedFrameSource merged(std::move(sources));
  merged.Close();
  EXPECT_TRUE(merged.Done());
  EXPECT_FALSE(merged.Next(0).has_value());
  EXPECT_THROW(MergedFrameSource(std::vector<std::unique_ptr<FrameSource>>{}), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::sensors
