#include "view/live_source.h"

#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

namespace sedbridge::view {

LiveSource::LiveSource(const std::string& url, const std::vector<std::string>& patterns, ViewState* state,
                       std::mutex* state_mutex)
    : lcm_(std::make_unique<lcm::LCM>(url)), state_(state), mu_(state_mutex) {
  if (!lcm_->good()) throw std::runtime_error("cannot open LCM at '" + url + "'");
  for (const std::string& channel : patterns)
    lcm_->subscribeFunction(
        channel,
        +[](const lcm::ReceiveBuffer* rbuf, const std::string& ch, LiveSource* self) {
          std::lock_guard<std::mutex> lock(*self->mu_);
          ++self->received_;
          self->state_->OnEvent(ch, rbuf->data, rbuf->data_size, rbuf->recv_utime);
        },
        this);
}

LiveSource::~LiveSource() = default;

void LiveSource::Handle(int timeout_ms) { lcm_->handleTimeout(timeout_ms); }

}  // namespace sedbridge::view
