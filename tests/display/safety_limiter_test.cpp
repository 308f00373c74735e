#include "display/safety_limiter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace sedbridge::display {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

SafetyLimits Limits() {
  SafetyLimits l;
  l.max = {10.0, 10.0, 5.0};
  l.slew_rate_per_s = 100.0;  // 1 unit per 10 ms
  l.watchdog_timeout_s = 0.1;
  return l;
}

constexpr int64_t kMs = 1000;

TEST(SafetyLimiter, FirstOutputIsZeroThenRampsAtTheSlewRate) {
  SafetyLimiter lim(Limits());
  EXPECT_EQ(lim.Apply(0, 1, {10, 10, 10}).value, (std::vector<double>{0, 0, 0}));
  const auto& out = lim.Apply(10 * kMs, 2, {10, 10, 10});
  EXPECT_NEAR(out.value[0], 1.0, 1e-12);
  EXPECT_TRUE(out.clamped);  // 10 > max of actuator 2
  for (int k = 2; k <= 20; ++k) lim.Apply(k * 10 * kMs, 2 + k, {10, 10, 10});
  EXPECT_DOUBLE_EQ(lim.last().value[0], 10.0);
  EXPECT_DOUBLE_EQ(lim.last().value[2], 5.0);  // its own hard max
}

TEST(SafetyLimiter, NonFiniteRequestIsZeroAtOnceWithFault) {
  SafetyLimiter lim(Limits());
  int64_t t = 0;
  for (int k = 0; k < 20; ++k, t += 10 * kMs) lim.Apply(t, k + 1, {5, 5, 5});
  ASSERT_DOUBLE_EQ(lim.last().value[1], 5.0);
  const auto& out = lim.Apply(t, 100, {5, kNaN, kInf});
  EXPECT_TRUE(out.fault);
  EXPECT_DOUBLE_EQ(out.value[0], 5.0);
  EXPECT_DOUBLE_EQ(out.value[1], 0.0);
  EXPECT_DOUBLE_EQ(out.value[2], 0.0);
  EXPECT_FALSE(lim.Apply(t + 10 * kMs, 101, {5, 5, 5}).fault);
}

TEST(SafetyLimiter, WrongLengthIsAFaultAndZero) {
  SafetyLimiter lim(Limits());
  const auto& out = lim.Apply(0, 1, {1, 2});
  EXPECT_TRUE(out.fault);
  EXPECT_EQ(out.value, (std::vector<double>{0, 0, 0}));
}

TEST(SafetyLimiter, NegativeRequestIsClampedToZero) {
  SafetyLimiter lim(Limits());
  lim.Apply(0, 1, {-3, 0, 0});
  const auto& out = lim.Apply(50 * kMs, 2, {-3, 0, 0});
  EXPECT_TRUE(out.clamped);
  EXPECT_DOUBLE_EQ(out.value[0], 0.0);
}

TEST(SafetyLimiter, SilenceRampsToZeroAndFlagsStale) {
  SafetyLimiter lim(Limits());
  int64_t t = 0;
  for (int k = 0; k < 20; ++k, t += 10 * kMs) lim.Apply(t, k + 1, {8, 8, 4});
  const int64_t last_input = t - 10 * kMs;
  // Held while the watchdog is armed.
  EXPECT_FALSE(lim.Tick(last_input + 100 * kMs).stale);
  EXPECT_DOUBLE_EQ(lim.last().value[0], 8.0);
  // Then ramps down at the slew rate: 8 units need 80 ms.
  const auto& first_stale = lim.Tick(last_input + 110 * kMs);
  EXPECT_TRUE(first_stale.stale);
  EXPECT_NEAR(first_stale.value[0], 7.0, 1e-9);
  for (int64_t s = last_input + 120 * kMs; s <= last_input + 200 * kMs; s += 10 * kMs) lim.Tick(s);
  EXPECT_EQ(lim.last().value, (std::vector<double>{0, 0, 0}));
  EXPECT_TRUE(lim.last().stale);
}

