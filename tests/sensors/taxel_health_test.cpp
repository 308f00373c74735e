// Taxel health (sensors/taxel_health.h) on scans of the uskin_4x4 profile made by its own
// forward model plus the profile's noise: faulty taxels are masked, real contacts are not.

#include "sensors/taxel_health.h"
#include "sensors/taxel_health_episodes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "sensors/calibration_press.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {
namespace {

class TaxelHealthTest : public ::testing::Test {
 protected:
  TaxelHealthTest() : profile_(LoadNamedSensorProfile("uskin_4x4")), model_(profile_, profile_.forward_model) {}

  /// A scan of `readings_N` (3 per taxel) with 2 counts of noise on every raw reading.
  Scan MakeScan(const Eigen::VectorXd& readings_N) {
    const int n = profile_.taxel_count;
    Scan s;
    s.num_taxels = n;
    s.num_axes = 3;
    s.complete = true;
    s.utime = 1000 + 10000 * sequence_;
    s.sequence = sequence_++;
    s.raw_counts.resize(size_t(3 * n));
    s.pressure_Pa.resize(size_t(n));
    s.shear_x_Pa.resize(size_t(n));
    s.shear_y_Pa.resize(size_t(n));
    s.force_N.resize(size_t(n));
    s.valid.assign(size_t(n), 1);
    s.flags.assign(size_t(n), 0);
    const double area_m2 = profile_.taxel_area_mm2() * 1e-6;
    std::normal_distribution<double> noise(0, 2);
    for (int k = 0; k < n; ++k) {
      double calibrated[3];
      for (int a = 0; a < 3; ++a) {
        const double per_count = NewtonsPerCount(profile_, k, a);
        const long counts = std::lround(readings_N[3 * k + a] / per_count + noise(rng_));
        s.raw_counts[size_t(3 * k + a)] = int32_t(profile_.calibration.offset_counts[size_t(a)] + double(counts));
        calibrated[a] = double(counts) * per_count;
      }
      s.shear_x_Pa[size_t(k)] = calibrated[0] / area_m2;
      s.shear_y_Pa[size_t(k)] = calibrated[1] / area_m2;
      s.pressure_Pa[size_t(k)] = calibrated[2] / area_m2;
      s.force_N[size_t(k)] = calibrated[2];
    }
    return s;
  }

  Eigen::VectorXd Sphere(double x_mm, double y_mm, double radius_mm, double force_N) const {
    ContactPrimitive c;
    c.shape = ContactShape::kSphere;
    c.x_mm = x_mm, c.y_mm = y_mm, c.radius_mm = radius_mm, c.normal_force_N = force_N;
    Eigen::VectorXd r;
    model_.Predict(c, &r);
    return r;
  }
  Eigen::VectorXd Quiet() const { return Eigen::VectorXd::Zero(3 * profile_.taxel_count); }
  const TaxelPosition& Centre(int k) const { return profile_.taxels[size_t(k)]; }
  // Centre of the four middle taxels 5, 6, 9, 10 (the example log's contact).
  static constexpr double kMiddleX = 0, kMiddleY = 0;

  /// Scans `count` scans of `readings(i)` edited by `edit(i, scan)` through `health`;
  /// `check(i, out)` sees each returned scan.
  void Run(TaxelHealth& health, int count, const std::function<Eigen::VectorXd(int)>& readings,
           const std::function<void(int, Scan&)>& edit, const std::function<void(int, const Scan&)>& check = {}) {
    for (int i = 0; i < count; ++i) {
      Scan s = MakeScan(readings(i));
      if (edit) edit(i, s);
      const Scan& out = health.Apply(s);
      if (check) check(i, out);
    }
  }

  static void SetNormal(Scan& s, int k, double force_N, double area_m2) {
    s.force_N[size_t(k)] = force_N;
    s.pressure_Pa[size_t(k)] = force_N / area_m2;
    s.raw_counts[size_t(3 * k + 2)] = int32_t(1000 + std::lround(force_N / 0.0005));
  }
  double Area_m2() const { return profile_.taxel_area_mm2() * 1e-6; }

