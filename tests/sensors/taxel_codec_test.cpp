#include "sensors/taxel_codec.h"

#include <gtest/gtest.h>

#include <random>

namespace sedbridge::sensors {
namespace {

SensorProfile Shipped(const std::string& name) { return LoadSensorProfile(ResolveProfilePath(name)); }

class ProfileRoundTripTest : public ::testing::TestWithParam<std::string> {};

// Encode random readings of every channel and decode them back: the one description must
// mean the same thing both ways.
TEST_P(ProfileRoundTripTest, EncodeThenDecodeGivesTheSameReadings) {
  const SensorProfile p = Shipped(GetParam());
  const TaxelCodec codec(p);
  std::mt19937 rng(42);
  std::uniform_int_distribution<int64_t> value(p.RawMin(), p.RawMax());
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<int32_t> channels(p.channel_count());
    for (auto& c : channels) c = static_cast<int32_t>(value(rng));
    const std::vector<Frame> frames = codec.EncodeScan(channels, trial, 1000 + trial);
    ASSERT_EQ(static_cast<int>(frames.size()), p.layout.frame_count);
    std::vector<int32_t> decoded(p.channel_count(), -999);
    std::vector<int> seen_slots;
    for (const Frame& f : frames) {
      EXPECT_TRUE(IsWellFormed(f));
      DecodedFrame d;
      ASSERT_EQ(codec.Decode(f, &d), DecodeStatus::kOk);
      seen_slots.push_back(d.slot);
      for (int j = 0; j < d.channel_count; ++j) decoded[d.first_channel + j] = d.samples[j];
    }
    EXPECT_EQ(decoded, channels);
    for (int k = 0; k < p.layout.frame_count; ++k) EXPECT_EQ(seen_slots[k], k);
  }
}

INSTANTIATE_TEST_SUITE_P(Shipped, ProfileRoundTripTest,
                         ::testing::Values("uskin_4x4", "cyskin_16", "barrett_bh8_pad"));

TEST(TaxelCodecTest, UskinTaxelIsBigEndianInBytes1To6) {
  const TaxelCodec codec(Shipped("uskin_4x4"));
  Frame f;
  f.id = 0x713;
  f.len = 7;
  const uint8_t bytes[7] = {0xAA, 0x12, 0x34, 0x56, 0x78, 0x9A, 0xBC};
  std::copy(bytes, bytes + 7, f.data.begin());
  DecodedFrame d;
  ASSERT_EQ(codec.Decode(f, &d), DecodeStatus::kOk);
  EXPECT_EQ(d.slot, 3);
  EXPECT_EQ(d.first_channel, 9);  // taxel 3, x
  EXPECT_EQ(d.samples[0], 0x1234);
  EXPECT_EQ(d.samples[1], 0x5678);
  EXPECT_EQ(d.samples[2], 0x9ABC);
}

TEST(TaxelCodecTest, CyskinIsLittleEndian) {
  const TaxelCodec codec(Shipped("cyskin_16"));
  Frame f;
  f.id = 0x409;
  f.len = 8;
  const uint8_t bytes[8] = {0x34, 0x12, 0x00, 0x01, 0xFF, 0xFF, 0x01, 0x00};
  std::copy(bytes, bytes + 8, f.data.begin());
  DecodedFrame d;
  ASSERT_EQ(codec.Decode(f, &d), DecodeStatus::kOk);
  EXPECT_EQ(d.first_channel, 8);
  EXPECT_EQ(d.samples[0], 0x1234);
  EXPECT_EQ(d.samples[1], 0x0100);
  EXPECT_EQ(d.samples[2], 0xFFFF);
  EXPECT_EQ(d.samples[3], 1);
}

TEST(TaxelCodecTest, BarrettGroupNibbleAndTwelveBitCellsMatchTheDriverFormula) {
  const TaxelCodec codec(Shipped("barrett_bh8_pad"));
  Frame f;
  f.id = 0x169;
  f.len = 8;
  const uint8_t data[8] = {0x3A, 0xBC, 0xDE, 0xF0, 0x12, 0x34, 0x56, 0x78};
  std::copy(data, data + 8, f.data.begin());
  DecodedFrame d;
  ASSERT_EQ(codec.Decode(f, &d), DecodeStatus::kOk);
  EXPECT_EQ(d.slot, 3);  // data[0] >> 4
  EXPECT_EQ(d.first_channel, 15);
  // The puck's packing: cell0 = (d0 & 0xF) << 8 | d1, cell1 = d2 << 4 | d3 >> 4, ...
  EXPECT_EQ(d.samples[0], (data[0] & 0xF) << 8 | data[1]);
  EXPECT_EQ(d.samples[1], data[2] << 4 | data[3] >> 4);
  EXPECT_EQ(d.samples[2], (data[3] & 0xF) << 8 | data[4]);
  EXPECT_EQ(d.samples[3], data[5] << 4 | data[6] >> 4);
  EXPECT_EQ(d.samples[4], (data[6] & 0xF) << 8 | data[7]);
  // The last group (4) carries only cells 20..23.
  f.data[0] = 0x40;
  ASSERT_EQ(codec.Decode(f, &d), DecodeStatus::kOk);
  EXPECT_EQ(d.channel_count, 4);
  // Group 5 does not exist.
  f.data[0] = 0x50;
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kBadFrameIndex);
}

