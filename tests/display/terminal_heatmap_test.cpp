#include "display/terminal_heatmap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace sedbridge::display {
namespace {

ActuatorLayout TwoByTwo() {
  // row-major from the tip: (−1, 1) (1, 1) / (−1, −1) (1, −1)
  return {{-1, 1, -1, 1}, {1, 1, -1, -1}, 10.0, "kPa"};
}

DisplayCommand Command(std::vector<double> v) {
  DisplayCommand c;
  c.display_id = "t";
  c.unit = "kPa";
  c.sequence = 4;
  c.value = std::move(v);
  return c;
}

int LineOf(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  if (pos == std::string::npos) return -1;
  return static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
}

TEST(TerminalHeatmap, TipRowOnTopAndColumnsLeftToRight) {
  HeatmapStyle plain;
  plain.color = false;
  const std::string out = RenderHeatmap(TwoByTwo(), Command({1.11, 2.22, 3.33, 4.44}), nullptr, plain);
  EXPECT_EQ(LineOf(out, "1.11"), LineOf(out, "2.22"));
  EXPECT_LT(LineOf(out, "2.22"), LineOf(out, "3.33"));
  EXPECT_LT(out.find("1.11"), out.find("2.22"));
  EXPECT_EQ(out.find("\033["), std::string::npos);  // plain means no escape codes
}

TEST(TerminalHeatmap, FlagsAndBadValuesAreVisible) {
  DisplayCommand c = Command({0, std::nan(""), 10, 0});
  c.stale = true;
  c.fault = true;
  const std::string out = RenderHeatmap(TwoByTwo(), c, nullptr);
  EXPECT_NE(out.find("[STALE]"), std::string::npos);
  EXPECT_NE(out.find("[FAULT]"), std::string::npos);
  EXPECT_NE(out.find("NaN"), std::string::npos);
  EXPECT_NE(out.find("\033[48;5;"), std::string::npos);
}

TEST(TerminalHeatmap, WrongActuatorCountIsReportedNotCrashed) {
  const std::string out = RenderHeatmap(TwoByTwo(), Command({1, 2}), nullptr);
  EXPECT_NE(out.find("wrong profile"), std::string::npos);
}

TEST(TerminalHeatmap, SedMapShowsPeak) {
  SedField f;
  f.x_mm = {0.0, 0.5, 100.0};
  f.y_mm = {0.0, 0.0, 0.0};
  f.sed_Pa = {50.0, 2500.0, std::nan("")};
  HeatmapStyle plain;
  plain.color = false;
  const std::string out = RenderHeatmap(TwoByTwo(), Command({0, 0, 0, 0}), &f, plain);
  EXPECT_NE(out.find("peak 2.5e+03 Pa at (0.5, 0.0) mm"), std::string::npos) << out;
  EXPECT_NE(out.find("non-finite"), std::string::npos);
  EXPECT_NE(out.find("@@"), std::string::npos);  // the peak cell at full shade
}

}  // namespace
}  // namespace sedbridge::display