TEST(SafetyLimiter, RepeatedInputDoesNotKeepItAlive) {
  SafetyLimiter lim(Limits());
  for (int64_t t = 0; t <= 400 * kMs; t += 10 * kMs) lim.Apply(t, 7, {5, 5, 5});
  EXPECT_TRUE(lim.last().stale);
  EXPECT_EQ(lim.last().value, (std::vector<double>{0, 0, 0}));
}

TEST(SafetyLimiter, RepeatedStampWithNaNStillZeroesAndFaults) {
  SafetyLimiter lim(Limits());
  int64_t t = 0;
  for (int k = 0; k < 20; ++k, t += 10 * kMs) lim.Apply(t, k + 1, {5, 5, 5});
  // same stamp as the last input (e.g. a producer marking a failed step with an old time)
  const auto& out = lim.Apply(t, 20, {kNaN, 7, 7});
  EXPECT_TRUE(out.fault);
  EXPECT_DOUBLE_EQ(out.value[0], 0.0);
  EXPECT_DOUBLE_EQ(out.value[1], 5.0);  // finite entries of a stale input are not taken
  EXPECT_TRUE(lim.Apply(t + kMs, 3, {1.0}).fault);  // wrong length, old stamp: all zero
  EXPECT_EQ(lim.last().value, (std::vector<double>{0, 0, 0}));
}

