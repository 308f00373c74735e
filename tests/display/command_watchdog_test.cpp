#include "display/command_watchdog.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace sedbridge::display {
namespace {

TEST(CommandWatchdog, StaleUntilFedThenAfterTimeout) {
  CommandWatchdog w(0.1);
  EXPECT_TRUE(w.Stale(0));
  EXPECT_TRUE(w.Feed(10, 1'000'000));
  EXPECT_FALSE(w.Stale(1'000'000));
  EXPECT_FALSE(w.Stale(1'100'000));  // exactly the timeout: still fresh
  EXPECT_TRUE(w.Stale(1'100'001));
}

TEST(CommandWatchdog, RepeatedOrOlderInputDoesNotRearm) {
  CommandWatchdog w(0.1);
  ASSERT_TRUE(w.Feed(500, 0));
  EXPECT_FALSE(w.Feed(500, 90'000));  // same field again
  EXPECT_FALSE(w.Feed(400, 95'000));  // reordered
  EXPECT_TRUE(w.Stale(150'000));
  EXPECT_TRUE(w.Feed(501, 150'000));
  EXPECT_FALSE(w.Stale(150'000));
}

TEST(CommandWatchdog, ClockGoingBackwardsCountsAsStale) {
  CommandWatchdog w(0.1);
  ASSERT_TRUE(w.Feed(1, 1'000'000));
  EXPECT_TRUE(w.Stale(999'999));
}

TEST(CommandWatchdog, RejectsNonPositiveTimeout) {
  EXPECT_THROW(CommandWatchdog(0.0), std::invalid_argument);
  EXPECT_THROW(CommandWatchdog(-1.0), std::invalid_argument);
  EXPECT_THROW(CommandWatchdog(1.0 / 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::display
