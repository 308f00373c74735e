#include "sensors/socketcan_source.h"

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cstring>
#include <thread>

namespace sedbridge::sensors {
namespace {

// A socketpair stands in for the CAN_RAW socket: the test writes struct can_frame /
// struct canfd_frame datagrams into one end, the source reads the other.
class SocketPairTest : public ::testing::Test {
 protected:
  void SetUp() override {
    int sv[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0) << std::strerror(errno);
    peer_ = sv[0];
    source_ = std::make_unique<SocketCanSource>(sv[1], "can0", true);
  }
  void TearDown() override {
    source_.reset();
    if (peer_ >= 0) ::close(peer_);
  }
  void Write(const void* data, size_t n) { ASSERT_EQ(::send(peer_, data, n, 0), static_cast<ssize_t>(n)); }

  int peer_ = -1;
  std::unique_ptr<SocketCanSource> source_;
};

TEST_F(SocketPairTest, ClassicFrameArrivesWithKernelTimestamp) {
  can_frame k;
  std::memset(&k, 0, sizeof k);
  k.can_id = 0x405;
  k.len = 8;
  for (int i = 0; i < 8; ++i) k.data[i] = static_cast<uint8_t>(0x10 + i);
  timeval before;
  gettimeofday(&before, nullptr);
  Write(&k, sizeof k);
  auto f = source_->Next(1000000);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->id, 0x405u);
  EXPECT_FALSE(f->extended);
  EXPECT_FALSE(f->fd);
  EXPECT_EQ(f->len, 8);
  EXPECT_EQ(f->data[7], 0x17);
  EXPECT_EQ(f->Interface(), "can0");
  // SO_TIMESTAMP (or the wall clock as a fallback) stamps the receive time.
  EXPECT_GE(f->utime, int64_t(before.tv_sec) * 1000000 + before.tv_usec);
  EXPECT_EQ(source_->Stats().frames, 1);
}

TEST_F(SocketPairTest, FdExtendedAndRemoteFrames) {
  canfd_frame fd;
  std::memset(&fd, 0, sizeof fd);
  fd.can_id = 0x1ABCDE | CAN_EFF_FLAG;
  fd.len = 24;
  fd.flags = CANFD_BRS;
  fd.data[23] = 0x99;
  Write(&fd, sizeof fd);
  can_frame rtr;
  std::memset(&rtr, 0, sizeof rtr);
  rtr.can_id = 0x201 | CAN_RTR_FLAG;
  rtr.len = 2;
  Write(&rtr, sizeof rtr);

  auto a = source_->Next(1000000);
  ASSERT_TRUE(a);
  EXPECT_TRUE(a->fd);
  EXPECT_TRUE(a->extended);
  EXPECT_EQ(a->id, 0x1ABCDEu);
  EXPECT_EQ(a->len, 24);
  EXPECT_EQ(a->fd_flags, kCanFdBrs);
  EXPECT_EQ(a->data[23], 0x99);
  auto b = source_->Next(1000000);
  ASSERT_TRUE(b);
  EXPECT_TRUE(b->remote);
  EXPECT_EQ(b->len, 2);
}

TEST_F(SocketPairTest, ErrorFramesAreDecodedIntoCounters) {
  can_frame e;
  std::memset(&e, 0, sizeof e);
  e.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  e.len = CAN_ERR_DLC;
  Write(&e, sizeof e);
  e.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
  e.data[1] = CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_RX_PASSIVE;
  Write(&e, sizeof e);
  e.can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED;
  e.data[1] = 0;
  Write(&e, sizeof e);
  for (int i = 0; i < 3; ++i) {
    auto f = source_->Next(1000000);
    ASSERT_TRUE(f);
    EXPECT_TRUE(f->error);
  }
  const FrameSourceStats s = source_->Stats();
  EXPECT_EQ(s.error_frames, 3);
  EXPECT_EQ(s.bus_off, 1);
  EXPECT_EQ(s.controller_overflow, 1);
  EXPECT_EQ(s.error_passive, 1);
  EXPECT_EQ(s.restarted, 1);
}

TEST_F(SocketPairTest, WrongSizedDatagramIsCountedAndSkipped) {
  const char junk[5] = {1, 2, 3, 4, 5};
  Write(junk, sizeof junk);
  can_frame k;
  std::memset(&k, 0, sizeof k);
  k.can_id = 0x123;
  k.len = 9;  // impossible for classic CAN
  Write(&k, sizeof k);
  k.len = 1;
  Write(&k, sizeof k);
  auto f = source_->Next(1000000);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->id, 0x123u);
  EXPECT_EQ(source_->Stats().read_errors, 2);
}

TEST_F(SocketPairTest, TimeoutReturnsNothingButIsNotTheEnd) {
  EXPECT_FALSE(source_->Next(0));
  EXPECT_FALSE(source_->Next(2000));
  EXPECT_FALSE(source_->Done());
}

TEST_F(SocketPairTest, PeerClosingEndsTheSource) {
  ::close(peer_);
  peer_ = -1;
  EXPECT_FALSE(source_->Next(1000000));
  EXPECT_TRUE(source_->Done());
}

TEST_F(SocketPairTest, CloseWakesABlockedReader) {
  std::optional<Frame> got;
  std::thread reader([&] { got = source_->Next(-1); });  // waits forever until Close()
  source_->Close();
  reader.join();
  EXPECT_FALSE(got);
  EXPECT_TRUE(source_->Done());
}

