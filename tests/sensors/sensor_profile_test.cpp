#include "sensors/sensor_profile.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "common/schema_keys.h"
#include "tests/common/readme_keys.h"

namespace sedbridge::sensors {
namespace {

const char* kMinimal = R"(
name: tiny
taxels:
  count: 4
  axes: 1
  grid: {rows: 2, cols: 2, pitch_mm: [2, 3]}
  size_mm: [1.5, 1.5]
frames:
  ids: [0x100, 0x101]
  length: 4
  samples_per_frame: 2
  sample_bits: 16
  byte_order: little
calibration:
  unit: kPa
  scale_per_count: 0.1
scan_rate_Hz: 100
)";

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseSensorProfileString(yaml, "p.yaml");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(SensorProfileTest, MinimalProfileGetsDefaultsAndGridPositions) {
  const SensorProfile p = ParseSensorProfileString(kMinimal, "p.yaml");
  EXPECT_EQ(p.name, "tiny");
  EXPECT_EQ(p.channel_count(), 4);
  ASSERT_EQ(p.taxels.size(), 4u);
  // Row-major, centred on the origin.
  EXPECT_DOUBLE_EQ(p.taxels[0].x_mm, -1.0);
  EXPECT_DOUBLE_EQ(p.taxels[0].y_mm, -1.5);
  EXPECT_DOUBLE_EQ(p.taxels[1].x_mm, 1.0);
  EXPECT_DOUBLE_EQ(p.taxels[2].y_mm, 1.5);
  EXPECT_EQ(p.layout.ids, (std::vector<uint32_t>{0x100, 0x101}));
  EXPECT_EQ(p.layout.frame_count, 2);
  EXPECT_DOUBLE_EQ(p.calibration.offset_counts[0], 0.0);
  EXPECT_EQ(p.calibration.saturation_high_counts, 65535);
  EXPECT_EQ(p.partial_timeout_us, 15000);  // 1.5 scan periods
}

TEST(SensorProfileTest, ShippedProfilesLoad) {
  const SensorProfile u = LoadSensorProfile(config::ResolveResource("config/sensors/uskin_4x4.yaml"));
  EXPECT_EQ(u.taxel_count, 16);
  EXPECT_EQ(u.axes, 3);
  EXPECT_EQ(u.layout.ids.front(), 0x710u);
  EXPECT_EQ(u.layout.ids.back(), 0x71Fu);
  ASSERT_EQ(u.start_frames.size(), 1u);
  EXPECT_EQ(u.start_frames[0].id, 0x201u);
  EXPECT_EQ(u.start_frames[0].len, 2);
  EXPECT_EQ(u.start_frames[0].data[0], 7);

  const SensorProfile c = LoadSensorProfile(ResolveProfilePath("cyskin_16"));
  EXPECT_EQ(c.layout.ids, (std::vector<uint32_t>{0x405, 0x407, 0x409, 0x40B}));
  EXPECT_EQ(c.layout.byte_order, ByteOrder::kLittle);

  const SensorProfile b = LoadSensorProfile(ResolveProfilePath("barrett_bh8_pad"));
  EXPECT_EQ(b.taxel_count, 24);
  EXPECT_EQ(b.layout.frame_count, 5);
  EXPECT_TRUE(b.layout.frame_index.present());
  EXPECT_EQ(b.layout.sample_bits, 12);
}

TEST(SensorProfileTest, UnknownKeyIsAnErrorWithLocation) {
  const std::string err = ErrorOf(Replace(kMinimal, "scan_rate_Hz: 100", "scan_rate_Hz: 100\nscan_rat: 3"));
  EXPECT_NE(err.find("p.yaml:"), std::string::npos) << err;
  EXPECT_NE(err.find("scan_rat"), std::string::npos) << err;
}

TEST(SensorProfileTest, InconsistentLayoutsAreRejected) {
  // Too few samples for the taxels.
  EXPECT_NE(ErrorOf(Replace(kMinimal, "ids: [0x100, 0x101]", "ids: [0x100]")).find("channels"),
            std::string::npos);
  // Samples do not fit the payload.
  EXPECT_NE(ErrorOf(Replace(kMinimal, "length: 4", "length: 3")).find("outside"), std::string::npos);
  // Duplicate ids.
  EXPECT_NE(ErrorOf(Replace(kMinimal, "0x101]", "0x100]")).find("differ"), std::string::npos);
  // 11-bit id out of range.
  EXPECT_NE(ErrorOf(Replace(kMinimal, "0x101]", "0x801]")).find("11-bit"), std::string::npos);
  // Zero scale would make every pressure 0.
  EXPECT_NE(ErrorOf(Replace(kMinimal, "scale_per_count: 0.1", "scale_per_count: 0")).find("non-zero"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(kMinimal, "scale_per_count: 0.1", "scale_per_count: .nan")).find("finite"),
            std::string::npos);
  // Grid does not match the taxel count.
  EXPECT_NE(ErrorOf(Replace(kMinimal, "rows: 2,", "rows: 3,")).find("rows * cols"), std::string::npos);
  // Bad command frame syntax.
  EXPECT_NE(ErrorOf(std::string(kMinimal) + "start_frames: [\"hello\"]\n").find("candump syntax"),
            std::string::npos);
}

TEST(SensorProfileTest, OverlappingFieldsAreRejected) {
  const std::string yaml = Replace(kMinimal, "byte_order: little",
                                   "byte_order: little\n  scan_counter: {first_bit: 8, bits: 4}");
  EXPECT_NE(ErrorOf(yaml).find("overlaps"), std::string::npos) << ErrorOf(yaml);
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

TEST(SensorProfileTest, UnknownProfileNameListsTheShippedOnes) {
  try {
    LoadNamedSensorProfile("no_such_sensor");
    FAIL();
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("uskin_4x4"), std::string::npos) << what;
    EXPECT_NE(what.find("barrett_bh8_pad"), std::string::npos) << what;
  }
  EXPECT_EQ(LoadNamedSensorProfile("cyskin_16").name, "cyskin_16");
}

}  // namespace
}  // namespace sedbridge::sensors

