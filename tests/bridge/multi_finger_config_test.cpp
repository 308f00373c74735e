// A hand's bridge config (`fingers:`): today's one-finger config is one finger whose channels
// keep their names; each listed finger gets its own sensor, bus, ids, model and display and
// channels ending in _<NAME>; a CAN id two fingers claim on one bus is refused at load,
// naming both fingers and where.

#include <gtest/gtest.h>

#include <string>

#include "bridge/bridge_config.h"
#include "bridge/fingers.h"
#include "common/config_error.h"

namespace sedbridge::bridge {
namespace {

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseBridgeConfig(yaml, "hand.yaml");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(MultiFingerConfig, OneFingerConfigIsOneFingerWithTodaysChannels) {
  const BridgeConfig c = ParseBridgeConfig("sensor: {profile: uskin_4x4, interface: can3}\ndisplay: {profile: pin_6x4}\n",
                                           "one.yaml");
  const std::vector<Finger> fingers = FingersOf(c);
  ASSERT_EQ(fingers.size(), 1u);
  EXPECT_EQ(fingers[0].name, kSingleFingerName);
  EXPECT_EQ(fingers[0].config.can_interface, "can3");
  EXPECT_EQ(fingers[0].config.display_profile, "pin_6x4");
  EXPECT_EQ(fingers[0].config.lcm.channels.tactile_scan, "TACTILE_SCAN");
  EXPECT_EQ(fingers[0].config.lcm.channels.command, "DISPLAY_COMMAND");
  EXPECT_EQ(fingers[0].config.can_id_offset, 0);
}

TEST(MultiFingerConfig, EachFingerHasItsOwnSensorModelDisplayAndChannels) {
  const BridgeConfig c = ParseBridgeConfig(
      "fe: {model: B_coarse}\n"
      "display: {profile: suction_4x4}\n"
      "fingers:\n"
      "  - name: thumb\n"
      "    sensor: {profile: uskin_4x4, interface: can0}\n"
      "  - name: index_tip\n"
      "    sensor: {profile: uskin_4x4, interface: can0, id_offset: 0x20}\n"
      "    fe: {model: B}\n"
      "    display: {profile: pin_6x4}\n"
      "  - name: middle\n"
      "    sensor: {profile: cyskin_16, interface: can1}\n",
      "hand.yaml");
  const std::vector<Finger> f = FingersOf(c);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].name, "thumb");
  EXPECT_EQ(f[0].config.model, "B_coarse");
  EXPECT_EQ(f[0].config.display_profile, "suction_4x4");
  EXPECT_EQ(f[0].config.lcm.channels.tactile_scan, "TACTILE_SCAN_THUMB");
  EXPECT_EQ(f[1].config.model, "B");
  EXPECT_EQ(f[1].config.display_profile, "pin_6x4");
  EXPECT_EQ(f[1].config.lcm.channels.command, "DISPLAY_COMMAND_INDEX_TIP");
  EXPECT_EQ(f[1].config.lcm.channels.status, "BRIDGE_STATUS_INDEX_TIP");
  EXPECT_EQ(LoadFingerSensorProfile(f[1].config).layout.ids.front(), 0x730u);
  EXPECT_EQ(f[2].config.sensor_profile, "cyskin_16");
  EXPECT_EQ(f[2].config.can_interface, "can1");
  EXPECT_TRUE(f[2].config.fingers.empty());
}

TEST(MultiFingerConfig, CanIdClaimedByTwoFingersIsRefusedNamingBoth) {
  const std::string what = ErrorOf(
      "fingers:\n"
      "  - name: thumb\n"
      "    sensor: {profile: uskin_4x4, interface: can0}\n"
      "  - name: index\n"
      "    sensor: {profile: uskin_4x4, interface: can0, id_offset: 4}\n");
  EXPECT_NE(what.find("hand.yaml:4:5"), std::string::npos) << what;
  EXPECT_NE(what.find("'thumb'"), std::string::npos) << what;
  EXPECT_NE(what.find("'index'"), std::string::npos) << what;
  EXPECT_NE(what.find("0x714"), std::string::npos) << what;
  EXPECT_NE(what.find("can0"), std::string::npos) << what;
  // Another bus, or ids moved past the other's: no conflict.
  EXPECT_EQ(ErrorOf("fingers:\n  - {name: a, sensor: {interface: can0}}\n  - {name: b, sensor: {interface: can1}}\n"), "");
  EXPECT_EQ(ErrorOf("fingers:\n  - {name: a}\n  - {name: b, sensor: {id_offset: 16}}\n"), "");
}

TEST(MultiFingerConfig, NamesAndIdsAreCheckedWhereTheyStand) {
  std::string what = ErrorOf("fingers:\n  - {name: thumb}\n  - {name: thumb, sensor: {interface: can1}}\n");
  EXPECT_NE(what.find("hand.yaml:3:12"), std::string::npos) << what;
  EXPECT_NE(what.find("two fingers are named 'thumb'"), std::string::npos) << what;
  what = ErrorOf("fingers:\n  - {name: 'index finger'}\n");
  EXPECT_NE(what.find("hand.yaml:2:12"), std::string::npos) << what;
  what = ErrorOf("fingers:\n  - {sensor: {interface: can1}}\n");
  EXPECT_NE(what.find("name"), std::string::npos) << what;
  what = ErrorOf("fingers:\n  - {name: a, sensor: {id_offset: 0x7F0}}\n");
  EXPECT_NE(what.find("hand.yaml:2:5"), std::string::npos) << what;
  EXPECT_NE(what.find("11-bit"), std::string::npos) << what;
  what = ErrorOf("fingers:\n  - {name: a, sensor: {profile: no_such_sensor}}\n");
  EXPECT_NE(what.find("finger 'a'"), std::string::npos) << what;
  what = ErrorOf("fingers:\n  - {name: a, sensor: {bus: can1}}\n");
  EXPECT_NE(what.find("bus"), std::string::npos) << what;
}

TEST(MultiFingerConfig, OneFingerCommandsRefuseAHand) {
  const BridgeConfig hand = ParseBridgeConfig("fingers:\n  - {name: a}\n  - {name: b, sensor: {interface: can1}}\n", "h.yaml");
  EXPECT_THROW(RequireOneFinger(hand, "run"), std::runtime_error);
  EXPECT_NO_THROW(RequireOneFinger(ParseBridgeConfig("", "one.yaml"), "run"));
}

}  // namespace
}  // namespace sedbridge::bridge
