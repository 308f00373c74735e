#include "display/display_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace sedbridge::display {
namespace {

constexpr int64_t kMs = 1000;

// A smooth SED bump on a 0.5 mm vertex grid around the pad origin, peak `peak_Pa`.
SedField Bump(int64_t utime, double peak_Pa) {
  SedField f;
  f.utime = utime;
  f.source_scan_utime = utime - 300;
  f.model_id = "B";
  for (double x = -6; x <= 6; x += 0.5) {
    for (double y = -6; y <= 6; y += 0.5) {
      f.x_mm.push_back(x);
      f.y_mm.push_back(y);
      f.z_mm.push_back(-1.5);
      f.sed_Pa.push_back(peak_Pa * std::exp(-(x * x + y * y) / 8.0));
    }
  }
  return f;
}

TEST(DisplayController, SteadyPressRendersCentreStrongerThanEdge) {
  DisplayController display(LoadDisplayProfile("config/displays/suction_4x4.yaml"));
  DisplayCommand c;
  for (int k = 1; k <= 100; ++k) c = display.OnSedField(Bump(k * 10 * kMs, 3000), k * 10 * kMs);
  EXPECT_EQ(c.display_id, "suction_4x4");
  EXPECT_EQ(c.unit, "kPa");
  ASSERT_EQ(c.value.size(), 16u);
  EXPECT_EQ(c.sequence, 99);
  EXPECT_EQ(c.source_sed_utime, 1000 * kMs);
  EXPECT_EQ(c.source_scan_utime, 1000 * kMs - 300);
  // sites 5, 6, 9, 10 are the inner 2x2 (±1 mm); 0 is a corner (±3 mm).
  EXPECT_GT(c.value[5], c.value[0]);
  EXPECT_GT(c.value[0], 0.0);
  EXPECT_FALSE(c.stale || c.fault || c.shutdown);
  // matches the mapping exactly once settled (no clamping at 3 kPa of SED)
  EXPECT_NEAR(c.value[5], display.last_mapping().requested[5], 1e-9);
}

// An injected request source replaces the curve; the limiter after it is the same, and a
// field the check rejects never reaches the source (the command faults).
TEST(DisplayController, InjectedRequestSourceIsLimitedAndNeverSeesARejectedField) {
  const DisplayProfile profile = LoadDisplayProfile("config/displays/pin_6x4.yaml");
  int calls = 0;
  double ask = 0.5;
  DisplayController display(profile, [&](const SedField&, std::vector<double>* requested) {
    ++calls;
    requested->assign(profile.size(), ask);
  });
  EXPECT_TRUE(display.has_request_source());
  int64_t t = 0;
  DisplayCommand c;
  for (int k = 1; k <= 50; ++k) c = display.OnSedField(Bump(k, 2000), t += 10 * kMs);
  EXPECT_EQ(calls, 50);
  ASSERT_EQ(c.value.size(), profile.size());
  for (double v : c.value) EXPECT_NEAR(v, 0.5, 1e-12);  // not the curve's centre-strong frame
  ask = 100;  // far above safety.max: clamped
  for (int k = 51; k <= 100; ++k) c = display.OnSedField(Bump(k, 2000), t += 10 * kMs);
  EXPECT_TRUE(c.clamped);
  for (double v : c.value) EXPECT_LE(v, profile.safety.max);
  SedField bad = Bump(101, 2000);
  bad.sed_Pa[3] = std::numeric_limits<double>::infinity();
  c = display.OnSedField(bad, t += 10 * kMs);
  EXPECT_EQ(calls, 100);
  EXPECT_TRUE(c.fault);
  for (double v : c.value) EXPECT_EQ(v, 0.0);
}

TEST(DisplayController, NaNFieldFaultsAndSilenceGoesStale) {
  DisplayController display(LoadDisplayProfile("config/displays/pin_6x4.yaml"));
  int64_t t = 0;
  for (int k = 1; k <= 50; ++k) display.OnSedField(Bump(k, 2000), t += 10 * kMs);
  SedField bad = Bump(51, 2000);
  bad.sed_Pa[bad.size() / 2] = std::nan("");
  const DisplayCommand c = display.OnSedField(bad, t += 10 * kMs);
  EXPECT_TRUE(c.fault);
  EXPECT_GT(display.last_mapping().check.non_finite_sed, 0u);
  DisplayCommand s;
  for (int k = 0; k < 30; ++k) s = display.Tick(t += 10 * kMs);
  EXPECT_TRUE(s.stale);
  for (double v : s.value) EXPECT_EQ(v, 0.0);
  EXPECT_TRUE(display.Shutdown(t).shutdown);
  const DisplayStats& stats = display.stats();
  EXPECT_EQ(stats.fields, 51);
  EXPECT_EQ(stats.fields_rejected, 1);
  EXPECT_EQ(stats.commands, 82);
  // the bad field and the 30 ticks after it: no good field came to clear the fault
  EXPECT_EQ(stats.commands_fault, 31);
  EXPECT_GT(stats.commands_stale, 0);
}

// Whole chain, all shipped profiles, adversarial fields: the emitted values respect the
// profile's hard max and slew rate.
TEST(DisplayController, AdversarialFieldsNeverExceedProfileLimits) {
  for (const char* name : {"suction_4x4", "pin_6x4", "electrotactile_4x4"}) {
    SCOPED_TRACE(name);
    const DisplayProfile profile = LoadDisplayProfile(std::string("config/displays/") + name + ".yaml");
    DisplayController display(profile);
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> u(0, 1);
    const double kHuge = std::numeric_limits<double>::max();
    int64_t t = 0;
    std::vector<double> prev(profile.size(), 0.0);
    for (int k = 1; k <= 2000; ++k) {
      t += 1 + int64_t(u(rng) * 20 * kMs);
      DisplayCommand c;
      if (u(rng) < 0.2) {
        c = display.Tick(t);
      } else {
        SedField f = Bump(k, u(rng) < 0.3 ? kHuge : u(rng) * 1e5);
        for (double& s : f.sed_Pa) {
          const double r = u(rng);
          if (r < 0.002) s = std::nan("");
          else if (r < 0.004) s = -std::numeric_limits<double>::infinity();
          else if (r < 0.01) s = -s;
        }
        if (u(rng) < 0.01) f.x_mm.pop_back();
        c = display.OnSedField(f, t);
      }
      ASSERT_EQ(c.value.size(), profile.size());
      for (std::size_t i = 0; i < c.value.size(); ++i) {
        ASSERT_GE(c.value[i], 0.0);
        ASSERT_LE(c.value[i], profile.safety.max_per_actuator[i]);
        ASSERT_LE(c.value[i] - prev[i], profile.safety.slew_rate_per_s * 20e-3 + 1e-9);
      }
      prev = c.value;
    }
  }
}

}  // namespace
}  // namespace sedbridge::display
