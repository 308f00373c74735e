// The leader-side driver's core: its own limiter and watchdog, size-safe decoding, display
// checks, HMAC authentication with replay rejection, and the serial line protocol.

#include "display/display_driver.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "display/serial_actuator_output.h"
#include "lcm/display_command_message.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_display_command.hpp"

namespace sedbridge::display {
using namespace sedbridge::lcm_io;  // LCM messages in and out
namespace {

constexpr int64_t kMs = 1000;
constexpr int64_t kT0 = 1'700'000'000'000'000;

// Keeps every frame written.
struct CaptureOutput : ActuatorOutput {
  std::vector<ActuatorFrame>* frames;
  explicit CaptureOutput(std::vector<ActuatorFrame>* f) : frames(f) {}
  bool Write(const ActuatorFrame& f) override {
    frames->push_back(f);
    return true;
  }
  std::string Describe() const override { return "capture"; }
};

DisplayProfile Suction() { return LoadDisplayProfile("config/displays/suction_4x4.yaml"); }

std::vector<uint8_t> Encoded(int64_t utime, int64_t sequence, double value, const DisplayProfile& p) {
  DisplayCommand c;
  c.utime = utime;
  c.sequence = sequence;
  c.display_id = p.name;
  c.unit = p.unit;
  c.value.assign(p.size(), value);
  const lcmt_display_command m = ToLcm(c);
  std::vector<uint8_t> b(size_t(m.getEncodedSize()));
  m.encode(b.data(), 0, int(b.size()));
  return b;
}

std::vector<uint8_t> Key(uint8_t fill) { return std::vector<uint8_t>(32, fill); }

double MaxOf(const ActuatorFrame& f) { return *std::max_element(f.value.begin(), f.value.end()); }

TEST(DisplayDriver, OwnLimiterAndWatchdogRampToZeroWhenCommandsStop) {
  const DisplayProfile p = Suction();  // max 20 kPa, slew 200 kPa/s, watchdog 0.1 s
  std::vector<ActuatorFrame> frames;
  DisplayDriver driver(p, std::make_unique<CaptureOutput>(&frames), DecodeDisplayCommand);
  int64_t t = kT0;
  // 1 s of commands at 100 Hz asking for 1000 kPa (a bridge gone wrong): clipped to 20.
  for (int k = 0; k < 100; ++k, t += 10 * kMs) {
    ASSERT_TRUE(driver.OnMessage(Encoded(t, k, 1000.0, p).data(), Encoded(t, k, 1000.0, p).size(), t));
    driver.Tick(t);
  }
  EXPECT_DOUBLE_EQ(MaxOf(frames.back()), 20.0);
  // Silence: ticks only. Zero at the latest after timeout + max / slew = 0.1 + 0.1 s.
  const int64_t silence = t;
  for (; t < silence + 400 * kMs; t += 5 * kMs) {
    const ActuatorFrame& f = driver.Tick(t);
    for (double v : f.value) {
      ASSERT_GE(v, 0.0);
      ASSERT_LE(v, 20.0);
    }
    if (t > silence + 200 * kMs + 5 * kMs) {
      ASSERT_EQ(MaxOf(f), 0.0) << (t - silence) / kMs << " ms into the silence";
      ASSERT_TRUE(f.stale);
    }
  }
  EXPECT_EQ(driver.counters().accepted, 100);
  driver.Shutdown(t);
  EXPECT_TRUE(frames.back().shutdown);
  EXPECT_EQ(MaxOf(frames.back()), 0.0);
}

TEST(DisplayDriver, MalformedAndWrongDisplayCommandsAreCountedAndIgnored) {
  const DisplayProfile p = Suction();
  std::vector<ActuatorFrame> frames;
  DisplayDriver driver(p, std::make_unique<CaptureOutput>(&frames), DecodeDisplayCommand);
  // The 160-byte num_actuators = 1e9 packet (a hostile input).
  std::vector<uint8_t> bomb = Encoded(kT0, 0, 5.0, p);
  const size_t at = 8 + 32 + (4 + p.name.size() + 1) + (4 + p.unit.size() + 1);
  bomb[at] = 0x3B, bomb[at + 1] = 0x9A, bomb[at + 2] = 0xCA, bomb[at + 3] = 0x00;  // 1e9
  bomb.resize(160);
  EXPECT_FALSE(driver.OnMessage(bomb.data(), bomb.size(), kT0));
  EXPECT_EQ(driver.counters().malformed, 1);
  DisplayProfile other = p;
  other.name = "pin_6x4";
  const std::vector<uint8_t> wrong = Encoded(kT0, 1, 5.0, other);
  EXPECT_FALSE(driver.OnMessage(wrong.data(), wrong.size(), kT0));
  EXPECT_EQ(driver.counters().wrong_display, 1);
  for (int k = 0; k < 50; ++k) EXPECT_EQ(MaxOf(driver.Tick(kT0 + k * 10 * kMs)), 0.0);
  EXPECT_EQ(driver.counters().accepted, 0);
}

TEST(DisplayDriver, AuthenticationRejectsUnsignedForgedAndReplayedCommands) {
  const DisplayProfile p = Suction();
  auto auth = std::make_shared<CommandAuthenticator>(Key(7));
  const CommandAuthenticator attacker(Key(8));
  std::vector<ActuatorFrame> frames;
  DisplayDriver driver(p, std::make_unique<CaptureOutput>(&frames), DecodeDisplayCommand, auth);
  int64_t t = kT0;
  // Forged 1e6 kPa commands: unsigned, signed with the wrong key, or with one bit flipped.
  for (int k = 0; k < 30; ++k, t += 10 * kMs) {
    const std::vector<uint8_t> plain = Encoded(t, k, 1e6, p);
    EXPECT_FALSE(driver.OnMessage(plain.data(), plain.size(), t));
    const std::vector<uint8_t> wrong_key = attacker.Sign(plain.data(), plain.size());
    EXPECT_FALSE(driver.OnMessage(wrong_key.data(), wrong_key.size(), t));
    std::vector<uint8_t> flipped = auth->Sign(plain.data(), plain.size());
    flipped[20] ^= 1;
    EXPECT_FALSE(driver.OnMessage(flipped.data(), flipped.size(), t));
    EXPECT_EQ(MaxOf(driver.Tick(t)), 0.0);
  }
  EXPECT_EQ(driver.counters().unsigned_or_forged, 90);
  // Genuine commands are taken...
  std::vector<std::vector<uint8_t>> genuine;
  for (int k = 0; k < 30; ++k, t += 10 * kMs) {
    genuine.push_back(auth->Sign(Encoded(t, 100 + k, 10.0, p).data(), Encoded(t, 100 + k, 10.0, p).size()));
    EXPECT_TRUE(driver.OnMessage(genuine.back().data(), genuine.back().size(), t));
    driver.Tick(t);
  }
  EXPECT_GT(MaxOf(frames.back()), 5.0);
  // ... and replaying them later (to hold the display on) is rejected: it ramps to zero.
  const int64_t replay_start = t;
  for (int round = 0; round < 3; ++round)
    for (const auto& g : genuine) {
      t += 5 * kMs;
      EXPECT_FALSE(driver.OnMessage(g.data(), g.size(), t));
      const ActuatorFrame& f = driver.Tick(t);
      if (t > replay_start + 200 * kMs) {
        ASSERT_EQ(MaxOf(f), 0.0);
      }
    }
  EXPECT_EQ(driver.counters().replayed, 90);
  EXPECT_EQ(driver.counters().accepted, 30);
}

TEST(DisplayDriver, TheWireFormatComesInAsADecoder) {
  const DisplayProfile p = Suction();
  std::vector<ActuatorFrame> frames;
  EXPECT_THROW(DisplayDriver(p, std::make_unique<CaptureOutput>(&frames), nullptr), std::invalid_argument);
  // Any decoder will do: the core checks the decoded command, not the bytes.
  const DisplayCommandDecoder one_byte_per_command = [&p](const void* data, std::size_t size, DisplayCommand* c) {
    if (size != 1) return false;
    c->utime = kT0 + *static_cast<const uint8_t*>(data);
    c->display_id = p.name;
    c->unit = p.unit;
    c->value.assign(p.size(), 5.0);
    return true;
  };
  DisplayDriver driver(p, std::make_unique<CaptureOutput>(&frames), one_byte_per_command);
  const uint8_t byte = 1;
  EXPECT_TRUE(driver.OnMessage(&byte, 1, kT0));
  EXPECT_FALSE(driver.OnMessage(&byte, 0, kT0));
  EXPECT_EQ(driver.counters().accepted, 1);
  EXPECT_EQ(driver.counters().malformed, 1);
}

TEST(CommandAuthenticator, KeyFileMustBeLongAndPrivate) {
  const std::string path = ::testing::TempDir() + "/sedbridge_key_" + std::to_string(::getpid());
  std::ofstream(path, std::ios::binary) << std::string(32, 'k');
  ::chmod(path.c_str(), 0644);
  EXPECT_THROW(CommandAuthenticator::FromKeyFile(path), std::runtime_error);  // world-readable
  ::chmod(path.c_str(), 0600);
  const CommandAuthenticator a = CommandAuthenticator::FromKeyFile(path);
  const std::vector<uint8_t> s = a.Sign("abc", 3);
  ASSERT_EQ(s.size(), 3 + CommandAuthenticator::kTagBytes);
  EXPECT_EQ(a.Verify(s.data(), s.size()), std::optional<std::size_t>(3));
  std::ofstream(path, std::ios::binary) << std::string(16, 'k');
  EXPECT_THROW(CommandAuthenticator::FromKeyFile(path), std::runtime_error);  // too short
  EXPECT_THROW(CommandAuthenticator(std::vector<uint8_t>(31, 1)), std::invalid_argument);
  EXPECT_THROW(CommandAuthenticator::FromKeyFile(path + ".missing"), std::runtime_error);
  std::filesystem::remove(path);
}

TEST(CommandAuthenticator, MatchesTheRfc4231TestVector) {
  // RFC 4231 test case 2 uses a 4-byte key; case 6 uses 131 bytes of 0xaa (>= our minimum):
  // "Test Using Larger Than Block-Size Key - Hash Key First".
  const CommandAuthenticator a(std::vector<uint8_t>(131, 0xaa));
  const std::string msg = "Test Using Larger Than Block-Size Key - Hash Key First";
  const std::vector<uint8_t> s = a.Sign(msg.data(), msg.size());
  static const uint8_t expected[32] = {0x60, 0xe4, 0x31, 0x59, 0x1e, 0xe0, 0xb6, 0x7f, 0x0d, 0x8a, 0x26,
                                       0xaa, 0xcb, 0xf5, 0xb7, 0x7f, 0x8e, 0x0b, 0xc6, 0x21, 0x37, 0x28,
                                       0xc5, 0x14, 0x05, 0x46, 0x04, 0x0f, 0x0e, 0xe3, 0x7f, 0x54};
  EXPECT_TRUE(std::equal(expected, expected + 32, s.begin() + long(msg.size())));
}

TEST(SerialActuatorOutput, LineProtocolHasFlagsCountValuesAndXorChecksum) {
  ActuatorFrame f;
  f.sequence = 42;
  f.stale = true;
  f.value = {0.0, 12.5, 3.25};
  const std::string line = FormatSerialLine(f);
  ASSERT_EQ(line.substr(0, 23), "$D,42,1,3,0.000,12.500,");
  ASSERT_GE(line.size(), 5u);
  EXPECT_EQ(line.substr(line.size() - 2), "\r\n");
  const size_t star = line.find('*');
  unsigned char sum = 0;
  for (size_t i = 1; i < star; ++i) sum ^= static_cast<unsigned char>(line[i]);
  char hex[3];
  std::snprintf(hex, sizeof hex, "%02X", sum);
  EXPECT_EQ(line.substr(star + 1, 2), hex);
  EXPECT_THROW(MakeActuatorOutput("serial:/dev/null:12345", 3, "kPa"), std::invalid_argument);
  EXPECT_THROW(MakeActuatorOutput("serial:/dev/null", 3, "kPa"), std::runtime_error);  // not a tty
  EXPECT_THROW(MakeActuatorOutput("tcp:1.2.3.4", 3, "kPa"), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::display
