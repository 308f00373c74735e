// The faulty-taxel set of the fidelity benchmark on a small subset of the rig's presses: the
// taxel under the contact dead or stuck high from the first scan, through taxel health.
#include "fidelity/faulty_taxel_fidelity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "bridge/contact_fe_step.h"
#include "common/resource_path.h"
#include "display/display_profile.h"
#include "sensors/calibration_press.h"

namespace sedbridge::fidelity {
namespace {

struct Rig {
  sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  std::vector<sensors::CalibrationPress> presses =
      sensors::LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), profile);
};

// The taxel nearest the press's object.
int TaxelUnder(const FidelityCase& press, const sensors::SensorProfile& profile) {
  int best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (int k = 0; k < profile.taxel_count; ++k) {
    const double dk = std::hypot(profile.taxels[size_t(k)].x_mm - press.primitive.x_mm,
                                 profile.taxels[size_t(k)].y_mm - press.primitive.y_mm);
    if (dk < d) d = dk, best = k;
  }
  return best;
}

TEST(FaultyTaxelFidelity, DeadTaxelReadsItsQuietNoiseAndStuckOneAConstantLoadOnTop) {
  const Rig rig;
  const FidelityCase press = FromCalibrationPress(rig.presses[3]);
  const int k = TaxelUnder(press, rig.profile);
  const size_t quiet = QuietScans(press);
  ASSERT_GE(quiet, 5u);
  ASSERT_LT(quiet, press.scans.size());
  const size_t peak = PeakScan(press, rig.profile);
  ASSERT_GT(press.scans[peak].force_N[size_t(k)], 0.05);  // loaded where it is healthy
  const FidelityCase dead = WithFaultyTaxel(press, rig.profile, k, TaxelFaultKind::kDead);
  const FidelityCase stuck = WithFaultyTaxel(press, rig.profile, k, TaxelFaultKind::kStuckHigh, 2.5);
  ASSERT_EQ(dead.scans.size(), press.scans.size());
  for (size_t i = 0; i < press.scans.size(); ++i) {
    const sensors::Scan& q = press.scans[i % quiet];
    EXPECT_EQ(dead.scans[i].force_N[size_t(k)], q.force_N[size_t(k)]) << i;
    EXPECT_EQ(dead.scans[i].shear_x_Pa[size_t(k)], q.shear_x_Pa[size_t(k)]) << i;
    EXPECT_NEAR(stuck.scans[i].force_N[size_t(k)], q.force_N[size_t(k)] + 2.5, 1e-12) << i;
    for (int j = 0; j < rig.profile.taxel_count; ++j) {
      if (j != k) {
        EXPECT_EQ(dead.scans[i].force_N[size_t(j)], press.scans[i].force_N[size_t(j)]);
      }
    }
  }
}

