#include "display/lcm_publisher.h"

#include <stdexcept>

#include "display/lcm_conversions.h"

namespace sedbridge::display {

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
  const int size = static_cast<int>(bytes.size());
  if (lcm_->publish(channel, bytes.data(), static_cast<unsigned>(size)) == 0) ++published_;
  else ++publish_errors_;
  LogRaw(channel, utime, bytes);
}

void LcmPublisher::LogRaw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
  if (!log_) return;
  try {
    log_->WriteRaw(channel, utime, bytes.data(), static_cast<int32_t>(bytes.size()));
  } catch (const std::runtime_error&) {
    ++log_errors_;  // disk full: keep driving the display; the caller sees the counter
  }
}

void LcmPublisher::PublishCommand(const DisplayCommand& command) {
  if (!auth_) {
    Publish(channels_.command, ToLcm(command));
    return;
  }
  const lcmt_display_command m = ToLcm(command);
  buffer_.resize(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(buffer_.data(), 0, static_cast<int>(buffer_.size()));
  std::vector<uint8_t> signed_bytes;
  try {
    signed_bytes = auth_->Sign(buffer_.data(), buffer_.size());
  } catch (const std::exception&) {
    ++publish_errors_;  // never throw in the loop; an unsigned command would be rejected anyway
    return;
  }
  if (lcm_->publish(channels_.command, signed_bytes.data(), static_cast<unsigned>(signed_bytes.size())) == 0)
    ++published_;
  else
    ++publish_errors_;
  LogRaw(channels_.command, m.utime, buffer_);  // the record keeps the plain message
}

void LcmPublisher::PublishSed(const SedField& field) { Publish(channels_.sed, ToLcm(field)); }

void LcmPublisher::PublishStatus(const lcmt_bridge_status& status) {
  Publish(channels_.status, status);
}

void LcmPublisher::PublishSa1Rate(const lcmt_sa1_rate_estimate& estimate) {
  Publish(channels_.sa1_rate, estimate);
}

void LcmPublisher::PublishTactileScan(const lcmt_tactile_scan& scan) {
  Publish(channels_.tactile_scan, scan);
}

}  // namespace sedbridge::display
