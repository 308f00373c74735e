#pragma once
// Live CAN input through Linux SocketCAN (CAN_RAW):
//   - kernel filters (CAN_RAW_FILTER) so only the profile's ids reach us;
//   - error frames opted in (CAN_RAW_ERR_FILTER) and decoded into FrameSourceStats
//     (bus-off, error-passive, controller overflow, restarted, ...);
//   - kernel receive time stamps (SO_TIMESTAMP) as Frame::utime;
//   - the kernel's drop counter (SO_RXQ_OVFL) as FrameSourceStats::kernel_drops;
//   - CAN FD (CAN_RAW_FD_FRAMES) when asked;
//   - non-blocking reads with a poll timeout, and a Close() that wakes a reader blocked in
//     another thread (clean shutdown).
// Tests drive it through an injected descriptor (a socketpair carrying struct can_frame /
// struct canfd_frame), since CI kernels often lack AF_CAN.

#include <sys/socket.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/frame_source.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::sensors {

/// One kernel receive filter: a frame passes when (can_id & mask) == (id & mask), with
/// can_id in the kernel's encoding (CAN_EFF_FLAG / CAN_RTR_FLAG bits included).
struct KernelFilter {
  uint32_t id = 0;
  uint32_t mask = 0;
};

/// Exact-match filters for the profile's ids (data frames of the right 11/29-bit kind only).
std::vector<KernelFilter> FiltersForProfile(const SensorProfile& profile);

struct SocketCanOptions {
  std::string interface = "can0";
  bool fd_frames = false;               ///< enable CAN FD reception (CAN_RAW_FD_FRAMES)
  std::vector<KernelFilter> filters;    ///< empty = receive every id
  /// Error classes to receive (CAN_ERR_* bits; default all). 0 = no error frames.
  uint32_t error_mask = 0x1FFFFFFFu;
  bool kernel_timestamps = true;        ///< SO_TIMESTAMP
  bool drop_counter = true;             ///< SO_RXQ_OVFL
  int receive_buffer_bytes = 0;         ///< SO_RCVBUF (0 = kernel default)
};

/// Options for a profile: its filters and FD setting, on `interface`.
SocketCanOptions OptionsForProfile(const SensorProfile& profile, const std::string& interface);

/// What recvmsg's control messages said.
struct ReceiveMeta {
  bool has_timestamp = false;
  int64_t utime = 0;          ///< kernel receive time [us since the Unix epoch]
  bool has_drop_count = false;
  uint32_t drop_count = 0;    ///< cumulative frames dropped by the kernel for this socket
};

/// Parses SCM_TIMESTAMP and SO_RXQ_OVFL control messages of a received message.
ReceiveMeta ParseControlMessages(const msghdr& message);

/// Converts a datagram read from a CAN_RAW socket (struct can_frame, CAN_MTU bytes, or
/// struct canfd_frame, CANFD_MTU bytes) into a Frame. Returns false for any other size or an
/// impossible length. Does not set utime or interface.
bool FrameFromKernel(const void* bytes, size_t size, Frame* frame);
/// The datagram to write for `frame` (CAN_MTU or CANFD_MTU bytes are filled in `buffer`,
/// which must hold 72 bytes). Returns the number of bytes.
size_t FrameToKernel(const Frame& frame, void* buffer);

class SocketCanSource final : public FrameSource {
 public:
  /// Opens and binds a CAN_RAW socket. Throws std::runtime_error naming the reason (no
  /// AF_CAN in this kernel, no such interface, permission).
  explicit SocketCanSource(const SocketCanOptions& options);
  /// Adopts an already open descriptor (ownership passes to the source): for tests with a
  /// socketpair, or a socket opened elsewhere. Socket options are tried and failures ignored.
  SocketCanSource(int fd, const std::string& interface_name, bool fd_frames);
  ~SocketCanSource() override;
  SocketCanSource(const SocketCanSource&) = delete;
  SocketCanSource& operator=(const SocketCanSource&) = delete;

  std::optional<Frame> Next(int64_t timeout_us) override;
  bool Done() const override { return done_.load(); }
  /// Thread-safe: wakes a Next() blocked in another thread, which then returns nullopt.
  void Close() override;
  FrameSourceStats Stats() const override { return stats_; }
  std::string Describe() const override { return "socketcan " + interface_; }

  /// Sends one frame (start/stop commands). Returns false on failure (errno kept).
  bool Send(const Frame& frame);

  /// True if this kernel can create AF_CAN sockets (for skipping live tests).
  static bool KernelHasCan(std::string* why_not);

  /// The socket's descriptor, for a reader that polls several buses at once
  /// (MultiSocketCanSource); reading stays with Next().
  int descriptor() const { return fd_; }
  const std::string& interface_name() const { return interface_; }

 private:
  void ApplyOptions(const SocketCanOptions& options, bool strict);

  int fd_ = -1;
  int wake_fd_ = -1;  // eventfd written by Close()
  std::string interface_;
  bool fd_frames_ = false;
  std::atomic<bool> done_{false};
  FrameSourceStats stats_;
};

}  // namespace sedbridge::sensors
