// The multi-bus reader of a live hand (sensors::MultiSocketCanSource) without AF_CAN: each
// bus is a SocketCanSource on a socketpair, the test writes struct can_frame datagrams into
// the other ends. The vcan test needs vcan0 and vcan1 and skips cleanly without them.

#include "sensors/multi_socketcan_source.h"

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <map>
#include <thread>

namespace sedbridge::sensors {
namespace {

class TwoBusTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<std::unique_ptr<SocketCanSource>> buses;
    for (const char* name : {"can0", "can1"}) {
      int sv[2];
      ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0) << std::strerror(errno);
      peers_[name] = sv[0];
      buses.push_back(std::make_unique<SocketCanSource>(sv[1], name, false));
    }
    source_ = std::make_unique<MultiSocketCanSource>(std::move(buses));
  }
  void TearDown() override {
    source_.reset();
    for (auto& [name, fd] : peers_)
      if (fd >= 0) ::close(fd);
  }
  void Write(const std::string& bus, uint32_t can_id, uint8_t first = 0) {
    can_frame k;
    std::memset(&k, 0, sizeof k);
    k.can_id = can_id;
    k.len = 8;
    k.data[0] = first;
    ASSERT_EQ(::send(peers_[bus], &k, sizeof k, 0), static_cast<ssize_t>(sizeof k));
  }
  void Hangup(const std::string& bus) {
    ::close(peers_[bus]);
    peers_[bus] = -1;
  }

  std::map<std::string, int> peers_;
  std::unique_ptr<MultiSocketCanSource> source_;
};

TEST_F(TwoBusTest, FramesOfBothBusesComeOutWithTheirInterface) {
  Write("can0", 0x405, 1);
  Write("can1", 0x405, 2);
  std::map<std::string, int> first_byte;
  for (int i = 0; i < 2; ++i) {
    const std::optional<Frame> f = source_->Next(1000000);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->id, 0x405u);
    first_byte[f->Interface()] = f->data[0];
  }
  EXPECT_EQ(first_byte, (std::map<std::string, int>{{"can0", 1}, {"can1", 2}}));
  EXPECT_EQ(source_->Stats().frames, 2);
  EXPECT_EQ(source_->Stats("can0").frames, 1);
  EXPECT_EQ(source_->Stats("can1").frames, 1);
  EXPECT_EQ(source_->Describe(), "socketcan can0+can1");
}

TEST_F(TwoBusTest, BusyBusDoesNotStarveTheOther) {
  for (int i = 0; i < 20; ++i) Write("can0", 0x405);
  Write("can1", 0x406);
  int position = -1;
  for (int i = 0; i < 21; ++i) {
    const std::optional<Frame> f = source_->Next(1000000);
    ASSERT_TRUE(f);
    if (f->Interface() == "can1") position = i;
  }
  EXPECT_GE(position, 0);
  EXPECT_LE(position, 1);  // buses take turns
}

TEST_F(TwoBusTest, TimeoutWithoutFramesReturnsEmpty) {
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(source_->Next(20000));
  const double waited_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(waited_ms, 15.0);
  EXPECT_FALSE(source_->Done());
}

TEST_F(TwoBusTest, OneBusGoneLeavesTheOtherRunning) {
  Hangup("can1");  // the peer's end closed: that bus is done (a CAN socket: ENETDOWN)
  Write("can0", 0x405, 7);
  std::optional<Frame> f = source_->Next(1000000);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->Interface(), "can0");
  EXPECT_FALSE(source_->Done());
  Hangup("can0");
  EXPECT_FALSE(source_->Next(100000));
  EXPECT_TRUE(source_->Done());
}

TEST_F(TwoBusTest, ErrorFramesAreCountedPerBus) {
  Write("can1", CAN_ERR_FLAG | CAN_ERR_BUSOFF);
  const std::optional<Frame> f = source_->Next(1000000);
  ASSERT_TRUE(f);
  EXPECT_TRUE(f->error);
  EXPECT_EQ(f->Interface(), "can1");
  EXPECT_EQ(source_->Stats("can1").bus_off, 1);
  EXPECT_EQ(source_->Stats("can0").bus_off, 0);
}

TEST_F(TwoBusTest, CloseWakesAReaderBlockedInAnotherThread) {
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    source_->Close();
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(source_->Next(-1));  // would wait forever
  closer.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_TRUE(source_->Done());
}

TEST(MultiSocketCanSource, SameBusTwiceIsRefused) {
  std::vector<std::unique_ptr<SocketCanSource>> buses;
  std::vector<int> peers;
  for (int i = 0; i < 2; ++i) {
    int sv[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    peers.push_back(sv[0]);
    buses.push_back(std::make_unique<SocketCanSource>(sv[1], "can0", false));
  }
  EXPECT_THROW(MultiSocketCanSource(std::move(buses)), std::invalid_argument);
  for (int fd : peers) ::close(fd);
}

// Needs AF_CAN and two virtual buses:
//   sudo modprobe vcan && for b in vcan0 vcan1; do sudo ip link add dev $b type vcan && sudo ip link set up $b; done
TEST(MultiSocketCanLiveTest, FramesOnVcan0AndVcan1ComeThroughOneReaderFiltered) {
  std::string why;
  if (!SocketCanSource::KernelHasCan(&why)) GTEST_SKIP() << why;
  if (if_nametoindex("vcan0") == 0 || if_nametoindex("vcan1") == 0)
    GTEST_SKIP() << "no vcan0 and vcan1 (ip link add dev vcan0 type vcan; the same for vcan1)";
  SocketCanOptions rx0, rx1;
  rx0.interface = "vcan0";
  rx0.filters = {{0x405, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG}};
  rx1.interface = "vcan1";
  rx1.filters = {{0x406, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG}};
  std::unique_ptr<MultiSocketCanSource> rx = MultiSocketCanSource::Open({rx0, rx1});
  SocketCanOptions tx0, tx1;
  tx0.interface = "vcan0";
  tx1.interface = "vcan1";
  SocketCanSource send0(tx0), send1(tx1);
  Frame f;
  f.len = 8;
  f.id = 0x406;
  ASSERT_TRUE(send0.Send(f));  // vcan0 keeps 0x405 only
  f.id = 0x405;
  ASSERT_TRUE(send0.Send(f));
  f.id = 0x406;
  ASSERT_TRUE(send1.Send(f));
  std::map<std::string, uint32_t> got;
  for (int i = 0; i < 2; ++i) {
    const std::optional<Frame> r = rx->Next(1000000);
    ASSERT_TRUE(r);
    got[r->Interface()] = r->id;
  }
  EXPECT_EQ(got, (std::map<std::string, uint32_t>{{"vcan0", 0x405u}, {"vcan1", 0x406u}}));
  EXPECT_FALSE(rx->Next(50000));
}

}  // namespace
}  // namespace sedbridge::sensors
