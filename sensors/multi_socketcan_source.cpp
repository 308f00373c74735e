#include "sensors/multi_socketcan_source.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <ctime>
#include <set>
#include <stdexcept>

namespace sedbridge::sensors {

MultiSocketCanSource::MultiSocketCanSource(std::vector<std::unique_ptr<SocketCanSource>> buses)
    : buses_(std::move(buses)) {
  if (buses_.empty()) throw std::invalid_argument("MultiSocketCanSource needs at least one bus");
  std::set<std::string> names;
  for (const auto& bus : buses_) {
    if (!bus) throw std::invalid_argument("MultiSocketCanSource: null bus");
    if (!names.insert(bus->interface_name()).second)
      throw std::invalid_argument("MultiSocketCanSource: bus '" + bus->interface_name() + "' given twice");
  }
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) throw std::runtime_error("eventfd failed");
}

std::unique_ptr<MultiSocketCanSource> MultiSocketCanSource::Open(const std::vector<SocketCanOptions>& buses) {
  std::vector<std::unique_ptr<SocketCanSource>> open;
  for (const SocketCanOptions& o : buses) {
    try {
      open.push_back(std::make_unique<SocketCanSource>(o));
    } catch (const std::exception& e) {
      throw std::runtime_error("CAN bus '" + o.interface + "': " + e.what());
    }
  }
  return std::make_unique<MultiSocketCanSource>(std::move(open));
}

MultiSocketCanSource::~MultiSocketCanSource() {
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

std::optional<Frame> MultiSocketCanSource::Next(int64_t timeout_us) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::microseconds(timeout_us < 0 ? 0 : timeout_us);
  std::vector<pollfd> fds;
  for (;;) {
    if (closed_.load()) return std::nullopt;
    // A frame already waiting on some bus, starting after the one served last.
    for (size_t k = 0; k < buses_.size(); ++k) {
      const size_t i = (next_bus_ + k) % buses_.size();
      if (buses_[i]->Done()) continue;
      if (std::optional<Frame> f = buses_[i]->Next(0)) {
        next_bus_ = (i + 1) % buses_.size();
        return f;
      }
    }
    if (Done() || timeout_us == 0) return std::nullopt;
    int64_t left_us = -1;
    if (timeout_us > 0) {
      left_us = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
      if (left_us <= 0) return std::nullopt;
    }
    fds.clear();
    for (const auto& bus : buses_)
      if (!bus->Done()) fds.push_back({bus->descriptor(), POLLIN, 0});
    fds.push_back({wake_fd_, POLLIN, 0});
    timespec ts{static_cast<time_t>(left_us / 1000000), static_cast<long>(left_us % 1000000) * 1000};
    const int r = ::ppoll(fds.data(), fds.size(), left_us < 0 ? nullptr : &ts, nullptr);
    if (r < 0 && errno != EINTR) return std::nullopt;
    if (r == 0) return std::nullopt;  // timeout
    // Data (or an error to count) on some bus: the loop's Next(0) reads it.
  }
}

bool MultiSocketCanSource::Done() const {
  if (closed_.load()) return true;
  for (const auto& bus : buses_)
    if (!bus->Done()) return false;
  return true;
}

void MultiSocketCanSource::Close() {
  closed_.store(true);
  for (auto& bus : buses_) bus->Close();
  const uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(wake_fd_, &one, sizeof one);
}

FrameSourceStats MultiSocketCanSource::Stats() const {
  FrameSourceStats sum;
  for (const auto& bus : buses_) {
    const FrameSourceStats s = bus->Stats();
    sum.frames += s.frames;
    sum.error_frames += s.error_frames;
    sum.bus_off += s.bus_off;
    sum.error_passive += s.error_passive;
    sum.error_warning += s.error_warning;
    sum.controller_overflow += s.controller_overflow;
    sum.restarted += s.restarted;
    sum.other_errors += s.other_errors;
    sum.kernel_drops += s.kernel_drops;
    sum.bad_lines += s.bad_lines;
    sum.read_errors += s.read_errors;
  }
  return sum;
}

FrameSourceStats MultiSocketCanSource::Stats(const std::string& interface) const {
  for (const auto& bus : buses_)
    if (bus->interface_name() == interface) return bus->Stats();
  return {};
}

std::string MultiSocketCanSource::Describe() const {
  std::string names;
  for (const auto& bus : buses_) names += (names.empty() ? "" : "+") + bus->interface_name();
  return "socketcan " + names;
}

bool MultiSocketCanSource::Send(const std::string& interface, const Frame& frame) {
  for (auto& bus : buses_)
    if (bus->interface_name() == interface) return bus->Send(frame);
  return false;
}

}  // namespace sedbridge::sensors
