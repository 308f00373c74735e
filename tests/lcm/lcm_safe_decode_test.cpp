// SafeDecode: no LCM bytes can make a reader allocate beyond the message's own size.

#include "lcm/lcm_safe_decode.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_contact_estimate.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"
#include "sedbridge/lcmt_tactile_scan.hpp"
#include "lcm_test_messages.h"

namespace sedbridge::lcm_io {
namespace {

using test_messages::Encode;

void PutInt32(std::vector<uint8_t>& b, size_t at, uint32_t v) {
  b[at] = uint8_t(v >> 24);
  b[at + 1] = uint8_t(v >> 16);
  b[at + 2] = uint8_t(v >> 8);
  b[at + 3] = uint8_t(v);
}

lcmt_display_command Command(int n) {
  lcmt_display_command m{};
  m.utime = 1;
  m.sequence = 2;
  m.display_id = "suction_4x4";
  m.unit = "kPa";
  m.num_actuators = n;
  m.value.assign(size_t(n), 1.5f);
  m.shutdown = 1;
  return m;
}

TEST(LcmSafeDecode, The160BytePacketWithABillionActuatorsIsRejectedWithoutAllocating) {
  // A hostile input: this packet made display-view allocate 3.9 GB and crash.
  std::vector<uint8_t> b = Encode(Command(20));
  // fingerprint 8 + 4 int64 + "suction_4x4" (4 + 12) + "kPa" (4 + 4) -> num_actuators at 64.
  const size_t at = 8 + 32 + 16 + 8;
  PutInt32(b, at, 1000000000u);
  b.resize(160);
  ASSERT_EQ(b.size(), 160u);
  lcmt_display_command m;
  EXPECT_FALSE(WireSizesFit<lcmt_display_command>(b.data(), b.size()));
  EXPECT_FALSE(SafeDecode(b.data(), b.size(), &m));
  EXPECT_LE(m.value.capacity(), 160u);  // nothing was sized from the count
  // The untouched message decodes.
  const std::vector<uint8_t> good = Encode(Command(20));
  ASSERT_TRUE(SafeDecode(good.data(), good.size(), &m));
  EXPECT_EQ(m.value.size(), 20u);
  EXPECT_EQ(m.display_id, "suction_4x4");
  EXPECT_TRUE(m.shutdown);
}

TEST(LcmSafeDecode, ContactEstimateDecodesAndItsTaxelCountIsChecked) {
  lcmt_contact_estimate c{};
  c.utime = 7;
  c.shape = 1;
  c.radius_mm = 12.5f;
  c.normal_force_N = 0.75f;
  c.num_taxels = 16;
  c.taxel_used.assign(16, 1);
  c.num_taxels_used = 16;
  const std::vector<uint8_t> good = Encode(c);
  lcmt_contact_estimate m;
  ASSERT_TRUE(SafeDecode(good.data(), good.size(), &m));
  EXPECT_EQ(m.taxel_used.size(), 16u);
  EXPECT_FLOAT_EQ(m.radius_mm, 12.5f);
  for (size_t n = 0; n < good.size(); ++n) EXPECT_FALSE(SafeDecode(good.data(), n, &m)) << "truncated at " << n;
  // fingerprint 8 + 2 int64 + shape 1 + 12 floats + residual 4 + fallback 1 + indentation 4 -> num_taxels at 82.
  std::vector<uint8_t> huge = good;
  PutInt32(huge, 82, 1000000000u);
  EXPECT_FALSE(SafeDecode(huge.data(), huge.size(), &m));
}

TEST(LcmSafeDecode, NegativeCountsTruncationAndTrailingBytesAreRejected) {
  const std::vector<uint8_t> good = Encode(Command(4));
  lcmt_display_command m;
  for (size_t n = 0; n < good.size(); ++n) EXPECT_FALSE(SafeDecode(good.data(), n, &m)) << "truncated at " << n;
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_FALSE(SafeDecode(longer.data(), longer.size(), &m));
  std::vector<uint8_t> negative = good;
  PutInt32(negative, 64, 0xFFFFFFFFu);  // -1
  EXPECT_FALSE(SafeDecode(negative.data(), negative.size(), &m));
  std::vector<uint8_t> huge_string = good;
  PutInt32(huge_string, 40, 0x7FFFFFFFu);  // display_id length
  EXPECT_FALSE(SafeDecode(huge_string.data(), huge_string.size(), &m));
  EXPECT_FALSE(SafeDecode<lcmt_display_command>(nullptr, 0, &m));
}

TEST(LcmSafeDecode, EveryTypeRoundTripsAndRejectsInflatedCounts) {
  lcmt_merkel_sed sed{};
  sed.model_id = "B";
  sed.num_vertices = 3;
  sed.num_positions = 3;
  sed.x_mm = sed.y_mm = sed.z_mm = {1, 2, 3};
  sed.num_ids = 2;
  sed.vertex_id = {7, 8};
  sed.sed_Pa = {4, 5, 6};
  lcmt_tactile_scan scan{};
  scan.sensor_id = "uskin_4x4";
  scan.num_taxels = 2;
  scan.raw_counts = {1, 2};
  scan.pressure_kPa = {0.5f, 0.25f};
  scan.valid = {1, 0};
  lcmt_bridge_status status{};
  status.fault_message = "degraded";
  status.num_reject_reasons = 2;
  status.reject_reason = {"wrong_taxel_count", "missing_shear"};
  status.scans_rejected = {3, 0};
  status.num_taxels = 2;
  status.taxel_health = {0, 2};
  lcmt_sa1_rate_estimate sa1{};
  sa1.display_id = "x";
  sa1.num_sites = 2;
  sa1.sed_Pa = {1, 2};
  sa1.rate_Hz = {3, 4};

  auto check = [](const auto& msg, std::vector<size_t> count_offsets) {
    using Msg = std::decay_t<decltype(msg)>;
    const std::vector<uint8_t> b = Encode(msg);
    Msg out;
    ASSERT_TRUE(SafeDecode(b.data(), b.size(), &out));
    EXPECT_EQ(Encode(out), b);
    for (size_t at : count_offsets) {
      std::vector<uint8_t> bad = b;
      PutInt32(bad, at, 1000000000u);
      EXPECT_FALSE(SafeDecode(bad.data(), bad.size(), &out)) << "count at " << at;
    }
  };
  // Offsets: fingerprint 8, then the fields in .lcm order.
  check(sed, {8 + 16 + 6, 8 + 16 + 6 + 4, 8 + 16 + 6 + 8 + 36});
  check(scan, {8 + 16 + 14, 8 + 16 + 14 + 4 + 18});  // num_taxels, num_shear
  check(status, {});
  // A negative reject-reason count (int8 at 8 + 8 + 28 + 4 + 4 + 40) is refused.
  {
    std::vector<uint8_t> bad = Encode(status);
    bad[8 + 8 + 28 + 4 + 4 + 40] = 0xff;
    lcmt_bridge_status out;
    EXPECT_FALSE(SafeDecode(bad.data(), bad.size(), &out));
  }
  // The per-taxel health count: after it come 2 bytes of states, 4 int32 and 5 int64.
  {
    std::vector<uint8_t> bad = Encode(status);
    PutInt32(bad, bad.size() - (4 + 2 + 16 + 40), 1000000000u);
    lcmt_bridge_status out;
    EXPECT_FALSE(SafeDecode(bad.data(), bad.size(), &out));
  }
  check(sa1, {8 + 8 + 6});
}

TEST(LcmSafeDecode, ATactileScanFromBeforeTheShearFieldsDecodesWithoutShear) {
  lcmt_tactile_scan scan{};
  scan.utime = 17;
  scan.sensor_id = "uskin_4x4";
  scan.num_taxels = 2;
  scan.raw_counts = {1, 2};
  scan.pressure_kPa = {0.5f, 0.25f};
  scan.valid = {1, 0};
  // The earlier version's bytes: its fingerprint, the same fields up to `valid`, no more.
  std::vector<uint8_t> old = Encode(scan);
  old.resize(old.size() - 4);  // num_shear
  const uint8_t fingerprint[8] = {0x3a, 0xfe, 0x5a, 0x31, 0xff, 0x1b, 0xfe, 0x44};
  std::copy(fingerprint, fingerprint + 8, old.begin());
  lcmt_tactile_scan out;
  ASSERT_TRUE(SafeDecode(old.data(), old.size(), &out));
  EXPECT_EQ(out.utime, 17);
  EXPECT_EQ(out.pressure_kPa, scan.pressure_kPa);
  EXPECT_EQ(out.num_shear, 0);
  EXPECT_TRUE(out.shear_x_kPa.empty());
  // Still checked as strictly: a trailing byte, a short buffer or an inflated count is refused.
  std::vector<uint8_t> bad = old;
  bad.push_back(0);
  EXPECT_FALSE(SafeDecode(bad.data(), bad.size(), &out));
  bad = old;
  bad.pop_back();
  EXPECT_FALSE(SafeDecode(bad.data(), bad.size(), &out));
  bad = old;
  PutInt32(bad, 8 + 16 + 14, 1000000000u);
  EXPECT_FALSE(SafeDecode(bad.data(), bad.size(), &out));
  // Today's fingerprint on the old layout is not today's message.
  std::vector<uint8_t> today = Encode(scan);
  today.resize(today.size() - 4);
  EXPECT_FALSE(SafeDecode(today.data(), today.size(), &out));
}

TEST(LcmSafeDecode, RandomCorruptionNeverDecodesMoreThanTheBytesHold) {
  std::mt19937 rng(13);
  const std::vector<uint8_t> good = Encode(Command(16));
  int accepted = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<uint8_t> b = good;
    const int flips = 1 + int(rng() % 4);
    for (int k = 0; k < flips; ++k) b[rng() % b.size()] = uint8_t(rng());
    if (rng() % 4 == 0) b.resize(rng() % (b.size() + 1));
    lcmt_display_command m;
    if (SafeDecode(b.data(), b.size(), &m)) {
      ++accepted;
      ASSERT_EQ(m.value.size(), size_t(m.num_actuators));
      ASSERT_LE(m.value.size() * 4, b.size());
    }
  }
  EXPECT_GT(accepted, 0);  // flips in the values still decode: the check is not vacuous
}

}  // namespace
}  // namespace sedbridge::lcm_io
