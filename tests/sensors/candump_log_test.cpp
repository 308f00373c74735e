#include "sensors/candump_log.h"

#include <gtest/gtest.h>

#include <sstream>

#include "common/config_error.h"

namespace sedbridge::sensors {
namespace {

Frame Parse(const std::string& line) {
  Frame f;
  const LineResult r = ParseCandumpLine(line, &f);
  EXPECT_EQ(r.kind, LineKind::kFrame) << line << ": " << (r.error ? r.error : "");
  return f;
}

std::string BadReason(const std::string& line) {
  Frame f;
  const LineResult r = ParseCandumpLine(line, &f);
  EXPECT_EQ(r.kind, LineKind::kBad) << line;
  return r.error ? r.error : "";
}

TEST(CandumpLineTest, ClassicStandardFrame) {
  const Frame f = Parse("(1699999999.123456) can0 123#DEADBEEF");
  EXPECT_EQ(f.utime, 1699999999123456);
  EXPECT_EQ(f.Interface(), "can0");
  EXPECT_EQ(f.id, 0x123u);
  EXPECT_FALSE(f.extended);
  EXPECT_FALSE(f.fd);
  ASSERT_EQ(f.len, 4);
  EXPECT_EQ(f.data[0], 0xDE);
  EXPECT_EQ(f.data[3], 0xEF);
}

TEST(CandumpLineTest, ExtendedIdAndEmptyData) {
  const Frame f = Parse("(0000000001.000001) vcan0 1F334455#");
  EXPECT_TRUE(f.extended);
  EXPECT_EQ(f.id, 0x1F334455u);
  EXPECT_EQ(f.len, 0);
  EXPECT_EQ(f.utime, 1000001);
}

TEST(CandumpLineTest, NanosecondTimestampIsTruncatedToMicroseconds) {
  EXPECT_EQ(Parse("(1699999999.123456789) can0 123#00").utime, 1699999999123456);
}

TEST(CandumpLineTest, RemoteFrames) {
  Frame f = Parse("(1.000000) can0 123#R");
  EXPECT_TRUE(f.remote);
  EXPECT_EQ(f.len, 0);
  f = Parse("(1.000000) can0 123#R5");
  EXPECT_TRUE(f.remote);
  EXPECT_EQ(f.len, 5);
}

TEST(CandumpLineTest, CanFdWithFlags) {
  const Frame f = Parse("(1.000000) can1 123##1DEADBEEF");
  EXPECT_TRUE(f.fd);
  EXPECT_EQ(f.fd_flags, kCanFdBrs);
  EXPECT_EQ(f.len, 4);
  std::string long_data(128, 'A');  // 64 bytes
  const Frame g = Parse("(1.000000) can1 7FF##3" + long_data);
  EXPECT_EQ(g.len, 64);
  EXPECT_EQ(g.fd_flags, kCanFdBrs | kCanFdEsi);
}

TEST(CandumpLineTest, ErrorFrame) {
  const Frame f = Parse("(1.000000) can0 20000040#0000000000000000");
  EXPECT_TRUE(f.error);
  EXPECT_EQ(f.id, 0x40u);  // CAN_ERR_BUSOFF
  EXPECT_EQ(f.len, 8);
}

TEST(CandumpLineTest, DotSeparatedDataRawDlcAndDirectionAreAccepted) {
  EXPECT_EQ(Parse("(1.000000) can0 123#11.22.33").len, 3);
  EXPECT_EQ(Parse("(1.000000) can0 123#1122334455667788_C").len, 8);
  EXPECT_EQ(Parse("(1.000000) can0 123#11 R").len, 1);
  EXPECT_EQ(Parse("(1.000000) can0 123#11\r").len, 1);
}

TEST(CandumpLineTest, CommentsAndBlankLinesAreSkipped) {
  Frame f;
  EXPECT_EQ(ParseCandumpLine("", &f).kind, LineKind::kSkip);
  EXPECT_EQ(ParseCandumpLine("   ", &f).kind, LineKind::kSkip);
  EXPECT_EQ(ParseCandumpLine("# recorded on the bench", &f).kind, LineKind::kSkip);
}

TEST(CandumpLineTest, BadLinesSayWhy) {
  EXPECT_NE(BadReason("can0 123#00").find("time stamp"), std::string::npos);
  EXPECT_NE(BadReason("(1.12345) can0 123#00").find("6 or 9"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 1234#00").find("3 (11-bit) or 8"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 800#00").find("0x7FF"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123#0").find("odd"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123#GG").find("hexadecimal"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123#001122334455667788").find("too many"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123##1001122334455667788").find("CAN FD data length"),
            std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123###00").find("XL"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 12300").find("'#'"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0").find("missing frame"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) 123#00").find("interface"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123#00 extra words").find("unexpected"), std::string::npos);
  EXPECT_NE(BadReason("(1.000000) can0 123#R9").find("unexpected"), std::string::npos);
  // Found by fuzz_candump_line: NUL bytes inside the interface name.
  EXPECT_NE(BadReason(std::string("(1.000000) ca\0n0 123#00", 24)).find("non-printable"), std::string::npos);
}

TEST(CandumpLineTest, WriterMatchesCandumpFormat) {
  Frame f;
  f.utime = 1699999999123456;
  f.SetInterface("can0");
  f.id = 0x123;
  f.len = 4;
  f.data[0] = 0xDE, f.data[1] = 0xAD, f.data[2] = 0xBE, f.data[3] = 0xEF;
  EXPECT_EQ(FormatCandumpLine(f), "(1699999999.123456) can0 123#DEADBEEF");
  f.utime = 5;  // seconds are zero-padded to 10 digits, as candump writes them
  f.extended = true;
  EXPECT_EQ(FormatCandumpLine(f), "(0000000000.000005) can0 00000123#DEADBEEF");
  f.extended = false;
  f.fd = true;
  f.fd_flags = kCanFdBrs;
  EXPECT_EQ(FormatCandumpLine(f), "(0000000000.000005) can0 123##1DEADBEEF");
  f.fd = false;
  f.remote = true;
  EXPECT_EQ(FormatCandumpLine(f), "(0000000000.000005) can0 123#R4");
  Frame e;
  e.error = true;
  e.id = 0x4;
  e.len = 8;
  e.data[1] = 0x10;
  e.SetInterface("vcan0");
  EXPECT_EQ(FormatCandumpLine(e), "(0000000000.000000) vcan0 20000004#0010000000000000");
}

TEST(CandumpLineTest, EveryFrameKindRoundTrips) {
  const std::vector<std::string> lines = {
      "(1699999999.123456) can0 123#DEADBEEF",
      "(1699999999.123457) can0 1FFFFFFF#0102030405060708",
      "(1699999999.123458) can0 7FF#",
      "(1699999999.123459) can0 123#R",
      "(1699999999.123460) can0 123#R8",
      "(1699999999.123461) can1 123##0",
      "(1699999999.123462) can1 00000042##3" + std::string(24, '5'),
      "(1699999999.123463) can0 20000100#0000000000000000",
  };
  for (const auto& line : lines) EXPECT_EQ(FormatCandumpLine(Parse(line)), line);
}

TEST(CandumpLogReaderTest, CountsBadLinesWithLineNumbersAndKeepsGoing) {
  std::istringstream in(
      "(1.000000) can0 123#00\n"
      "garbage\n"
      "# comment\n"
      "\n"
      "(1.000100) can0 123#0\n"
      "(1.000200) can0 124#01\n");
  CandumpLogReader reader(in, "test.log");
  Frame f;
  std::vector<uint32_t> ids;
  while (reader.Next(&f)) ids.push_back(f.id);
  EXPECT_EQ(ids, (std::vector<uint32_t>{0x123, 0x124}));
  EXPECT_EQ(reader.lines_read(), 6);
  EXPECT_EQ(reader.bad_line_count(), 2);
  ASSERT_EQ(reader.bad_lines().size(), 2u);
  EXPECT_EQ(reader.bad_lines()[0].line_number, 2);
  EXPECT_EQ(reader.bad_lines()[0].text, "garbage");
  EXPECT_EQ(reader.bad_lines()[1].line_number, 5);
}

TEST(CandumpLogReaderTest, WriterOutputReadsBack) {
  std::ostringstream out;
  CandumpLogWriter writer(out);
  for (int i = 0; i < 100; ++i) {
    Frame f;
    f.utime = 1700000000000000 + i * 1000;
    f.id = 0x700 + (i % 16);
    f.len = 7;
    f.data[1] = static_cast<uint8_t>(i);
    f.SetInterface("can0");
    writer.Write(f);
  }
  writer.Flush();
  std::istringstream in(out.str());
  CandumpLogReader reader(in);
  Frame f;
  int n = 0;
  while (reader.Next(&f)) {
    EXPECT_EQ(f.utime, 1700000000000000 + n * 1000);
    EXPECT_EQ(f.data[1], n);
    ++n;
  }
  EXPECT_EQ(n, 100);
  EXPECT_EQ(reader.bad_line_count(), 0);
}

TEST(CandumpLogSourceTest, AsFastAsPossibleKeepsRecordedTimestamps) {
  auto in = std::make_unique<std::istringstream>(
      "(10.000000) can0 123#00\n"
      "bad\n"
      "(20.000000) can0 20000040#0000000000000000\n");
  CandumpLogSource source(std::move(in), "mem");
  auto a = source.Next(0);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->utime, 10000000);
  auto b = source.Next(0);
  ASSERT_TRUE(b);
  EXPECT_TRUE(b->error);
  EXPECT_FALSE(source.Done());
  EXPECT_FALSE(source.Next(0));
  EXPECT_TRUE(source.Done());
  const FrameSourceStats s = source.Stats();
  EXPECT_EQ(s.frames, 2);
  EXPECT_EQ(s.bad_lines, 1);
  EXPECT_EQ(s.error_frames, 1);
  EXPECT_EQ(s.bus_off, 1);
}

TEST(CandumpLogSourceTest, RecordedTimingWithholdsAFrameUntilItIsDue) {
  // The second frame is due 1000 s after the first: a zero timeout must not return it.
  auto in = std::make_unique<std::istringstream>(
      "(10.000000) can0 123#00\n"
      "(1010.000000) can0 123#01\n");
  PlaybackOptions options;
  options.speed = 1.0;
  CandumpLogSource source(std::move(in), "mem", options);
  ASSERT_TRUE(source.Next(0));
  EXPECT_FALSE(source.Next(0));
  EXPECT_FALSE(source.Done());
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// A hostile input: one huge line must not take memory with it, and the lines around it survive.
TEST(CandumpLogReaderLimits, HugeLineIsOneBadLineAndCostsNoMemory) {
  std::string text = "(1700000000.000000) can0 710#0102030405060708\n";
  text += std::string(10 * 1024 * 1024, 'x') + "\n";
  text += "(1700000000.000100) can0 711#0102030405060708\n";
  text += "(1700000000.000200) can0 712#01020304";  // last line without a newline
  std::istringstream in(text);
  CandumpLogReader reader(in, "huge");
  Frame f;
  int frames = 0;
  while (reader.Next(&f)) ++frames;
  EXPECT_EQ(frames, 3);
  EXPECT_EQ(reader.bad_line_count(), 1);
  ASSERT_EQ(reader.bad_lines().size(), 1u);
  EXPECT_EQ(reader.bad_lines()[0].line_number, 2);
  EXPECT_NE(reader.bad_lines()[0].reason.find("longer than"), std::string::npos);
  EXPECT_LE(reader.bad_lines()[0].text.size(), 120u);
}

TEST(CandumpLogReaderLimits, ADirectoryIsNotALog) {
  try {
    CandumpLogSource source(::testing::TempDir());
    FAIL() << "a directory was accepted";
  } catch (const sedbridge::config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sedbridge::sensors