  SensorProfile profile_;
  TactileForwardModel model_;
  std::mt19937 rng_{7};
  int64_t sequence_ = 0;
};

TEST_F(TaxelHealthTest, HealthyQuietScansAndTheForwardModelsContactsMaskNothing) {
  TaxelHealth health(profile_);
  // Quiet, then spheres pressed on the middle, on a taxel's centre and on the corner taxel's.
  Run(health, 50, [&](int) { return Quiet(); }, {});
  for (const auto& [x, y] : {std::pair{kMiddleX, kMiddleY}, std::pair{Centre(5).x_mm, Centre(5).y_mm},
                             std::pair{Centre(0).x_mm, Centre(0).y_mm}})
    Run(health, 100, [&](int i) { return Sphere(x, y, 3, 2.0 * std::min(i, 50) / 50); }, {},
        [&](int i, const Scan& out) { EXPECT_EQ(health.left_out(), 0) << "scan " << i << " at " << x << ", " << y; (void)out; });
  EXPECT_EQ(health.masked_count(), 0);
  EXPECT_EQ(health.counters().masked_taxel_scans, 0);
  EXPECT_EQ(health.counters().retares, 0);
}

TEST_F(TaxelHealthTest, RealContactOnASingleTaxelsCentreIsNoFault) {
  // A thin, sharp contact right on one taxel's centre loads that taxel far more than any
  // other, but its neighbours respond as the forward model says: no fault.
  TaxelHealth health(profile_);
  for (int k : {5, 0, 6}) {
    Run(health, 80, [&](int i) { return Sphere(Centre(k).x_mm, Centre(k).y_mm, 0.5, 3.0 * std::min(i, 40) / 40); }, {},
        [&](int i, const Scan&) { EXPECT_EQ(health.left_out(), 0) << "taxel " << k << " scan " << i; });
    Run(health, 20, [&](int) { return Quiet(); }, {});
  }
  EXPECT_EQ(health.masked_count(), 0);
}

TEST_F(TaxelHealthTest, SaturatedTaxelUnderAHardPressIsHardContactNotAFault) {
  // Taxel 5 clips at 60 % of its true load (saturated, a lower bound): its neighbours carry
  // more than the clipped reading implies, which is a hard contact, as today.
  TaxelHealth health(profile_);
  Run(
      health, 100, [&](int i) { return Sphere(Centre(5).x_mm, Centre(5).y_mm, 2, 10.0 * std::min(i, 50) / 50); },
      [&](int, Scan& s) {
        const double full_scale = 0.6 * s.force_N[5];
        if (full_scale > 0.1) SetNormal(s, 5, full_scale, Area_m2()), s.flags[5] |= kTaxelSaturated;
      },
      [&](int i, const Scan& out) {
        EXPECT_EQ(health.left_out(), 0) << "scan " << i;
        EXPECT_TRUE(out.valid[5]);
      });
  EXPECT_EQ(health.masked_count(), 0);
}

TEST_F(TaxelHealthTest, TaxelStuckFromTheFirstScanIsLeftOutAtOnceAndMasked) {
  // No clean baseline: taxel 0 (a corner: the least spread) reads 2.5 N more from scan 0.
  TaxelHealth health(profile_);
  Run(health, 200, [&](int i) { return i < 100 ? Quiet() : Sphere(kMiddleX, kMiddleY, 3, 1.0); },
      [&](int, Scan& s) { SetNormal(s, 0, s.force_N[0] + 2.5, Area_m2()); },
      [&](int i, const Scan& out) {
        EXPECT_FALSE(out.valid[0]) << "scan " << i;  // left out from the first scan on
        EXPECT_TRUE(out.flags[0] & kTaxelMasked);
        for (int k = 1; k < 16; ++k) EXPECT_TRUE(out.valid[size_t(k)]) << "taxel " << k << " scan " << i;
      });
  EXPECT_EQ(health.fault(0), TaxelFault::kStuckHigh);
  EXPECT_EQ(health.masked_count(), 1);
  EXPECT_EQ(health.counters().recovered, 0);
  // The same at a middle taxel.
  TaxelHealth middle(profile_);
  Run(middle, 20, [&](int) { return Quiet(); }, [&](int, Scan& s) { SetNormal(s, 5, s.force_N[5] + 2.5, Area_m2()); });
  EXPECT_EQ(middle.fault(5), TaxelFault::kStuckHigh);
}

TEST_F(TaxelHealthTest, TaxelThatFailsMidPressAndRecoversIsMaskedThenBack) {
  // The example log's press: a sphere on the middle four taxels, held. Taxel 5 reads nothing
  // from scan 50 to 99, then works again.
  TaxelHealth health(profile_);
  int masked_at = -1, back_at = -1;
  Run(
      health, 250, [&](int i) { return Sphere(kMiddleX, kMiddleY, 5, 0.8 * std::min(i, 30) / 30); },
      [&](int i, Scan& s) {
        if (i >= 50 && i < 100) SetNormal(s, 5, s.force_N[5] - (Sphere(kMiddleX, kMiddleY, 5, 0.8))[3 * 5 + 2], Area_m2());
      },
      [&](int i, const Scan&) {
        if (masked_at < 0 && health.masked(5)) masked_at = i;
        if (masked_at >= 0 && back_at < 0 && !health.masked(5)) back_at = i;
      });
  // Masked within 0.1 s of failing (dead_after_s 0.05), back within 0.1 s after recover_after_s.
  EXPECT_GE(masked_at, 50);
  EXPECT_LE(masked_at, 60);
  EXPECT_GE(back_at, 100 + 19);
  EXPECT_LE(back_at, 100 + 30);
  EXPECT_EQ(health.counters().masked_dead, 1);
  EXPECT_EQ(health.counters().recovered, 1);
  EXPECT_EQ(health.masked_count(), 0);
}

TEST_F(TaxelHealthTest, StuckTaxelMidPressIsLeftOutAtOnceAndNoNeighbourIsJudgedDead) {
  // The example log's press; taxel 5 reads 2.5 N more from scan 50 on. Its neighbours carry
  // the press, so it is no isolated load, but it reads far more than the press implies.
  TaxelHealth health(profile_);
  Run(
      health, 150, [&](int i) { return Sphere(kMiddleX, kMiddleY, 5, 0.8 * std::min(i, 30) / 30); },
      [&](int i, Scan& s) {
        if (i >= 50) SetNormal(s, 5, s.force_N[5] + 2.5, Area_m2());
      },
      [&](int i, const Scan& out) {
        EXPECT_EQ(bool(out.valid[5]), i < 50) << "scan " << i;
        for (int k = 0; k < 16; ++k) EXPECT_TRUE(k == 5 || out.valid[size_t(k)]) << "taxel " << k << " scan " << i;
      });
  EXPECT_EQ(health.fault(5), TaxelFault::kStuckHigh);
  EXPECT_EQ(health.masked_count(), 1);
  EXPECT_EQ(health.counters().masked_dead, 0);
}

// `sedbridge decode`'s story of the press above: taxel 5 masked dead from about 0.5 s, back
// about 0.2 s after it works again; a healthy press tells that nothing was masked.
TEST_F(TaxelHealthTest, EpisodesSayWhichTaxelWasMaskedWhyAndWhen) {
  TaxelHealth health(profile_);
  TaxelHealthEpisodes episodes;
  Run(
      health, 250, [&](int i) { return Sphere(kMiddleX, kMiddleY, 5, 0.8 * std::min(i, 30) / 30); },
      [&](int i, Scan& s) {
        if (i >= 50 && i < 100) SetNormal(s, 5, s.force_N[5] - (Sphere(kMiddleX, kMiddleY, 5, 0.8))[3 * 5 + 2], Area_m2());
      },
      [&](int i, const Scan&) { episodes.Observe(health, 0.01 * i); });
  ASSERT_EQ(episodes.episodes().size(), 1u);
  const TaxelHealthEpisode& e = episodes.episodes()[0];
  EXPECT_EQ(e.taxel, 5);
  EXPECT_EQ(e.fault, TaxelFault::kDead);
  EXPECT_GE(e.from_s, 0.5 - 1e-9);
  EXPECT_LE(e.from_s, 0.6 + 1e-9);
  EXPECT_GE(e.to_s, 1.19 - 1e-9);
  EXPECT_LE(e.to_s, 1.3 + 1e-9);
  EXPECT_EQ(e.scans, std::lround((e.to_s - e.from_s) / 0.01));
  const std::string report = episodes.Report();
  EXPECT_NE(report.find("taxel health: 1 masking; masked at the end: none"), std::string::npos) << report;
  EXPECT_NE(report.find("  taxel 5 dead: masked 0."), std::string::npos) << report;

  TaxelHealth healthy(profile_);
  TaxelHealthEpisodes none;
  Run(healthy, 60, [&](int i) { return Sphere(kMiddleX, kMiddleY, 5, 0.8 * std::min(i, 30) / 30); }, {},
      [&](int i, const Scan&) { none.Observe(healthy, 0.01 * i); });
  EXPECT_EQ(none.Report(), "taxel health: no taxel masked\n");

  // Stuck from the first scan: still masked at the end.
  TaxelHealth stuck(profile_);
  TaxelHealthEpisodes open;
  Run(stuck, 40, [&](int) { return Quiet(); }, [&](int, Scan& s) { SetNormal(s, 3, 2.5, Area_m2()); },
      [&](int i, const Scan&) { open.Observe(stuck, 0.01 * i); });
  ASSERT_EQ(open.episodes().size(), 1u);
  EXPECT_EQ(open.episodes()[0].to_s, -1);
  EXPECT_NE(open.Report().find("masked at the end: 3 stuck high"), std::string::npos) << open.Report();
  EXPECT_NE(open.Report().find("s to the end ("), std::string::npos) << open.Report();
}

TEST_F(TaxelHealthTest, TwoAdjacentTaxelsFailing) {
  // Stuck: 5 and 6 both read 2.5 N from the first scan; each is the other's largest
  // neighbour, which the stuck test leaves out.
  TaxelHealth stuck(profile_);
  Run(stuck, 20, [&](int) { return Quiet(); }, [&](int, Scan& s) {
    SetNormal(s, 5, s.force_N[5] + 2.5, Area_m2());
    SetNormal(s, 6, s.force_N[6] + 2.5, Area_m2());
  });
  EXPECT_EQ(stuck.fault(5), TaxelFault::kStuckHigh);
  EXPECT_EQ(stuck.fault(6), TaxelFault::kStuckHigh);
  EXPECT_EQ(stuck.masked_count(), 2);
  // Dead: 5 and 6 read nothing beside a hard press on 9's centre (the taxel below 5). 5 is
  // masked; 6 (diagonal to the press) should read so little that the point loads that
  // explain the others disagree on it: not judged, as any healthy taxel is not. (Both taxels
  // of one side of a press between them could not be told from a press shifted to the other
  // side either.)
  TaxelHealth dead(profile_);
  const Eigen::VectorXd full = Sphere(Centre(9).x_mm, Centre(9).y_mm, 5, 3.0);
  Run(dead, 100, [&](int i) { return Sphere(Centre(9).x_mm, Centre(9).y_mm, 5, 3.0 * std::min(i, 30) / 30); },
      [&](int i, Scan& s) {
        const double share = std::min(i, 30) / 30.0;
        SetNormal(s, 5, s.force_N[5] - share * full[3 * 5 + 2], Area_m2());
        SetNormal(s, 6, s.force_N[6] - share * full[3 * 6 + 2], Area_m2());
      });
  EXPECT_EQ(dead.fault(5), TaxelFault::kDead);
  for (int k = 0; k < 16; ++k) {
    if (k != 5 && k != 6) {
      EXPECT_FALSE(dead.masked(k)) << "taxel " << k;
    }
  }
}

TEST_F(TaxelHealthTest, FrozenTaxelIsMaskedButNoiseFreeInputIsNot) {
  TaxelHealth health(profile_);
  Scan frozen_copy;
  Run(health, 60, [&](int) { return Quiet(); }, [&](int i, Scan& s) {
    if (i == 0) frozen_copy = s;
    for (int a = 0; a < 3; ++a) s.raw_counts[size_t(3 * 3 + a)] = frozen_copy.raw_counts[size_t(3 * 3 + a)];
  });
  EXPECT_EQ(health.fault(3), TaxelFault::kFrozen);
  EXPECT_EQ(health.masked_count(), 1);
  // A noise-free simulation repeats every unloaded reading: that is no frozen sensor.
  TaxelHealth clean(profile_);
  Scan still = MakeScan(Quiet());
  std::fill(still.raw_counts.begin(), still.raw_counts.end(), 1000);
  for (int i = 0; i < 100; ++i) clean.Apply(still);
  EXPECT_EQ(clean.masked_count(), 0);
}

TEST_F(TaxelHealthTest, DriftingBaselineIsReTaredWhileQuiet) {
  // Taxel 7's normal baseline creeps by 0.03 N (30 sigma) over 3 s with nothing touching,
  // then stays there for 3 s.
  TaxelHealth health(profile_);
  double late_sum_N = 0;
  Run(health, 600, [&](int) { return Quiet(); },
      [&](int i, Scan& s) { SetNormal(s, 7, s.force_N[7] + 0.03 * std::min(i, 300) / 300, Area_m2()); },
      [&](int i, const Scan& out) {
        if (i >= 500) late_sum_N += out.force_N[7];
      });
  EXPECT_GE(health.counters().retares, 1);
  EXPECT_EQ(health.masked_count(), 0);
  EXPECT_LT(std::abs(late_sum_N / 100), 0.012);  // read 0.03 N; the re-tare leaves < retare_sigma
  EXPECT_GT(health.retare_offset_N(7), 0.015);
}

TEST_F(TaxelHealthTest, DisabledChangesNothing) {
  SensorProfile p = profile_;
  p.taxel_health.enabled = false;
  TaxelHealth health(p);
  Scan s = MakeScan(Quiet());
  SetNormal(s, 5, 2.5, Area_m2());
  for (int i = 0; i < 10; ++i) EXPECT_EQ(&health.Apply(s), &s);
  EXPECT_EQ(health.masked_count(), 0);
}

}  // namespace
}  // namespace sedbridge::sensors
