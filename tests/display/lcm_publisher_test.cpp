#include "display/lcm_publisher.h"

#include <gtest/gtest.h>

#include <cmath>

#include "display/lcm_conversions.h"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"

namespace sedbridge::display {
namespace {

struct Received {
  std::vector<lcmt_display_command> commands;
  std::vector<lcmt_merkel_sed> fields;
  std::vector<std::string> channels;
  void OnCommand(const lcm::ReceiveBuffer*, const std::string& ch, const lcmt_display_command* m) {
    commands.push_back(*m);
    channels.push_back(ch);
  }
  void OnSed(const lcm::ReceiveBuffer*, const std::string& ch, const lcmt_merkel_sed* m) {
    fields.push_back(*m);
    channels.push_back(ch);
  }
};

void Drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

DisplayCommand Command(int64_t seq) {
  DisplayCommand c;
  c.utime = 1000 + seq;
  c.sequence = seq;
  c.source_scan_utime = 900;
  c.source_sed_utime = 950;
  c.display_id = "suction_4x4";
  c.unit = "kPa";
  c.value = {0.0, 1.25, 20.0};
  c.clamped = true;
  return c;
}

TEST(LcmPublisher, MemqRoundTripOnDefaultChannels) {
  LcmPublisher out("memq://");
  Received rx;
  out.lcm().subscribe("DISPLAY_COMMAND", &Received::OnCommand, &rx);
  out.lcm().subscribe("FINGERTIP_SED", &Received::OnSed, &rx);
  for (int k = 0; k < 3; ++k) out.PublishCommand(Command(k));
  SedField f;
  f.utime = 77;
  f.model_id = "B";
  f.x_mm = {0, 1};
  f.y_mm = {2, 3};
  f.sed_Pa = {5, std::nan("")};
  out.PublishSed(f);
  Drain(out.lcm());
  ASSERT_EQ(rx.commands.size(), 3u);
  EXPECT_EQ(rx.commands[2].sequence, 2);
  EXPECT_EQ(rx.commands[0].num_actuators, 3);
  EXPECT_FLOAT_EQ(rx.commands[0].value[1], 1.25f);
  EXPECT_TRUE(rx.commands[0].clamped);
  EXPECT_FALSE(rx.commands[0].stale);
  ASSERT_EQ(rx.fields.size(), 1u);
  EXPECT_EQ(rx.fields[0].num_positions, 2);
  EXPECT_TRUE(std::isnan(rx.fields[0].sed_Pa[1]));
  EXPECT_FLOAT_EQ(rx.fields[0].max_sed_Pa, 5.0f);  // max over finite values
  EXPECT_EQ(out.published(), 4);
  EXPECT_EQ(out.publish_errors(), 0);
}

TEST(LcmPublisher, ChannelsAreConfigurable) {
  LcmChannels ch;
  ch.command = "LEFT_HAND_DISPLAY";
  LcmPublisher out("memq://", ch);
  Received rx;
  out.lcm().subscribe("LEFT_HAND_DISPLAY", &Received::OnCommand, &rx);
  out.PublishCommand(Command(0));
  Drain(out.lcm());
  ASSERT_EQ(rx.channels.size(), 1u);
  EXPECT_EQ(rx.channels[0], "LEFT_HAND_DISPLAY");
}

TEST(LcmPublisher, RejectsBadChannelNamesAndUrls) {
  LcmChannels ch;
  ch.status = "bridge_status";
  EXPECT_THROW(LcmPublisher("memq://", ch), std::invalid_argument);
  EXPECT_THROW(LcmPublisher("nosuchprovider://"), std::runtime_error);
}

TEST(LcmConversions, CommandValuesNeverRoundAboveTheirDoubleValue) {
  DisplayCommand c = Command(0);
  c.value = {0.1, 20.0 / 3.0, 1e-30, 3.4e38};
  const lcmt_display_command m = ToLcm(c);
  for (std::size_t i = 0; i < c.value.size(); ++i)
    EXPECT_LE(static_cast<double>(m.value[i]), c.value[i]) << i;
  EXPECT_EQ(FromLcm(m).value.size(), 4u);
}

TEST(LcmConversions, SedFieldRoundTripAndOverflowToInf) {
  SedField f;
  f.utime = 3;
  f.source_scan_utime = 2;
  f.model_id = "B";
  f.x_mm = {1.5};
  f.y_mm = {-2};
  f.z_mm = {-1.5};
  f.sed_Pa = {1e300};
  const SedField back = FromLcm(ToLcm(f));
  EXPECT_EQ(back.model_id, "B");
  EXPECT_EQ(back.source_scan_utime, 2);
  EXPECT_DOUBLE_EQ(back.z_mm[0], -1.5);
  EXPECT_TRUE(std::isinf(back.sed_Pa[0]));
}

}  // namespace
}  // namespace sedbridge::display