TEST(SafetyLimiter, NoJumpAfterAPause) {
  SafetyLimiter lim(Limits());
  lim.Apply(0, 1, {10, 10, 5});
  // 10 s without any call, then fresh input: the rise is bounded by slew * timeout.
  const auto& out = lim.Apply(10'000 * kMs, 2, {10, 10, 5});
  EXPECT_LE(out.value[0], 100.0 * 0.1 + 1e-12);
}

TEST(SafetyLimiter, SparseMessagesRiseByTimeNotByMessage) {
  // Messages 0.2 s apart: each may rise only kMaxRiseInterval_s worth of slew, so 0 -> 10
  // takes several messages instead of one (found by adversarial review: 0 -> 20 kPa in one
  // message).
  SafetyLimiter lim(Limits());
  lim.Apply(0, 1, {10, 10, 5});
  const auto& out = lim.Apply(200 * kMs, 2, {10, 10, 5});
  EXPECT_NEAR(out.value[0], 100.0 * kMaxRiseInterval_s, 1e-12);
  EXPECT_LT(out.value[0], 10.0);
}

TEST(SafetyLimiter, DeadBandBelowTheDeviceMinimumIsSentAsZero) {
  SafetyLimits l = Limits();
  l.min_nonzero = 2.0;  // the device accepts 0 or [2, max]
  SafetyLimiter lim(l);
  int64_t t = 0;
  std::vector<double> seen;
  for (int k = 0; k < 30; ++k, t += 10 * kMs) seen.push_back(lim.Apply(t, k + 1, {10, 1.5, 5}).value[0]);
  for (double y : seen) EXPECT_TRUE(y == 0.0 || y >= 2.0) << y;
  EXPECT_DOUBLE_EQ(seen[1], 0.0);   // ramp at 1: below the minimum, off
  EXPECT_DOUBLE_EQ(seen[2], 2.0);   // ramp at 2: on
  EXPECT_DOUBLE_EQ(lim.last().value[1], 0.0);  // a request of 1.5 can never be rendered
  l.min_nonzero = -1;
  EXPECT_THROW(SafetyLimiter{l}, std::invalid_argument);
}

TEST(SafetyLimiter, ShutdownIsZeroForGood) {
  SafetyLimiter lim(Limits());
  for (int k = 0; k < 50; ++k) lim.Apply(k * 10 * kMs, k + 1, {9, 9, 4});
  ASSERT_GT(lim.last().value[0], 0);
  const auto& out = lim.Shutdown(500 * kMs);
  EXPECT_TRUE(out.shutdown);
  EXPECT_EQ(out.value, (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(lim.Apply(510 * kMs, 1000, {9, 9, 4}).value, (std::vector<double>{0, 0, 0}));
  EXPECT_TRUE(lim.Tick(600 * kMs).shutdown);
}

TEST(SafetyLimiter, LimitsCannotBeDisabled) {
  for (auto mutate : std::vector<void (*)(SafetyLimits&)>{
           [](SafetyLimits& l) { l.max[0] = kInf; },
           [](SafetyLimits& l) { l.max[1] = 0; },
           [](SafetyLimits& l) { l.max.clear(); },
           [](SafetyLimits& l) { l.slew_rate_per_s = kInf; },
           [](SafetyLimits& l) { l.slew_rate_per_s = 0; },
           [](SafetyLimits& l) { l.slew_rate_per_s = kNaN; },
           [](SafetyLimits& l) { l.watchdog_timeout_s = 0; },
           [](SafetyLimits& l) { l.watchdog_timeout_s = 1e9; },
       }) {
    SafetyLimits l = Limits();
    mutate(l);
    EXPECT_THROW(SafetyLimiter{l}, std::invalid_argument);
  }
}

// ---- property tests: random and adversarial request streams ----

// Draws requests from a mixture of nasty cases; each time step may be input, silence, or a
// burst of several inputs at the same instant.
class Adversary {
 public:
  explicit Adversary(uint32_t seed) : rng_(seed) {}

  double Value(double max) {
    switch (Pick(10)) {
      case 0: return kNaN;
      case 1: return Pick(2) ? kInf : -kInf;
      case 2: return std::numeric_limits<double>::max() * (Pick(2) ? 1 : -1);
      case 3: return -Uniform(0, 1e6);
      case 4: return Uniform(max, 1e9);
      case 5: return Pick(2) ? 0.0 : max;
      case 6: return std::numeric_limits<double>::denorm_min();
      default: return Uniform(0, max);
    }
  }
  std::vector<double> Request(const std::vector<double>& max) {
    if (Pick(50) == 0) return std::vector<double>(Pick(2) ? 0 : max.size() + 1, 1.0);
    std::vector<double> r;
    for (double m : max) r.push_back(Value(m));
    return r;
  }
  int Pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  double Uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }

 private:
  std::mt19937 rng_;
};

struct Checker {
  const SafetyLimits& limits;
  std::vector<double> prev;
  int64_t prev_t = 0;
  bool have_prev = false;
  int strong_outputs = 0;  // outputs above half the max: the stream was not trivially zero

  void Check(const LimitedOutput& out, int64_t t, const char* where) {
    ASSERT_EQ(out.value.size(), limits.max.size());
    const double dt = have_prev ? std::max<int64_t>(0, t - prev_t) * 1e-6 : 0;
    for (std::size_t i = 0; i < out.value.size(); ++i) {
      const double y = out.value[i];
      ASSERT_TRUE(std::isfinite(y)) << where << " t=" << t;
      ASSERT_GE(y, 0.0) << where << " t=" << t;
      ASSERT_LE(y, limits.max[i]) << where << " t=" << t << " actuator " << i;
      ASSERT_TRUE(y == 0.0 || y >= limits.min_nonzero) << where << " in the dead band at t=" << t;
      if (!have_prev) {
        ASSERT_EQ(y, 0.0) << "first output must start from rest";
        continue;
      }
      const double tol = 1e-9;
      const double step = y - prev[i];
      ASSERT_LE(step, limits.slew_rate_per_s * std::min({dt, limits.watchdog_timeout_s, kMaxRiseInterval_s}) +
                          limits.min_nonzero + tol)
          << where << " rise too fast at t=" << t << " actuator " << i;
      const bool dropped_to_zero_for_safety = y == 0.0 && (out.fault || out.shutdown || limits.min_nonzero > 0);
      if (!dropped_to_zero_for_safety) {
        ASSERT_GE(step, -limits.slew_rate_per_s * dt - tol)
            << where << " fall too fast at t=" << t << " actuator " << i;
      }
      if (y > 0.5 * limits.max[i]) ++strong_outputs;
    }
    prev = out.value;
    prev_t = std::max(prev_t, t);
    have_prev = true;
  }
};

class SafetyLimiterProperty : public ::testing::TestWithParam<uint32_t> {};

TEST_P(SafetyLimiterProperty, NeverAboveMaxNeverFasterThanSlewZeroAfterSilence) {
  Adversary adv(GetParam());
  SafetyLimits limits;
  const int n = 1 + adv.Pick(20);
  for (int i = 0; i < n; ++i) limits.max.push_back(adv.Uniform(0.1, 50));
  limits.slew_rate_per_s = adv.Uniform(1, 2000);
  limits.watchdog_timeout_s = adv.Uniform(0.005, 1.0);
  // Half the seeds with a device dead band below range[0].
  if (adv.Pick(2)) limits.min_nonzero = adv.Uniform(0, 0.4 * *std::min_element(limits.max.begin(), limits.max.end()));
  SafetyLimiter lim(limits);
  Checker check{limits, {}, 0, false, 0};
  int faults = 0, clamps = 0, stales = 0;
  const double max_max = *std::max_element(limits.max.begin(), limits.max.end());
  const int64_t to_zero_us =
      int64_t(std::ceil((limits.watchdog_timeout_s + max_max / limits.slew_rate_per_s) * 1e6));

  int64_t t = adv.Pick(1000) * kMs;
  int64_t input_utime = 0;
  for (int step = 0; step < 3000; ++step) {
    // Time advances irregularly: jitter, same-instant bursts, and occasional long gaps.
    switch (adv.Pick(20)) {
      case 0: break;                                      // burst: same instant
      case 1: t += int64_t(adv.Uniform(0, 3e6)); break;   // long pause
      default: t += int64_t(adv.Uniform(100, 30'000)); break;
    }
    const int mode = adv.Pick(10);
    if (mode < 6) {  // fresh input (sometimes repeated or reordered stamps)
      const int stamp = adv.Pick(10);
      const int64_t stamp_utime = stamp == 0 ? input_utime : stamp == 1 ? input_utime - 5 : ++input_utime;
      const LimitedOutput& out = lim.Apply(t, stamp_utime, adv.Request(limits.max));
      check.Check(out, t, "Apply");
      faults += out.fault;
      clamps += out.clamped;
      stales += out.stale;
    } else if (mode < 9) {
      check.Check(lim.Tick(t), t, "Tick");
    } else {
      // A stretch of silence ticked at the command rate: must end at exactly zero.
      const int64_t period = int64_t(adv.Uniform(500, 20'000));
      const int64_t until = t + to_zero_us + period + int64_t(adv.Uniform(0, 2e5));
      for (; t < until; t += period) check.Check(lim.Tick(t), t, "silence");
      check.Check(lim.Tick(t), t, "silence end");
      for (double y : lim.last().value)
        ASSERT_EQ(y, 0.0) << "not zero after silence, seed " << GetParam();
      ASSERT_TRUE(lim.last().stale);
    }
    if (HasFatalFailure()) return;
  }
  // The adversary exercised every path (guards against a vacuous pass).
  EXPECT_GT(check.strong_outputs, 100);
  EXPECT_GT(faults, 10);
  EXPECT_GT(clamps, 10);
  EXPECT_GT(stales, 10);
  // Shutdown: zero at once and afterwards, whatever comes in.
  check.Check(lim.Shutdown(t), t, "shutdown");
  for (int k = 0; k < 10; ++k) {
    t += 1000;
    check.Check(lim.Apply(t, ++input_utime, adv.Request(limits.max)), t, "after shutdown");
    for (double y : lim.last().value) ASSERT_EQ(y, 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Seeds, SafetyLimiterProperty,
                         ::testing::Values(1u, 2u, 3u, 7u, 42u, 1234u, 99991u, 20260101u));

TEST(SafetyLimiterProperty, ReachesZeroWithinTimeoutPlusRampAfterFullOutput) {
  SafetyLimits limits = Limits();
  SafetyLimiter lim(limits);
  int64_t t = 0;
  for (int k = 0; k < 200; ++k, t += kMs) lim.Apply(t, k + 1, {1e9, 1e9, 1e9});
  const int64_t last_input = t - kMs;
  ASSERT_DOUBLE_EQ(lim.last().value[0], 10.0);
  const int64_t deadline = last_input + int64_t((0.1 + 10.0 / 100.0) * 1e6) + kMs;
  for (; t <= deadline; t += kMs) lim.Tick(t);
  EXPECT_EQ(lim.last().value, (std::vector<double>{0, 0, 0}));
}

}  // namespace
}  // namespace sedbridge::display
