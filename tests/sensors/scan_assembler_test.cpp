#include "sensors/scan_assembler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sedbridge::sensors {
namespace {

SensorProfile Shipped(const std::string& name) { return LoadSensorProfile(ResolveProfilePath(name)); }

// cyskin_16: 4 frames (0x405, 0x407, 0x409, 0x40B) of 4 taxels, kPa = (raw - 1000) * 0.02,
// 250 scans/s (4 ms), partial timeout 6 ms.
class CyskinAssemblerTest : public ::testing::Test {
 protected:
  CyskinAssemblerTest() : profile_(Shipped("cyskin_16")), codec_(profile_) {}

  std::vector<Frame> ScanFrames(int32_t value, int64_t utime) {
    std::vector<int32_t> raw(16);
    for (int i = 0; i < 16; ++i) raw[i] = value + i;
    auto frames = codec_.EncodeScan(raw, -1, utime);
    for (size_t k = 0; k < frames.size(); ++k) frames[k].utime = utime + 100 * static_cast<int64_t>(k);
    return frames;
  }

  SensorProfile profile_;
  TaxelCodec codec_;
  std::vector<Scan> scans_;
};

TEST_F(CyskinAssemblerTest, FourFramesMakeOneCalibratedScanStampedByTheLastFrame) {
  ScanAssembler a(profile_);
  for (const Frame& f : ScanFrames(1500, 1000000)) a.Push(f, &scans_);
  ASSERT_EQ(scans_.size(), 1u);
  const Scan& s = scans_[0];
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.utime, 1000300);
  EXPECT_EQ(s.sequence, 0);
  EXPECT_EQ(s.num_taxels, 16);
  EXPECT_EQ(s.raw_counts[5], 1505);
  EXPECT_NEAR(s.pressure_Pa[5], (1505 - 1000) * 0.02 * 1000, 1e-9);
  EXPECT_NEAR(s.force_N[5], s.pressure_Pa[5] * 9e-6, 1e-12);  // 3 mm x 3 mm
  EXPECT_EQ(s.ValidCount(), 16);
  EXPECT_TRUE(s.shear_x_Pa.empty());
  EXPECT_EQ(a.counters().scans_complete, 1);
  EXPECT_EQ(a.counters().rejected(), 0);
}

TEST_F(CyskinAssemblerTest, ReorderedFramesStillCompleteAndAreCounted) {
  ScanAssembler a(profile_);
  auto frames = ScanFrames(1500, 0);
  std::swap(frames[1], frames[3]);
  for (const Frame& f : frames) a.Push(f, &scans_);
  ASSERT_EQ(scans_.size(), 1u);
  EXPECT_TRUE(scans_[0].complete);
  EXPECT_EQ(scans_[0].raw_counts[15], 1515);
  EXPECT_EQ(a.counters().reordered, 2);  // slots 2 and 1 came after slot 3
}

TEST_F(CyskinAssemblerTest, DuplicateFrameIsCountedAndIgnored) {
  ScanAssembler a(profile_);
  auto frames = ScanFrames(1500, 0);
  a.Push(frames[0], &scans_);
  Frame again = frames[0];
  again.utime += 50;
  a.Push(again, &scans_);
  for (size_t k = 1; k < frames.size(); ++k) a.Push(frames[k], &scans_);
  ASSERT_EQ(scans_.size(), 1u);
  EXPECT_TRUE(scans_[0].complete);
  EXPECT_EQ(a.counters().duplicates, 1);
}

TEST_F(CyskinAssemblerTest, MissingFrameGivesAPartialScanAfterTheTimeout) {
  ScanAssembler a(profile_);
  auto frames = ScanFrames(1500, 0);
  frames.erase(frames.begin() + 2);  // taxels 8..11 never arrive
  for (const Frame& f : frames) a.Push(f, &scans_);
  EXPECT_TRUE(scans_.empty());
  a.Poll(3000, &scans_);  // within 6 ms: keep waiting
  EXPECT_TRUE(scans_.empty());
  a.Poll(7000, &scans_);
  ASSERT_EQ(scans_.size(), 1u);
  const Scan& s = scans_[0];
  EXPECT_FALSE(s.complete);
  EXPECT_EQ(s.ValidCount(), 12);
  EXPECT_EQ(s.flags[8], kTaxelMissing);
  EXPECT_FALSE(s.valid[11]);
  EXPECT_TRUE(s.valid[12]);
  EXPECT_EQ(a.counters().scans_partial, 1);
  EXPECT_EQ(a.counters().missing_frames, 1);
}

