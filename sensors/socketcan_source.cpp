#include "sensors/socketcan_source.h"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "common/wall_clock.h"

namespace sedbridge::sensors {

namespace {

std::string ErrnoText(const std::string& what) { return what + ": " + std::strerror(errno); }

}  // namespace

std::vector<KernelFilter> FiltersForProfile(const SensorProfile& p) {
  std::vector<KernelFilter> out;
  for (uint32_t id : p.layout.ids) {
    KernelFilter f;
    if (p.layout.extended_ids) {
      f.id = (id & CAN_EFF_MASK) | CAN_EFF_FLAG;
      f.mask = CAN_EFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    } else {
      f.id = id & CAN_SFF_MASK;
      f.mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    out.push_back(f);
  }
  return out;
}

SocketCanOptions OptionsForProfile(const SensorProfile& p, const std::string& interface) {
  SocketCanOptions o;
  o.interface = interface;
  o.fd_frames = p.layout.fd;
  o.filters = FiltersForProfile(p);
  return o;
}

ReceiveMeta ParseControlMessages(const msghdr& msg) {
  ReceiveMeta meta;
  for (cmsghdr* c = CMSG_FIRSTHDR(const_cast<msghdr*>(&msg)); c; c = CMSG_NXTHDR(const_cast<msghdr*>(&msg), c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SCM_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof(timeval))) {
      timeval tv;
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      meta.has_timestamp = true;
      meta.utime = static_cast<int64_t>(tv.tv_sec) * 1000000 + tv.tv_usec;
    } else if (c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(uint32_t))) {
      std::memcpy(&meta.drop_count, CMSG_DATA(c), sizeof(uint32_t));
      meta.has_drop_count = true;
    }
  }
  return meta;
}

bool FrameFromKernel(const void* bytes, size_t size, Frame* f) {
  if (size != CAN_MTU && size != CANFD_MTU) return false;
  canfd_frame k;
  std::memset(&k, 0, sizeof k);
  std::memcpy(&k, bytes, size);  // can_frame is a prefix-compatible layout of canfd_frame
  *f = Frame{};
  const bool fd = size == CANFD_MTU;
  const int max_len = fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  if (k.len > max_len) return false;
  f->fd = fd;
  f->len = k.len;
  if (k.can_id & CAN_ERR_FLAG) {
    if (fd) return false;
    f->error = true;
    f->id = k.can_id & CAN_ERR_MASK;
  } else {
    f->extended = (k.can_id & CAN_EFF_FLAG) != 0;
    f->remote = !fd && (k.can_id & CAN_RTR_FLAG) != 0;
    f->id = k.can_id & (f->extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  }
  if (fd) {
    if (!IsValidFdLength(k.len)) return false;
    f->fd_flags = k.flags & (CANFD_BRS | CANFD_ESI);
  }
  if (!f->remote) std::memcpy(f->data.data(), k.data, f->len);
  return true;
}

size_t FrameToKernel(const Frame& f, void* buffer) {
  canfd_frame k;
  std::memset(&k, 0, sizeof k);
  if (f.error) {
    k.can_id = CAN_ERR_FLAG | (f.id & CAN_ERR_MASK);
  } else {
    k.can_id = f.extended ? (f.id & CAN_EFF_MASK) | CAN_EFF_FLAG : f.id & CAN_SFF_MASK;
    if (f.remote && !f.fd) k.can_id |= CAN_RTR_FLAG;
  }
  k.len = std::min<uint8_t>(f.len, f.fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN);
  if (f.fd) k.flags = f.fd_flags & (CANFD_BRS | CANFD_ESI);
  if (!f.remote) std::memcpy(k.data, f.data.data(), k.len);
  const size_t n = f.fd ? CANFD_MTU : CAN_MTU;
  std::memcpy(buffer, &k, n);
  return n;
}

bool SocketCanSource::KernelHasCan(std::string* why_not) {
  const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (s < 0) {
    if (why_not) *why_not = ErrnoText("socket(PF_CAN, SOCK_RAW, CAN_RAW)") +
                            " (this kernel lacks AF_CAN / the can-raw module)";
    return false;
  }
  ::close(s);
  return true;
}

SocketCanSource::SocketCanSource(const SocketCanOptions& options)
    : interface_(options.interface), fd_frames_(options.fd_frames) {
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) {
    if (errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT)
      throw std::runtime_error("SocketCAN unavailable: this kernel has no AF_CAN / CAN_RAW support (" +
                               std::string(std::strerror(errno)) + "); use a candump log instead");
    throw std::runtime_error(ErrnoText("cannot create a CAN_RAW socket"));
  }
  try {
    if (options.interface.empty() || options.interface.size() >= IFNAMSIZ)
      throw std::runtime_error("bad CAN interface name '" + options.interface + "'");
    const unsigned index = if_nametoindex(options.interface.c_str());
    if (index == 0)
      throw std::runtime_error("no network interface '" + options.interface +
                               "' (for a virtual bus: ip link add dev vcan0 type vcan && ip link set up vcan0)");
    ApplyOptions(options, true);
    sockaddr_can addr;
    std::memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(index);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0)
      throw std::runtime_error(ErrnoText("cannot bind to " + options.interface));
    if (::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK) < 0)
      throw std::runtime_error(ErrnoText("fcntl(O_NONBLOCK)"));
    wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (wake_fd_ < 0) throw std::runtime_error(ErrnoText("eventfd"));
  } catch (...) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
}

