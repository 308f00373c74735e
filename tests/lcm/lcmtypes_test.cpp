// The generated message types: encode/decode round trips and type safety of decoding.

#include <gtest/gtest.h>

#include <vector>

#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_contact_estimate.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"
#include "sedbridge/lcmt_tactile_scan.hpp"
#include "lcm_test_messages.h"

namespace sedbridge {
namespace {

using lcm_io::test_messages::Encode;

TEST(LcmTypes, TactileScanRoundTrip) {
  lcmt_tactile_scan m;
  m.utime = 123;
  m.sequence = 7;
  m.sensor_id = "taxels_4x4";
  m.num_taxels = 3;
  m.raw_counts = {10, 20, 4095};
  m.pressure_kPa = {0.5f, 1.5f, 40.0f};
  m.valid = {true, true, false};
  m.num_shear = 0;
  const auto buf = Encode(m);
  lcmt_tactile_scan d;
  ASSERT_EQ(d.decode(buf.data(), 0, buf.size()), static_cast<int>(buf.size()));
  EXPECT_EQ(d.sensor_id, "taxels_4x4");
  EXPECT_EQ(d.raw_counts[2], 4095);
  EXPECT_FALSE(d.valid[2]);
}

TEST(LcmTypes, MerkelSedWithIdsOnly) {
  lcmt_merkel_sed m;
  m.utime = 5;
  m.model_id = "B";
  m.num_vertices = 2;
  m.num_positions = 0;
  m.num_ids = 2;
  m.vertex_id = {11, 42};
  m.sed_Pa = {100.0f, 250.0f};
  m.max_sed_Pa = 250.0f;
  const auto buf = Encode(m);
  lcmt_merkel_sed d;
  ASSERT_GT(d.decode(buf.data(), 0, buf.size()), 0);
  EXPECT_EQ(d.vertex_id[1], 42);
  EXPECT_TRUE(d.x_mm.empty());
  EXPECT_FLOAT_EQ(d.max_sed_Pa, 250.0f);
}

TEST(LcmTypes, StatusAndSa1RoundTrip) {
  lcmt_bridge_status s{};
  s.utime = 1;
  s.latency_p99_ms = 3.5f;
  s.scans_dropped = 12;
  s.fault_state = 2;
  s.fault_message = "solver diverged";
  s.num_taxels = 3;
  s.taxel_health = {0, 1, 4};
  s.taxels_stuck = 1;
  s.taxels_drifting = 1;
  s.taxel_scans_left_out = 250;
  s.taxel_retares = 2;
  s.model_inadequate_scans = 7;
  lcmt_bridge_status ds;
  const auto buf = Encode(s);
  ASSERT_GT(ds.decode(buf.data(), 0, buf.size()), 0);
  EXPECT_EQ(ds.fault_message, "solver diverged");
  EXPECT_EQ(ds.scans_dropped, 12);
  EXPECT_EQ(ds.taxel_health, (std::vector<int8_t>{0, 1, 4}));
  EXPECT_EQ(ds.taxels_stuck, 1);
  EXPECT_EQ(ds.taxels_drifting, 1);
  EXPECT_EQ(ds.taxel_scans_left_out, 250);
  EXPECT_EQ(ds.taxel_retares, 2);
  EXPECT_EQ(ds.model_inadequate_scans, 7);

  lcmt_sa1_rate_estimate r;
  r.utime = 2;
  r.display_id = "suction_4x4";
  r.num_sites = 1;
  r.sed_Pa = {10.0f};
  r.rate_Hz = {3.0f};
  lcmt_sa1_rate_estimate dr;
  const auto rbuf = Encode(r);
  ASSERT_GT(dr.decode(rbuf.data(), 0, rbuf.size()), 0);
  EXPECT_FLOAT_EQ(dr.rate_Hz[0], 3.0f);
}

TEST(LcmTypes, ContactEstimateRoundTripWithTheTaxelsUsed) {
  lcmt_contact_estimate m{};
  m.utime = 9;
  m.shape = 1;
  m.normal_force_N = 0.5f;
  m.indentation_mm = 0.2f;
  m.num_taxels = 4;
  m.taxel_used = {1, 0, 2, 1};
  m.num_taxels_used = 3;
  m.model_inadequate = 1;
  m.width_mm = 2.5f;
  const auto buf = Encode(m);
  lcmt_contact_estimate d;
  ASSERT_EQ(d.decode(buf.data(), 0, buf.size()), static_cast<int>(buf.size()));
  EXPECT_FLOAT_EQ(d.indentation_mm, 0.2f);
  EXPECT_EQ(d.taxel_used, (std::vector<int8_t>{1, 0, 2, 1}));
  EXPECT_EQ(d.num_taxels_used, 3);
  EXPECT_EQ(d.model_inadequate, 1);
  EXPECT_EQ(d.width_mm, 2.5f);
}

TEST(LcmTypes, DecodingTheWrongTypeFails) {
  lcmt_display_command c;
  c.utime = 1;
  c.num_actuators = 1;
  c.value = {1.0f};
  const auto buf = Encode(c);
  lcmt_merkel_sed wrong;
  EXPECT_LT(wrong.decode(buf.data(), 0, buf.size()), 0);  // fingerprint mismatch
  lcmt_display_command truncated;
  EXPECT_LT(truncated.decode(buf.data(), 0, buf.size() - 3), 0);
}

}  // namespace
}  // namespace sedbridge