TEST_F(CyskinAssemblerTest, NextScanBeginningEmitsThePartialOneAndCarriesOldValues) {
  ScanAssembler a(profile_);
  for (const Frame& f : ScanFrames(1500, 0)) a.Push(f, &scans_);
  auto second = ScanFrames(1600, 4000);
  a.Push(second[0], &scans_);
  a.Push(second[1], &scans_);  // frames 2 and 3 are lost
  for (const Frame& f : ScanFrames(1700, 8000)) a.Push(f, &scans_);
  ASSERT_EQ(scans_.size(), 3u);
  EXPECT_TRUE(scans_[0].complete);
  EXPECT_FALSE(scans_[1].complete);
  EXPECT_EQ(scans_[1].sequence, 1);
  EXPECT_EQ(scans_[1].raw_counts[0], 1600);
  EXPECT_EQ(scans_[1].raw_counts[12], 1512);  // carried from scan 0, flagged missing
  EXPECT_EQ(scans_[1].flags[12], kTaxelMissing);
  EXPECT_TRUE(scans_[2].complete);
  EXPECT_EQ(scans_[2].raw_counts[12], 1712);
}

TEST_F(CyskinAssemblerTest, ForeignAndMalformedFramesAreCountedByKind) {
  ScanAssembler a(profile_);
  Frame f = ScanFrames(1500, 0)[0];
  Frame unknown = f;
  unknown.id = 0x123;
  a.Push(unknown, &scans_);
  Frame short_frame = f;
  short_frame.len = 5;
  a.Push(short_frame, &scans_);
  Frame remote = f;
  remote.remote = true;
  a.Push(remote, &scans_);
  Frame fd = f;
  fd.fd = true;
  a.Push(fd, &scans_);
  Frame err;
  err.error = true;
  err.id = 0x40;
  err.len = 8;
  a.Push(err, &scans_);
  const BadFrameCounters& c = a.counters();
  EXPECT_EQ(c.unknown_id, 1);
  EXPECT_EQ(c.wrong_length, 1);
  EXPECT_EQ(c.remote_frames, 1);
  EXPECT_EQ(c.wrong_frame_type, 1);
  EXPECT_EQ(c.error_frames, 1);
  EXPECT_EQ(c.rejected(), 5);
  EXPECT_EQ(c.frames_used, 0);
  EXPECT_TRUE(scans_.empty());
}

TEST_F(CyskinAssemblerTest, SaturatedReadingIsFullScaleWithAFlagNeverSilence) {
  // Found by adversarial review: saturated taxels were invalid (then filled or zeroed), so the
  // hardest contact gave zero feedback. Now: valid, at the full-scale value, flagged.
  ScanAssembler a(profile_);
  std::vector<int32_t> raw(16, 1500);
  raw[6] = 65535;
  raw[7] = 0;  // the low rail too (profile saturation_counts: [0, 65535])
  for (const Frame& f : codec_.EncodeScan(raw, -1, 0)) a.Push(f, &scans_);
  ASSERT_EQ(scans_.size(), 1u);
  EXPECT_EQ(scans_[0].flags[6], kTaxelSaturated);
  EXPECT_EQ(scans_[0].flags[7], kTaxelSaturated);
  EXPECT_TRUE(scans_[0].valid[6]);
  EXPECT_TRUE(scans_[0].valid[7]);
  EXPECT_EQ(scans_[0].ValidCount(), 16);
  EXPECT_EQ(scans_[0].SaturatedCount(), 2);
  // kPa = (raw - 1000) * 0.02: full scale 1290.7 kPa, far above the 10 kPa of its neighbours.
  EXPECT_NEAR(scans_[0].pressure_Pa[6], (65535 - 1000) * 0.02 * 1e3, 1e-6);
  EXPECT_GT(scans_[0].pressure_Pa[6], 100 * scans_[0].pressure_Pa[5]);
  EXPECT_EQ(a.counters().saturated_values, 2);
}