TEST(FaultyTaxelFidelity, TaxelUnderTheContactDeadOrStuckStaysWithinTheTargets) {
  const Rig rig;
  FidelityBenchmark bench("B", rig.profile, display::LoadNamedDisplayProfile("suction_4x4"), "");
  // Spheres of 5 and 8 mm and a rod.
  std::vector<FidelityCase> presses;
  for (int i : {3, 6, 14}) presses.push_back(FromCalibrationPress(rig.presses[size_t(i)]));
  const bridge::BridgeConfig config = bridge::LoadBridgeConfig(bridge::DefaultBridgeConfigPath());
  for (const FidelityCase& press : presses) {
    FaultyTaxelOptions options;
    options.taxels = {TaxelUnder(press, rig.profile)};
    int progress_calls = 0;
    options.progress = [&](size_t done, size_t all, const std::vector<FaultyTaxelRow>& rows) {
      ++progress_calls;
      EXPECT_EQ(done, 1u);
      EXPECT_EQ(all, 1u);
      EXPECT_EQ(rows.size(), 2u);
    };
    const std::vector<FaultyTaxelRow> rows =
        RunFaultyTaxelSet(bench, {press}, rig.profile, bridge::ReconstructionOptionsOf(config), options);
    EXPECT_EQ(progress_calls, 1);
    ASSERT_EQ(rows.size(), 2u);
    for (const FaultyTaxelRow& r : rows) {
      SCOPED_TRACE(press.name + " taxel " + std::to_string(r.taxel) + " " + ToString(r.kind) + ": " + r.health);
      EXPECT_TRUE(r.healthy_within);
      EXPECT_TRUE(r.row.truth_valid);
      EXPECT_TRUE(r.within) << "peak ratio " << r.row.recon_error.peak_ratio << ", L2 " << r.row.recon_error.rel_l2
                            << ", offset " << r.row.recon_error.peak_offset_mm << " mm; " << r.row.recon_press;
      // By taxel health, or by the fit (the lone misfit: a dead taxel under a rod, which the
      // dead test does not judge, one point load not explaining a rod's ring).
      EXPECT_TRUE(r.taxel_left_out_at_peak || r.fit_use_at_peak == contact::TaxelUse::kLoneMisfit);
      EXPECT_GT(r.quiet_scans, 0);
      if (r.kind == TaxelFaultKind::kStuckHigh) {
        EXPECT_EQ(r.quiet_scans_driving, 0);
        EXPECT_EQ(r.healthy_quiet_scans_driving, 0);
      }
    }
    const FaultyTaxelTally dead = Tally(rows, TaxelFaultKind::kDead);
    EXPECT_EQ(dead.rows, 1);
    EXPECT_EQ(dead.scored, 1);
  }
}

// Dead taxels the fit took within max_rms_sigma, which a punch or a pair then absorbed, as the
// benchmark scores them: under a 6 x 6 mm punch's edge (press_22, taxels 5 and 10), a 5 x 2
// mm punch's (press_29, taxel 4), under one sphere of a pair (press_24, taxels 7 and 10),
// and off a 5 mm sphere (press_03, corner taxel 1: read as a 2.6 mm punch before). Each
// stays within the three targets, with the taxel left out at the peak.
TEST(FaultyTaxelFidelity, DeadTaxelUnderAPunchEdgeOrOneSphereOfAPairStaysWithinTheTargets) {
  const Rig rig;
  FidelityBenchmark bench("B", rig.profile, display::LoadNamedDisplayProfile("suction_4x4"), "");
  const bridge::BridgeConfig config = bridge::LoadBridgeConfig(bridge::DefaultBridgeConfigPath());
  struct Case {
    int press;
    std::vector<int> taxels;
  };
  for (const Case& c : {Case{22, {5, 10}}, Case{29, {4}}, Case{24, {7, 10}}, Case{3, {1}}}) {
    FaultyTaxelOptions options;
    options.taxels = c.taxels;
    options.kinds = {TaxelFaultKind::kDead};
    const std::vector<FaultyTaxelRow> rows = RunFaultyTaxelSet(
        bench, {FromCalibrationPress(rig.presses[size_t(c.press)])}, rig.profile, bridge::ReconstructionOptionsOf(config),
        options);
    ASSERT_EQ(rows.size(), c.taxels.size());
    for (const FaultyTaxelRow& r : rows) {
      SCOPED_TRACE(r.press + " taxel " + std::to_string(r.taxel) + " dead: " + r.health);
      EXPECT_TRUE(r.healthy_within);
      EXPECT_TRUE(r.within) << "peak ratio " << r.row.recon_error.peak_ratio << ", L2 " << r.row.recon_error.rel_l2
                            << ", offset " << r.row.recon_error.peak_offset_mm << " mm; " << r.row.recon_press;
      EXPECT_TRUE(r.taxel_left_out_at_peak || r.fit_use_at_peak == contact::TaxelUse::kLoneMisfit);
    }
  }
}

}  // namespace
}  // namespace sedbridge::fidelity