TEST(TaxelCodecTest, RejectsForeignAndMalformedFrames) {
  const TaxelCodec codec(Shipped("cyskin_16"));
  DecodedFrame d;
  Frame f;
  f.id = 0x406;  // between the profile's ids
  f.len = 8;
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kUnknownId);
  f.id = 0x405;
  f.extended = true;  // same number, 29-bit: another device
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kUnknownId);
  f.extended = false;
  f.len = 6;
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kWrongLength);
  f.len = 8;
  f.fd = true;
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kWrongFrameType);
  f.fd = false;
  f.remote = true;
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kRemoteFrame);
  f.remote = false;
  f.error = true;
  EXPECT_EQ(codec.Decode(f, &d), DecodeStatus::kErrorFrame);
}

TEST(TaxelCodecTest, SignedSamplesAndScanCounterRoundTrip) {
  SensorProfile p = Shipped("cyskin_16");
  p.layout.sample_signed = true;
  p.layout.sample_bits = 12;
  p.layout.scan_counter = {56, 8};  // last byte
  p.layout.byte_order = ByteOrder::kBig;
  ValidateProfile(p);
  const TaxelCodec codec(p);
  std::vector<int32_t> channels(16);
  for (int i = 0; i < 16; ++i) channels[i] = (i % 2 ? -1 : 1) * i * 100;
  channels[3] = -5000;  // beyond -2048: the encoder clamps like a saturated ADC
  const auto frames = codec.EncodeScan(channels, 300, 0);
  DecodedFrame d;
  ASSERT_EQ(codec.Decode(frames[0], &d), DecodeStatus::kOk);
  EXPECT_EQ(d.scan_counter, 300 % 256);
  EXPECT_EQ(d.samples[1], -100);
  EXPECT_EQ(d.samples[2], 200);
  EXPECT_EQ(d.samples[3], -2048);
}

TEST(TaxelCodecTest, CanFdLayoutCarriesAWholeScanInOneFrame) {
  SensorProfile p = Shipped("cyskin_16");
  p.layout.fd = true;
  p.layout.fd_flags = kCanFdBrs;
  p.layout.length = 32;
  p.layout.samples_per_frame = 16;
  p.layout.frame_count = 1;
  p.layout.ids = {0x405};
  ValidateProfile(p);
  const TaxelCodec codec(p);
  std::vector<int32_t> channels(16);
  for (int i = 0; i < 16; ++i) channels[i] = 1000 * i + 7;
  const auto frames = codec.EncodeScan(channels, -1, 0);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(frames[0].fd);
  EXPECT_EQ(frames[0].fd_flags, kCanFdBrs);
  EXPECT_EQ(frames[0].len, 32);
  DecodedFrame d;
  ASSERT_EQ(codec.Decode(frames[0], &d), DecodeStatus::kOk);
  EXPECT_EQ(d.channel_count, 16);
  EXPECT_EQ(d.samples[15], 15007);
  Frame classic = frames[0];
  classic.fd = false;
  EXPECT_EQ(codec.Decode(classic, &d), DecodeStatus::kWrongFrameType);
}

TEST(TaxelCodecTest, BitHelpersAgreeBothWays) {
  for (ByteOrder order : {ByteOrder::kBig, ByteOrder::kLittle}) {
    for (int first = 0; first < 40; first += 3) {
      for (int bits : {1, 4, 7, 12, 16, 24}) {
        uint8_t data[8] = {0xA5, 0x5A, 0xFF, 0x00, 0x3C, 0xC3, 0x11, 0xEE};
        uint8_t before[8];
        std::copy(data, data + 8, before);
        const uint32_t value = 0xABCDEFu & ((1u << bits) - 1);
        TaxelCodec::WriteBits(data, first, bits, order, value);
        EXPECT_EQ(TaxelCodec::ReadBits(data, first, bits, order), value);
        // Bits outside the field are untouched: writing the old value back restores all.
        TaxelCodec::WriteBits(data, first, bits, order, TaxelCodec::ReadBits(before, first, bits, order));
        EXPECT_TRUE(std::equal(data, data + 8, before));
      }
    }
  }
}

}  // namespace
}  // namespace sedbridge::sensors
