#include "lcm/lcm_publisher.h"

#include <stdexcept>

namespace sedbridge::lcm_io {

LcmPublisher::LcmPublisher(const std::string& url, LcmChannels channels)
    : url_(url), channels_(std::move(channels)) {
  channels_.Validate();
  lcm_ = std::make_unique<lcm::LCM>(url_);
  if (!lcm_->good())
    throw std::runtime_error("cannot initialise LCM with URL '" + url_ +
                             "' (udpm needs a multicast route; try memq:// or see README)");
}

void LcmPublisher::OpenLog(const std::string& path) { log_ = std::make_unique<LcmLogWriter>(path); }

void LcmPublisher::PublishRaw(const std::string& channel, int64_t utime,
                              const std::vector<uint8_t>& bytes) {
  if (auth_ && channel == channels_.command) {
    PublishSigned(channel, utime, bytes);
    return;
  }
  const int size = static_cast<int>(bytes.size());
  if (lcm_->publish(channel, bytes.data(), static_cast<unsigned>(size)) == 0) ++published_;
  else ++publish_errors_;
  LogRaw(channel, utime, bytes);
}

void LcmPublisher::PublishSigned(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
  std::vector<uint8_t> signed_bytes;
  try {
    signed_bytes = auth_->Sign(bytes.data(), bytes.size());
  } catch (const std::exception&) {
    ++publish_errors_;  // never throw in the loop; an unsigned command would be rejected anyway
    return;
  }
  if (lcm_->publish(channel, signed_bytes.data(), static_cast<unsigned>(signed_bytes.size())) == 0)
    ++published_;
  else
    ++publish_errors_;
  LogRaw(channel, utime, bytes);  // the record keeps the plain message
}

void LcmPublisher::LogRaw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
  if (!log_) return;
  try {
    log_->WriteRaw(channel, utime, bytes.data(), static_cast<int32_t>(bytes.size()));
  } catch (const std::runtime_error&) {
    ++log_errors_;  // disk full: keep driving the display; the caller sees the counter
  }
}

}  // namespace sedbridge::lcm_io