// The key table of config/sensors/README.md and the profile schema name the same keys.
namespace sedbridge::sensors {
namespace {

TEST(SensorProfileTest, ReadmeTableNamesEverySchemaKeyAndNoOther) {
  test_util::ExpectReadmeNamesSchemaKeys(config::ResolveResource("config/sensors/README.md"), config::SchemaKeys<SensorProfile>());
}

TEST(SensorProfileTest, EveryShippedProfileLoads) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(config::ResolveResource("config/sensors"))) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_EQ(LoadSensorProfile(entry.path().string()).name, entry.path().stem().string());
    ++loaded;
  }
  EXPECT_GE(loaded, 4);
}

TEST(SensorProfileTest, SlotIdsFromIdBaseAndKeysThatGoTogether) {
  const SensorProfile p =
      ParseSensorProfileString(Replace(kMinimal, "ids: [0x100, 0x101]", "id_base: 0x100\n  id_step: 2\n  count: 2"), "p.yaml");
  EXPECT_EQ(p.layout.ids, (std::vector<uint32_t>{0x100, 0x102}));
  EXPECT_EQ(ErrorOf(Replace(kMinimal, "ids: [0x100, 0x101]", "id_base: 0x100")), "p.yaml:9:3: missing required key 'count'");
  EXPECT_EQ(ErrorOf(Replace(kMinimal, "ids: [0x100, 0x101]", "ids: [0x100, 0x101]\n  id_step: 2")),
            "p.yaml:10:12: 'id_step' goes with 'id_base', not 'ids'");
  EXPECT_EQ(ErrorOf(Replace(kMinimal, "  axes: 1", "  axes: 2")), "p.yaml:5:9: 'axes' must be 1 (normal) or 3 (x, y, z)");
  EXPECT_EQ(ErrorOf(Replace(kMinimal, "  size_mm: [1.5, 1.5]\n", "")), "p.yaml:4:3: missing required key 'size_mm'");
  EXPECT_EQ(ErrorOf(Replace(kMinimal, "taxels:", "taxelz:")), "p.yaml:2:1: missing required key 'taxels'");
}

}  // namespace
}  // namespace sedbridge::sensors
