#include "view/frame_hub.h"

namespace sedbridge::view {

void FrameHub::Publish(std::string frame) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    frame_ = std::move(frame);
    ++number_;
  }
  cv_.notify_all();
}

std::string FrameHub::Latest(uint64_t* number) const {
  std::lock_guard<std::mutex> lock(mu_);
  if (number) *number = number_;
  return frame_;
}

bool FrameHub::WaitNewer(uint64_t* seen, std::string* frame, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mu_);
  if (!cv_.wait_for(lock, timeout, [&] { return closed_ || number_ > *seen; })) return false;
  if (closed_) return false;
  *seen = number_;
  *frame = frame_;
  return true;
}

void FrameHub::Close() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    closed_ = true;
  }
  cv_.notify_all();
}

bool FrameHub::closed() const {
  std::lock_guard<std::mutex> lock(mu_);
  return closed_;
}

}  // namespace sedbridge::view
