#include "sensors/interface_filter_source.h"

namespace sedbridge::sensors {

InterfaceFilterSource::InterfaceFilterSource(FrameSource& inner, std::string interface)
    : inner_(inner), interface_(std::move(interface)) {}

std::optional<Frame> InterfaceFilterSource::Next(int64_t timeout_us) {
  // Blocking reads (timeout < 0, as a log replay does) skip on to the next kept frame; a
  // bounded read returns nullopt after a skipped frame, as on a timeout, so a busy other
  // bus cannot stretch the caller's wait.
  while (true) {
    std::optional<Frame> f = inner_.Next(timeout_us);
    if (!f) return f;
    const std::string name = f->Interface();
    if (seen_.size() < 64) seen_.insert(name);  // bounded: a corrupt log cannot grow it without end
    if (interface_.empty() || name == interface_) {
      ++passed_;
      return f;
    }
    ++skipped_;
    if (timeout_us >= 0) return std::nullopt;
  }
}

FrameSourceStats InterfaceFilterSource::Stats() const {
  FrameSourceStats s = inner_.Stats();
  s.frames = passed_;
  return s;
}

std::string InterfaceFilterSource::Describe() const {
  return interface_.empty() ? inner_.Describe() : inner_.Describe() + " (interface " + interface_ + " only)";
}

}  // namespace sedbridge::sensors