TEST_F(CyskinAssemblerTest, FramesFromAnotherInterfaceAreNotThisSensors) {
  AssemblerOptions o;
  o.interface = "can0";
  ScanAssembler a(profile_, o);
  for (Frame f : ScanFrames(1500, 0)) {
    f.SetInterface("can1");  // the same sensor ids on another bus
    a.Push(f, &scans_);
  }
  EXPECT_TRUE(scans_.empty());
  EXPECT_EQ(a.counters().other_interface, 4);
  for (Frame f : ScanFrames(1500, 10000)) {
    f.SetInterface("can0");
    a.Push(f, &scans_);
  }
  ASSERT_EQ(scans_.size(), 1u);
  EXPECT_TRUE(scans_[0].complete);
  // Without an interface set, any bus is taken (one SocketCAN socket = one bus).
  ScanAssembler any(profile_);
  std::vector<Scan> out;
  for (Frame f : ScanFrames(1500, 0)) {
    f.SetInterface("can1");
    any.Push(f, &out);
  }
  EXPECT_EQ(out.size(), 1u);
}

TEST_F(CyskinAssemblerTest, BusOffAndErrorPassiveSetTheBusState) {
  ScanAssembler a(profile_);
  Frame passive;
  passive.error = true;
  passive.id = 0x04;  // CAN_ERR_CRTL
  passive.len = 8;
  passive.data[1] = 0x10;  // CAN_ERR_CRTL_RX_PASSIVE
  a.Push(passive, &scans_);
  EXPECT_EQ(a.counters().bus_state, kBusErrorPassive);
  EXPECT_EQ(a.counters().error_passive_events, 1);
  Frame off;
  off.error = true;
  off.id = 0x40;  // CAN_ERR_BUSOFF
  off.len = 8;
  for (int k = 0; k < 4800; ++k) a.Push(off, &scans_);  // a hostile input: 4800 of them left fault_state 0
  EXPECT_EQ(a.counters().bus_state, kBusOff);
  EXPECT_EQ(a.counters().bus_off_events, 4800);
  EXPECT_EQ(a.counters().error_frames, 4801);
  Frame restarted;
  restarted.error = true;
  restarted.id = 0x100;  // CAN_ERR_RESTARTED
  restarted.len = 8;
  a.Push(restarted, &scans_);
  EXPECT_EQ(a.counters().bus_state, kBusErrorActive);
}

TEST_F(CyskinAssemblerTest, CalibrationGivingNanMarksTheTaxelInvalidAndZero) {
  // A profile built in code can carry a gain the YAML loader would refuse.
  profile_.calibration.taxel_gain[4] = std::numeric_limits<double>::quiet_NaN();
  profile_.calibration.taxel_gain[5] = std::numeric_limits<double>::infinity();
  ScanAssembler a(profile_);
  for (const Frame& f : ScanFrames(1500, 0)) a.Push(f, &scans_);
  ASSERT_EQ(scans_.size(), 1u);
  const Scan& s = scans_[0];
  EXPECT_EQ(s.flags[4], kTaxelNonFinite);
  EXPECT_EQ(s.flags[5], kTaxelNonFinite);
  EXPECT_EQ(s.pressure_Pa[4], 0.0);
  EXPECT_EQ(s.pressure_Pa[5], 0.0);
  for (double p : s.pressure_Pa) EXPECT_TRUE(std::isfinite(p));
  EXPECT_EQ(a.counters().nonfinite_values, 2);
}

