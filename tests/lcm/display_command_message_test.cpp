#include "lcm/display_command_message.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/lcm/lcm_test_messages.h"

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
namespace {

using test_messages::Command;

std::vector<uint8_t> Encoded(const lcmt_display_command& m) {
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

TEST(LcmConversions, CommandValuesNeverRoundAboveTheirDoubleValue) {
  DisplayCommand c = Command(0);
  c.value = {0.1, 20.0 / 3.0, 1e-30, 3.4e38};
  const lcmt_display_command m = ToLcm(c);
  for (std::size_t i = 0; i < c.value.size(); ++i)
    EXPECT_LE(static_cast<double>(m.value[i]), c.value[i]) << i;
  EXPECT_EQ(FromLcm(m).value.size(), 4u);
}

TEST(LcmConversions, DecodeDisplayCommandTakesOneWholeWellFormedMessageOnly) {
  const std::vector<uint8_t> bytes = Encoded(ToLcm(Command(7)));
  DisplayCommand c;
  ASSERT_TRUE(DecodeDisplayCommand(bytes.data(), bytes.size(), &c));
  EXPECT_EQ(c.sequence, 7);
  EXPECT_EQ(c.display_id, "suction_4x4");
  EXPECT_EQ(c.value, (std::vector<double>{0.0, 1.25, 20.0}));
  EXPECT_TRUE(c.clamped);
  EXPECT_FALSE(DecodeDisplayCommand(bytes.data(), bytes.size() - 1, &c));  // truncated
  std::vector<uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(DecodeDisplayCommand(longer.data(), longer.size(), &c));  // trailing byte
}

}  // namespace
}  // namespace sedbridge::lcm_io