TEST_F(SocketPairTest, SendWritesKernelFrames) {
  Frame start;
  start.id = 0x201;
  start.len = 2;
  start.data[0] = 7;
  ASSERT_TRUE(source_->Send(start));
  can_frame k;
  ASSERT_EQ(::recv(peer_, &k, sizeof k, 0), static_cast<ssize_t>(CAN_MTU));
  EXPECT_EQ(k.can_id, 0x201u);
  EXPECT_EQ(k.len, 2);
  EXPECT_EQ(k.data[0], 7);
}

TEST(SocketCanConversionTest, FramesRoundTripThroughKernelLayout) {
  Frame f;
  f.id = 0x1FFFFFFF;
  f.extended = true;
  f.fd = true;
  f.fd_flags = kCanFdBrs | kCanFdEsi;
  f.len = 64;
  for (int i = 0; i < 64; ++i) f.data[i] = static_cast<uint8_t>(i * 3);
  unsigned char buf[CANFD_MTU];
  ASSERT_EQ(FrameToKernel(f, buf), static_cast<size_t>(CANFD_MTU));
  Frame g;
  ASSERT_TRUE(FrameFromKernel(buf, CANFD_MTU, &g));
  EXPECT_TRUE(g.SamePayload(f));
  Frame e;
  e.error = true;
  e.id = CAN_ERR_BUSOFF;
  e.len = 8;
  ASSERT_EQ(FrameToKernel(e, buf), static_cast<size_t>(CAN_MTU));
  ASSERT_TRUE(FrameFromKernel(buf, CAN_MTU, &g));
  EXPECT_TRUE(g.error);
  EXPECT_EQ(g.id, static_cast<uint32_t>(CAN_ERR_BUSOFF));
  EXPECT_FALSE(FrameFromKernel(buf, 10, &g));
}

TEST(SocketCanConversionTest, ControlMessagesGiveTimestampAndDropCounter) {
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(uint32_t))];
  std::memset(control, 0, sizeof control);
  msghdr msg;
  std::memset(&msg, 0, sizeof msg);
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  cmsghdr* c = CMSG_FIRSTHDR(&msg);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SCM_TIMESTAMP;
  c->cmsg_len = CMSG_LEN(sizeof(timeval));
  const timeval tv{1700000000, 123456};
  std::memcpy(CMSG_DATA(c), &tv, sizeof tv);
  c = CMSG_NXTHDR(&msg, c);
  ASSERT_NE(c, nullptr);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SO_RXQ_OVFL;
  c->cmsg_len = CMSG_LEN(sizeof(uint32_t));
  const uint32_t drops = 42;
  std::memcpy(CMSG_DATA(c), &drops, sizeof drops);
  const ReceiveMeta meta = ParseControlMessages(msg);
  EXPECT_TRUE(meta.has_timestamp);
  EXPECT_EQ(meta.utime, 1700000000123456);
  EXPECT_TRUE(meta.has_drop_count);
  EXPECT_EQ(meta.drop_count, 42u);
}

TEST(SocketCanConversionTest, ProfileFiltersMatchOnlyItsDataFrames) {
  const SensorProfile p = LoadSensorProfile(ResolveProfilePath("cyskin_16"));
  const auto filters = FiltersForProfile(p);
  ASSERT_EQ(filters.size(), 4u);
  auto passes = [&](uint32_t can_id) {
    for (const auto& f : filters)
      if ((can_id & f.mask) == (f.id & f.mask)) return true;
    return false;
  };
  EXPECT_TRUE(passes(0x405));
  EXPECT_TRUE(passes(0x40B));
  EXPECT_FALSE(passes(0x406));
  EXPECT_FALSE(passes(0x405 | CAN_RTR_FLAG));
  EXPECT_FALSE(passes(0x405 | CAN_EFF_FLAG));
}

// Needs a kernel with AF_CAN and a vcan0 interface:
//   sudo modprobe vcan && sudo ip link add dev vcan0 type vcan && sudo ip link set up vcan0
TEST(SocketCanLiveTest, FrameSentOnVcan0IsReceivedFiltered) {
  std::string why;
  if (!SocketCanSource::KernelHasCan(&why)) GTEST_SKIP() << why;
  if (if_nametoindex("vcan0") == 0) GTEST_SKIP() << "no vcan0 interface (ip link add dev vcan0 type vcan)";
  const SensorProfile p = LoadSensorProfile(ResolveProfilePath("cyskin_16"));
  SocketCanSource rx(OptionsForProfile(p, "vcan0"));
  SocketCanOptions tx_options;
  tx_options.interface = "vcan0";
  SocketCanSource tx(tx_options);
  Frame other;
  other.id = 0x123;
  other.len = 1;
  ASSERT_TRUE(tx.Send(other));  // filtered out by the kernel
  Frame mine;
  mine.id = 0x407;
  mine.len = 8;
  mine.data[0] = 0x42;
  ASSERT_TRUE(tx.Send(mine));
  auto f = rx.Next(1000000);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->id, 0x407u);
  EXPECT_EQ(f->data[0], 0x42);
}

TEST(SocketCanLiveTest, MissingAfCanOrInterfaceIsAClearError) {
  SocketCanOptions o;
  o.interface = "nosuchcan9";
  try {
    SocketCanSource s(o);
    FAIL() << "opened a nonexistent interface";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_TRUE(what.find("AF_CAN") != std::string::npos || what.find("nosuchcan9") != std::string::npos) << what;
  }
}

}  // namespace
}  // namespace sedbridge::sensors
