#include "lcm/display_session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "lcm/lcm_log_reader.h"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
namespace {

SedField Press(int64_t utime) {
  SedField f;
  f.utime = utime;
  for (double x = -4; x <= 4; x += 0.5)
    for (double y = -4; y <= 4; y += 0.5) {
      f.x_mm.push_back(x);
      f.y_mm.push_back(y);
      f.z_mm.push_back(-1.5);
      f.sed_Pa.push_back(3000 * std::exp(-(x * x + y * y) / 6));
    }
  return f;
}

TEST(DisplaySession, PublishesAndEndsWithAZeroCommandInTheLog) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("sedbridge_session_" + std::to_string(::getpid()) + ".lcmlog"))
                               .string();
  LcmSettings settings;
  settings.url = "memq://";
  settings.log_path = path;
  DisplaySessionOptions options;
  options.publish_sa1_rate = true;
  {
    DisplaySession session(LoadDisplayProfile("config/displays/suction_4x4.yaml"), settings,
                           options);
    int64_t t = 1'000'000;
    for (int k = 0; k < 30; ++k, t += 10'000) session.OnSedField(Press(t), t);
    EXPECT_GT(session.last_command().value[5], 0.0);
    // no explicit Shutdown(): the destructor must publish zeros
  }
  LcmLogReader reader(path);
  int commands = 0, sa1 = 0, fields = 0, shutdowns = 0;
  lcmt_display_command last;
  lcmt_sa1_rate_estimate rate;
  while (const lcm::LogEvent* e = reader.Next()) {
    if (e->channel == "DISPLAY_COMMAND") {
      ASSERT_TRUE(LcmLogReader::Decode(*e, &last));
      ++commands;
      shutdowns += last.shutdown;
    } else if (e->channel == "SA1_RATE_ESTIMATE") {
      ASSERT_TRUE(LcmLogReader::Decode(*e, &rate));
      ++sa1;
    } else if (e->channel == "FINGERTIP_SED") {
      ++fields;
    }
  }
  EXPECT_EQ(commands, 30 + DisplaySession::kShutdownRepeats);
  EXPECT_EQ(shutdowns, DisplaySession::kShutdownRepeats);
  EXPECT_EQ(fields, 15);  // 100 Hz of fields, published at the default 50 Hz
  EXPECT_EQ(sa1, 30);
  EXPECT_TRUE(last.shutdown);
  for (float v : last.value) EXPECT_EQ(v, 0.0f);
  EXPECT_EQ(rate.num_sites, 16);
  EXPECT_GT(rate.rate_Hz[5], rate.rate_Hz[0]);  // centre fires more than the corner
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sedbridge::lcm_io