SocketCanSource::SocketCanSource(int fd, const std::string& interface_name, bool fd_frames)
    : fd_(fd), interface_(interface_name), fd_frames_(fd_frames) {
  SocketCanOptions o;
  o.fd_frames = fd_frames;
  ApplyOptions(o, false);  // a socketpair accepts SO_TIMESTAMP; CAN options are ignored
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) throw std::runtime_error(ErrnoText("eventfd"));
}

void SocketCanSource::ApplyOptions(const SocketCanOptions& o, bool strict) {
  auto set = [&](int level, int name, const void* value, socklen_t size, const char* what) {
    if (::setsockopt(fd_, level, name, value, size) < 0 && strict)
      throw std::runtime_error(ErrnoText(std::string("setsockopt ") + what));
  };
  const int one = 1;
  if (strict) {
    std::vector<can_filter> filters;
    for (const KernelFilter& f : o.filters) filters.push_back({f.id, f.mask});
    if (!filters.empty())
      set(SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
          static_cast<socklen_t>(filters.size() * sizeof(can_filter)), "CAN_RAW_FILTER");
    const can_err_mask_t err_mask = o.error_mask & CAN_ERR_MASK;
    set(SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask, "CAN_RAW_ERR_FILTER");
    if (o.fd_frames) set(SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &one, sizeof one, "CAN_RAW_FD_FRAMES");
  }
  if (o.kernel_timestamps) set(SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one, "SO_TIMESTAMP");
  // Not every socket type knows SO_RXQ_OVFL; losing the counter is not worth failing for.
  if (o.drop_counter) ::setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one);
  if (o.receive_buffer_bytes > 0)
    set(SOL_SOCKET, SO_RCVBUF, &o.receive_buffer_bytes, sizeof(int), "SO_RCVBUF");
}

SocketCanSource::~SocketCanSource() {
  if (fd_ >= 0) ::close(fd_);
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void SocketCanSource::Close() {
  done_.store(true);
  if (wake_fd_ >= 0) {
    const uint64_t one = 1;
    [[maybe_unused]] ssize_t n = ::write(wake_fd_, &one, sizeof one);
  }
}

std::optional<Frame> SocketCanSource::Next(int64_t timeout_us) {
  alignas(canfd_frame) unsigned char buffer[CANFD_MTU + 8];
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(uint32_t)) + 64];
  for (;;) {
    if (done_.load()) return std::nullopt;
    iovec iov{buffer, sizeof buffer};
    msghdr msg;
    std::memset(&msg, 0, sizeof msg);
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        ++stats_.read_errors;
        if (errno == ENETDOWN || errno == EBADF || errno == ENODEV) done_.store(true);
        return std::nullopt;
      }
      if (timeout_us == 0) return std::nullopt;
      // Wait for data or for Close().
      pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
      timespec ts{static_cast<time_t>(timeout_us / 1000000), static_cast<long>(timeout_us % 1000000) * 1000};
      const int r = ::ppoll(fds, 2, timeout_us < 0 ? nullptr : &ts, nullptr);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) return std::nullopt;  // timeout (or poll failure)
      if (fds[1].revents) return std::nullopt;
      if (fds[0].revents & (POLLERR | POLLNVAL)) {
        ++stats_.read_errors;
        return std::nullopt;
      }
      timeout_us = 0;  // data is there: read it without waiting again
      continue;
    }
    if (n == 0) {  // peer closed (socketpair); a CAN_RAW socket never reads 0 bytes
      done_.store(true);
      return std::nullopt;
    }
    Frame f;
    if ((msg.msg_flags & MSG_TRUNC) || !FrameFromKernel(buffer, static_cast<size_t>(n), &f)) {
      ++stats_.read_errors;
      continue;
    }
    const ReceiveMeta meta = ParseControlMessages(msg);
    f.utime = meta.has_timestamp ? meta.utime : WallClockUtime();
    if (meta.has_drop_count) stats_.kernel_drops = meta.drop_count;
    f.SetInterface(interface_);
    ++stats_.frames;
    if (f.error) CountErrorFrame(f, &stats_);
    return f;
  }
}

bool SocketCanSource::Send(const Frame& frame) {
  alignas(canfd_frame) unsigned char buffer[CANFD_MTU];
  const size_t n = FrameToKernel(frame, buffer);
  return ::send(fd_, buffer, n, MSG_DONTWAIT | MSG_NOSIGNAL) == static_cast<ssize_t>(n);
}

}  // namespace sedbridge::sensors