TEST_F(CyskinAssemblerTest, TareAveragesTheFirstQuietScans) {
  AssemblerOptions options;
  options.tare_scans = 3;
  options.quiet_tolerance_counts = 10;
  ScanAssembler a(profile_, options);
  int64_t t = 0;
  // A touch (big change) first: collection restarts; then three quiet scans 2000, 2002, 2004.
  for (int32_t v : {1200, 5000, 2000, 2002, 2004, 2500}) {
    for (const Frame& f : ScanFrames(v, t)) a.Push(f, &scans_);
    t += 4000;
  }
  ASSERT_EQ(scans_.size(), 6u);
  // The third quiet scan (index 4) completes the tare; it was itself calibrated before.
  EXPECT_FALSE(scans_[4].tared);
  EXPECT_TRUE(scans_[5].tared);
  EXPECT_TRUE(a.tared());
  EXPECT_NEAR(a.baseline_counts()[0], 2002, 1e-9);
  EXPECT_NEAR(a.baseline_counts()[9], 2011, 1e-9);
  EXPECT_NEAR(scans_[5].pressure_Pa[0], (2500 - 2002) * 0.02 * 1000, 1e-6);
}

TEST_F(CyskinAssemblerTest, TareOnDemand) {
  ScanAssembler a(profile_);
  for (const Frame& f : ScanFrames(3000, 0)) a.Push(f, &scans_);
  EXPECT_FALSE(a.tared());
  a.RequestTare(1);
  EXPECT_TRUE(a.tare_in_progress());
  for (const Frame& f : ScanFrames(3000, 4000)) a.Push(f, &scans_);
  EXPECT_TRUE(a.tared());
  for (const Frame& f : ScanFrames(3000, 8000)) a.Push(f, &scans_);
  EXPECT_NEAR(scans_.back().pressure_Pa[3], 0.0, 1e-9);
}

TEST_F(CyskinAssemblerTest, StaleTaxelIsFlaggedAfterIdenticalReadings) {
  profile_.stale_after_scans = 3;
  ScanAssembler a(profile_);
  for (int k = 0; k < 5; ++k) {
    std::vector<int32_t> raw(16);
    for (int i = 0; i < 16; ++i) raw[i] = 1500 + k;  // everything changes ...
    raw[2] = 1400;                                    // ... except taxel 2 (stuck)
    for (const Frame& f : codec_.EncodeScan(raw, -1, k * 4000)) a.Push(f, &scans_);
  }
  ASSERT_EQ(scans_.size(), 5u);
  EXPECT_EQ(scans_[2].flags[2], 0);
  EXPECT_EQ(scans_[3].flags[2], kTaxelStale);
  EXPECT_EQ(scans_[4].flags[2], kTaxelStale);
  EXPECT_EQ(scans_[4].flags[3], 0);
  EXPECT_EQ(a.counters().stale_taxels, 2);
}

TEST_F(CyskinAssemblerTest, FrameOlderThanTheLastScanIsStale) {
  ScanAssembler a(profile_);
  auto first = ScanFrames(1500, 100000);
  for (const Frame& f : first) a.Push(f, &scans_);
  Frame late = ScanFrames(1400, 50000)[1];  // recorded before the scan already emitted
  a.Push(late, &scans_);
  EXPECT_EQ(a.counters().stale_frames, 1);
  EXPECT_EQ(scans_.size(), 1u);
}

TEST(ScanAssemblerTest, ScanCounterGapsAndOldCountersAreCounted) {
  SensorProfile p = Shipped("cyskin_16");
  p.layout.sample_bits = 12;
  p.layout.scan_counter = {48, 8};
  ValidateProfile(p);
  const TaxelCodec codec(p);
  ScanAssembler a(p);
  std::vector<Scan> scans;
  std::vector<int32_t> raw(16, 1500);
  auto push_scan = [&](int64_t counter, int64_t t) {
    for (const Frame& f : codec.EncodeScan(raw, counter, t)) a.Push(f, &scans);
  };
  push_scan(254, 0);
  push_scan(255, 4000);
  push_scan(2, 8000);  // wrapped; 0 and 1 lost
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[2].sensor_counter, 2);
  EXPECT_EQ(a.counters().scans_dropped, 2);
  // A frame of scan 255 arriving now is stale.
  a.Push(codec.EncodeSlot(1, raw, 255, 9000), &scans);
  EXPECT_EQ(a.counters().stale_frames, 1);
  // A different counter mid-scan ends the scan in progress as partial.
  a.Push(codec.EncodeSlot(0, raw, 3, 12000), &scans);
  a.Push(codec.EncodeSlot(0, raw, 4, 13000), &scans);
  ASSERT_EQ(scans.size(), 4u);
  EXPECT_FALSE(scans[3].complete);
  EXPECT_EQ(scans[3].sensor_counter, 3);
}

