#include "lcm/lcm_publisher.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lcm/display_command_message.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"
#include "tests/lcm/lcm_test_messages.h"

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
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

using test_messages::Command;

TEST(LcmPublisher, MemqRoundTripOnDefaultChannels) {
  LcmPublisher out("memq://");
  Received rx;
  out.lcm().subscribe("DISPLAY_COMMAND", &Received::OnCommand, &rx);
  out.lcm().subscribe("FINGERTIP_SED", &Received::OnSed, &rx);
  for (int k = 0; k < 3; ++k) out.Publish(out.channels().command, ToLcm(Command(k)));
  SedField f;
  f.utime = 77;
  f.model_id = "B";
  f.x_mm = {0, 1};
  f.y_mm = {2, 3};
  f.sed_Pa = {5, std::nan("")};
  out.Publish(out.channels().sed, ToLcm(f));
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
  out.Publish(out.channels().command, ToLcm(Command(0)));
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

}  // namespace
}  // namespace sedbridge::lcm_io
