#pragma once
// Feeds a ViewState from a live LCM bus (any LCM URL): raw subscriptions to the bridge's
// channels, every finger's (ViewState::SubscriptionPatterns), decoded by ViewState's size-safe
// path. Subscribes only; it publishes nothing.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "view/view_state.h"

namespace lcm {
class LCM;
}

namespace sedbridge::view {

class LiveSource {
 public:
  /// Throws std::runtime_error when LCM cannot be opened at `url`.
  LiveSource(const std::string& url, const std::vector<std::string>& patterns, ViewState* state, std::mutex* state_mutex);
  ~LiveSource();
  /// Handles the messages that arrive within `timeout_ms`.
  void Handle(int timeout_ms);
  int64_t received() const { return received_; }

 private:
  std::unique_ptr<lcm::LCM> lcm_;
  ViewState* state_;
  std::mutex* mu_;
  int64_t received_ = 0;
};

}  // namespace sedbridge::view