TEST(ScanAssemblerTest, UskinForceBecomesPressureAndShear) {
  const SensorProfile p = Shipped("uskin_4x4");
  const TaxelCodec codec(p);
  ScanAssembler a(p);
  std::vector<int32_t> raw(48);
  for (int i = 0; i < 16; ++i) {
    raw[3 * i + 0] = 32768 + 100;  // x: +0.02 N
    raw[3 * i + 1] = 32768 - 50;   // y: -0.01 N
    raw[3 * i + 2] = 1000 + 2000;  // z: 1 N
  }
  std::vector<Scan> scans;
  for (const Frame& f : codec.EncodeScan(raw, -1, 0)) a.Push(f, &scans);
  ASSERT_EQ(scans.size(), 1u);
  const Scan& s = scans[0];
  const double area_m2 = 16e-6;
  EXPECT_EQ(s.num_axes, 3);
  EXPECT_NEAR(s.force_N[7], 1.0, 1e-12);
  EXPECT_NEAR(s.pressure_Pa[7], 1.0 / area_m2, 1e-6);
  EXPECT_NEAR(s.shear_x_Pa[7], 0.02 / area_m2, 1e-6);
  EXPECT_NEAR(s.shear_y_Pa[7], -0.01 / area_m2, 1e-6);
}

TEST(ScanAssemblerTest, BarrettGroupsInAnyOrderMakeAScan) {
  const SensorProfile p = Shipped("barrett_bh8_pad");
  const TaxelCodec codec(p);
  ScanAssembler a(p);
  std::vector<int32_t> raw(24);
  for (int i = 0; i < 24; ++i) raw[i] = 100 * i;
  auto frames = codec.EncodeScan(raw, -1, 0);
  std::reverse(frames.begin(), frames.end());
  std::vector<Scan> scans;
  for (const Frame& f : frames) a.Push(f, &scans);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_TRUE(scans[0].complete);
  EXPECT_EQ(scans[0].raw_counts, raw);
  EXPECT_NEAR(scans[0].pressure_Pa[23], 2300 * 0.05 * 1000, 1e-9);
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// One corrupted group nibble must not misalign every later scan (frames of one scan arrive
// as a burst; an idle gap of half a period ends the scan).
TEST(ScanAssemblerTest, CorruptedFrameIndexDoesNotMisalignLaterScans) {
  const SensorProfile p = Shipped("barrett_bh8_pad");  // 40 Hz: 25 ms period
  const TaxelCodec codec(p);
  ScanAssembler a(p);
  std::vector<Scan> scans;
  for (int k = 0; k < 6; ++k) {
    std::vector<int32_t> raw(24);
    for (int i = 0; i < 24; ++i) raw[i] = 100 + 10 * k + i;
    auto frames = codec.EncodeScan(raw, -1, 0);
    for (int j = 0; j < 5; ++j) frames[j].utime = k * 25000 + j * 130;
    if (k == 2) frames[3].data[0] = 0x10;  // group 3 claims to be group 1
    for (const Frame& f : frames) a.Push(f, &scans);
  }
  ASSERT_GE(scans.size(), 6u);
  EXPECT_TRUE(scans.back().complete);
  EXPECT_TRUE(scans[scans.size() - 2].complete);
  // Scans 0, 1, 3, 4, 5 complete; scan 2 ends up as two partial pieces ({0,1,2}, {"1",4}).
  EXPECT_EQ(a.counters().scans_complete, 5);
  EXPECT_EQ(a.counters().scans_partial, 2);
  EXPECT_EQ(a.counters().reordered, 0);
}

}  // namespace
}  // namespace sedbridge::sensors
