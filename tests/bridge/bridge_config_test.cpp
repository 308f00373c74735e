#include "bridge/bridge_config.h"

#include <gtest/gtest.h>

#include "bridge/contact_fe_step.h"
#include "bridge/latency_stats.h"
#include "bridge/pipeline_status.h"
#include "common/config_error.h"
#include "common/resource_path.h"
#include "common/schema_keys.h"
#include "tests/common/readme_keys.h"

namespace sedbridge::bridge {
namespace {

TEST(BridgeConfig, ShippedDefaultLoadsWithEveryKey) {
  const BridgeConfig c = LoadBridgeConfig(DefaultBridgeConfigPath());
  EXPECT_EQ(c.sensor_profile, "uskin_4x4");
  EXPECT_EQ(c.model, "B");
  EXPECT_EQ(c.preset, "fast");
  EXPECT_EQ(c.fe_step, FeStepKind::kContact);
  EXPECT_TRUE(c.face_contact);
  EXPECT_TRUE(c.two_contacts);
  EXPECT_TRUE(c.finite_rods);
  EXPECT_DOUBLE_EQ(c.contact_tolerance, 1e-5);
  EXPECT_EQ(c.display_profile, "suction_4x4");
  EXPECT_DOUBLE_EQ(c.status_Hz, 10);
  EXPECT_DOUBLE_EQ(c.conditioning.noise_floor_Pa, 150);
  EXPECT_EQ(c.lcm.channels.command, "DISPLAY_COMMAND");
}

TEST(BridgeConfig, EmptyFileGivesDefaults) {
  const BridgeConfig c = ParseBridgeConfig("", "empty.yaml");
  EXPECT_EQ(c.model, "B");
  EXPECT_DOUBLE_EQ(c.registration.scale, 1.0);
  EXPECT_TRUE(c.face_contact);
  EXPECT_FALSE(ParseBridgeConfig("fe: {face_contact: false}\n", "nodes.yaml").face_contact);
  EXPECT_TRUE(c.two_contacts);
  EXPECT_FALSE(ParseBridgeConfig("fe: {two_contacts: false}\n", "single.yaml").two_contacts);
  EXPECT_FALSE(ParseBridgeConfig("fe: {finite_rods: false}\n", "crossing.yaml").finite_rods);
  EXPECT_DOUBLE_EQ(c.contact_tolerance, 1e-5);
  EXPECT_DOUBLE_EQ(ParseBridgeConfig("fe: {contact_tolerance: 1.0e-8}\n", "tight.yaml").contact_tolerance, 1e-8);
  // The leader press's options follow the key.
  EXPECT_TRUE(contact::LeaderComplianceOptions("").face_samples);
  EXPECT_FALSE(contact::LeaderComplianceOptions("", false).face_samples);
}

TEST(BridgeConfig, ReadsRegistrationAndTraction) {
  const BridgeConfig c = ParseBridgeConfig(
      "registration: {offset_mm: [1.5, -2], rotation_deg: 30, scale: 0.8}\n"
      "traction: {kernel_sigma_mm: 1.2, invalid_taxels: zero, max_invalid_fraction: 0.25, nodal_load: consistent}\n"
      "rates: {status_Hz: 5, tick_Hz: 500}\n",
      "t.yaml");
  EXPECT_DOUBLE_EQ(c.registration.offset_mm.x(), 1.5);
  EXPECT_DOUBLE_EQ(c.registration.rotation_deg, 30);
  EXPECT_DOUBLE_EQ(c.registration.scale, 0.8);
  EXPECT_DOUBLE_EQ(c.traction.kernel_sigma_mm, 1.2);
  EXPECT_DOUBLE_EQ(c.conditioning.fill_sigma_mm, 1.2);
  EXPECT_EQ(c.conditioning.invalid, InvalidTaxelPolicy::kZero);
  EXPECT_EQ(c.traction.nodal_load, NodalLoad::kConsistent);
  EXPECT_EQ(ParseBridgeConfig("", "e.yaml").traction.nodal_load, NodalLoad::kLumped);
  EXPECT_DOUBLE_EQ(c.tick_Hz, 500);
}

// The error of parsing `yaml` names `where` (file:line[:column]) and `key`.
void ExpectErrorNaming(const std::string& yaml, const std::string& file, const std::string& where,
                       const std::string& key) {
  try {
    ParseBridgeConfig(yaml, file);
    FAIL() << "no error for " << yaml;
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(where), std::string::npos) << what;
    EXPECT_NE(what.find(key), std::string::npos) << what;
  }
}

TEST(BridgeConfig, UnknownKeyNamesFileLineColumn) {
  ExpectErrorNaming("fe:\n  model: B\n  presett: fast\n", "bridge.yaml", "bridge.yaml:3:3", "presett");
  EXPECT_THROW(ParseBridgeConfig("registration: {scale: -1}\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("fe: {preset: turbo}\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("lcm: {channels: {command: lower}}\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("bogus: 1\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("fe: {preset: accurate, step: reduced}\n", "b.yaml"), config::ConfigError);
  EXPECT_EQ(ParseBridgeConfig("fe: {step: reduced}\n", "b.yaml").fe_step, FeStepKind::kReduced);
  ExpectErrorNaming("fe:\n  contact_tolerance: 0.5\n", "loose.yaml", "loose.yaml:2:", "contact_tolerance");
  EXPECT_THROW(ParseBridgeConfig("fe: {contact_tolerance: 0}\n", "b.yaml"), config::ConfigError);
  EXPECT_EQ(ParseBridgeConfig("fe: {merkel_region: display}\n", "b.yaml").merkel_region, MerkelRegion::kDisplay);
  EXPECT_EQ(ParseBridgeConfig("fe: {model: B}\n", "b.yaml").merkel_region, MerkelRegion::kLayer);
  ExpectErrorNaming("fe:\n  merkel_region: pad\n", "region.yaml", "region.yaml:2:", "merkel_region");
  EXPECT_EQ(ParseBridgeConfig("fe: {model: B}\n", "b.yaml").radius_tracking, RadiusTracking::kPosterior);
  const BridgeConfig steady = ParseBridgeConfig("fe: {radius_tracking: steady}\n", "b.yaml");
  EXPECT_EQ(steady.radius_tracking, RadiusTracking::kSteady);
  EXPECT_FALSE(ReconstructionOptionsOf(steady).radius_track_posterior);
  EXPECT_TRUE(ReconstructionOptionsOf(ParseBridgeConfig("fe: {model: B}\n", "b.yaml")).radius_track_posterior);
  ExpectErrorNaming("fe:\n  radius_tracking: kalman\n", "tracking.yaml", "tracking.yaml:2:", "radius_tracking");
}

TEST(BridgeConfig, DisplayRenderingIsInverseOrCurveAndItsErrorsNameFileLineColumn) {
  EXPECT_FALSE(ParseBridgeConfig("display: {profile: pin_6x4}\n", "b.yaml").display_rendering.has_value());
  EXPECT_EQ(ParseBridgeConfig("display: {profile: pin_6x4, rendering: curve}\n", "b.yaml").display_rendering,
            RenderingMethod::kCurve);
  EXPECT_EQ(ParseBridgeConfig("display: {profile: pin_6x4, rendering: inverse}\n", "b.yaml").display_rendering,
            RenderingMethod::kInverse);
  ExpectErrorNaming("display:\n  profile: pin_6x4\n  rendering: inverted\n", "bridge.yaml", "bridge.yaml:3:14",
                    "inverse, curve");
  ExpectErrorNaming("display:\n  profile: pin_6x4\n  rendering: [inverse]\n", "bridge.yaml", "bridge.yaml:3:14",
                    "rendering");
  // The inverse renderer needs the whole layer under the display.
  ExpectErrorNaming("fe: {merkel_region: display}\ndisplay:\n  profile: pin_6x4\n  rendering: inverse\n", "bridge.yaml",
                    "bridge.yaml:4:14", "merkel_region");
}

// The renderer's iterations a scan: 8 unless said, 1..200, a bad value named where it stands.
TEST(BridgeConfig, RenderIterationsAreBoundedAndNamedWhereTheyStand) {
  EXPECT_EQ(ParseBridgeConfig("display: {profile: suction_4x4}\n", "b.yaml").display_render_iterations, 3);
  EXPECT_EQ(ParseBridgeConfig("display: {profile: suction_4x4, render_iterations: 2}\n", "b.yaml").display_render_iterations, 2);
  EXPECT_EQ(ParseBridgeConfig("display: {profile: suction_4x4}\n", "b.yaml").display_render_evaluations, 0);
  EXPECT_EQ(ParseBridgeConfig("display: {profile: pin_8x8, render_evaluations: 2}\n", "b.yaml").display_render_evaluations, 2);
  ExpectErrorNaming("display:\n  profile: suction_4x4\n  render_evaluations: -1\n", "bridge.yaml", "bridge.yaml:3:23",
                    "render_evaluations");
  ExpectErrorNaming("display:\n  profile: suction_4x4\n  render_iterations: 0\n", "bridge.yaml", "bridge.yaml:3:22",
                    "render_iterations");
  ExpectErrorNaming("display:\n  profile: suction_4x4\n  render_iterations: 2.5\n", "bridge.yaml", "bridge.yaml:3:22",
                    "render_iterations");
}

TEST(BridgeConfig, LcmSectionIsReadThroughItsSchema) {
  const BridgeConfig c = ParseBridgeConfig("lcm:\n  log: out/x.lcmlog\n  channels: {contact: LEFT_CONTACT}\n", "b.yaml");
  EXPECT_EQ(c.lcm.log_path, "out/x.lcmlog");
  EXPECT_EQ(c.lcm.channels.contact, "LEFT_CONTACT");
  EXPECT_EQ(c.lcm.channels.sed, "FINGERTIP_SED");
  EXPECT_EQ(c.lcm.url, lcm_io::kDefaultLcmUrl);
  try {
    ParseBridgeConfig("lcm:\n  channels:\n    status: bridge_status\n", "b.yaml");
    FAIL() << "lower-case channel accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "b.yaml:3:13: channel 'bridge_status' must be UPPER_SNAKE");
  }
}

TEST(BridgeConfig, RatesAreBounded) {
  // Hostile inputs: tick_Hz 0.1 held 20 kPa for 10 s; status_Hz 1e-30 overflowed the period.
  EXPECT_THROW(ParseBridgeConfig("rates: {tick_Hz: 0.1}\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("rates: {tick_Hz: 1e9}\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("rates: {status_Hz: 1e-30}\n", "b.yaml"), config::ConfigError);
  EXPECT_THROW(ParseBridgeConfig("rates: {status_Hz: .nan}\n", "b.yaml"), config::ConfigError);
  try {
    ParseBridgeConfig("rates:\n  tick_Hz: 0.1\n", "b.yaml");
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "b.yaml:2:12: 'tick_Hz' must be in [50, 10000] Hz (got 0.1)");
  }
  EXPECT_DOUBLE_EQ(ParseBridgeConfig("rates: {tick_Hz: 50, status_Hz: 0.1}\n", "b.yaml").tick_Hz, 50);
  EXPECT_THROW(ParseBridgeConfig("rates: {tick_Hz: 100, tick_Hz: 0.1}\n", "b.yaml"), config::ConfigError);
}

TEST(LatencyStats, PercentilesWindowAndRun) {
  LatencyStats s;
  for (int i = 1; i <= 100; ++i) s.Add(i * 1000);  // 1..100 ms
  LatencySummary w = s.Window();
  EXPECT_EQ(w.count, 100);
  EXPECT_DOUBLE_EQ(w.p50_ms, 50);
  EXPECT_DOUBLE_EQ(w.p99_ms, 99);
  EXPECT_DOUBLE_EQ(w.max_ms, 100);
  s.ResetWindow();
  EXPECT_EQ(s.Window().count, 0);
  s.Add(-5);  // clocks that disagree count as 0
  EXPECT_EQ(s.Run().count, 101);
  EXPECT_DOUBLE_EQ(s.Run().max_ms, 100);
}

TEST(LatencyStats, BoundedMemoryKeepsAUniformSubsample) {
  LatencyStats s(64);
  for (int i = 0; i < 10000; ++i) s.Add(i % 100 * 1000);
  const LatencySummary r = s.Run();
  EXPECT_EQ(r.count, 10000);
  EXPECT_NEAR(r.p50_ms, 50, 10);
  EXPECT_DOUBLE_EQ(r.max_ms, 99);
}

TEST(BridgeConfig, FeStepKindNamesRoundTrip) {
  for (FeStepKind k : {FeStepKind::kScene, FeStepKind::kReduced, FeStepKind::kContact})
    EXPECT_EQ(FeStepKindFromString(ToString(k)), k);
  EXPECT_THROW(FeStepKindFromString("exact"), std::invalid_argument);
}

TEST(PipelineStatus, ReasonsAndStatesHaveNames) {
  EXPECT_STREQ(ToString(FaultState::kDegraded), "degraded");
  EXPECT_EQ(static_cast<int>(FaultState::kFault), 2);  // the BRIDGE_STATUS wire value
  // One name per reason, in enum order (RejectCounters indexes by the enum).
  ASSERT_EQ(config::AllNames<RejectReason>().size(), size_t(kNumRejectReasons));
  for (int i = 0; i < kNumRejectReasons; ++i)
    EXPECT_EQ(NamesOf(RejectReason{}).at(size_t(i)).first, static_cast<RejectReason>(i));
  RejectCounters c;
  EXPECT_EQ(FormatRejectCounters(c), "none");
  ++c[RejectReason::kTooManyInvalidTaxels];
  ++c[RejectReason::kFeStepFailed];
  ++c[RejectReason::kFeStepFailed];
  EXPECT_EQ(c.total(), 3);
  EXPECT_EQ(FormatRejectCounters(c), "too_many_invalid_taxels 1, fe_step_failed 2");
}

}  // namespace
}  // namespace sedbridge::bridge

// The key table of config/bridge/README.md and BridgeConfig::Serialize name the same keys.
namespace sedbridge::bridge {
namespace {

TEST(BridgeConfig, ReadmeTableNamesEverySchemaKeyAndNoOther) {
  test_util::ExpectReadmeNamesSchemaKeys(config::ResolveResource("config/bridge/README.md"), config::SchemaKeys<BridgeConfig>());
}

}  // namespace
}  // namespace sedbridge::bridge
