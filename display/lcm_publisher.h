#pragma once
// Publishes the display stage's messages on LCM (and, optionally, into an LCM event log).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "display/command_authenticator.h"
#include "display/display_command.h"
#include "display/lcm_channels.h"
#include "display/lcm_log_writer.h"
#include "display/sed_field.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"
#include "sedbridge/lcmt_tactile_scan.hpp"

namespace sedbridge::display {

/// One LCM connection plus channel names. Publishing never throws in the real-time path: a
/// failed send is counted (publish_errors()) and the run goes on; the next command follows
/// within one period anyway. Not thread-safe.
///
///   LcmPublisher out(settings.url, settings.channels);     // "memq://" in tests
///   out.OpenLog("out/run.lcmlog");                          // optional
///   out.PublishCommand(controller.OnSedField(field, now));
class LcmPublisher {
 public:
  /// @param[in] url       LCM provider URL, e.g. kDefaultLcmUrl, "memq://", "udpm://...?ttl=1"
  /// @param[in] channels  validated (UPPER_SNAKE); throws std::invalid_argument otherwise
  /// Throws std::runtime_error when LCM cannot be initialised with `url`.
  explicit LcmPublisher(const std::string& url = kDefaultLcmUrl, LcmChannels channels = {});

  /// Also writes every later published message to an LCM event log at `path`
  /// (replay: `lcm-logplayer path`). Throws std::runtime_error if it cannot be created.
  void OpenLog(const std::string& path);

  /// Signs every later DISPLAY_COMMAND on the bus with `auth` (payload || HMAC tag); the
  /// log still gets the plain message. nullptr = unsigned.
  void SetAuthenticator(std::shared_ptr<const CommandAuthenticator> auth) { auth_ = std::move(auth); }

  void PublishCommand(const DisplayCommand& command);
  void PublishSed(const SedField& field);
  void PublishStatus(const lcmt_bridge_status& status);
  void PublishSa1Rate(const lcmt_sa1_rate_estimate& estimate);
  void PublishTactileScan(const lcmt_tactile_scan& scan);

  /// Any lcm-gen message on any channel; the log timestamp is msg.utime.
  template <typename Msg>
  void Publish(const std::string& channel, const Msg& msg);

  lcm::LCM& lcm() { return *lcm_; }  ///< e.g. to subscribe on the same memq:// instance
  const LcmChannels& channels() const { return channels_; }
  const std::string& url() const { return url_; }
  int64_t published() const { return published_; }
  int64_t publish_errors() const { return publish_errors_; }
  int64_t log_errors() const { return log_errors_; }
  LcmLogWriter* log() { return log_.get(); }

 private:
  void PublishRaw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes);
  void LogRaw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes);

  std::string url_;
  LcmChannels channels_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<LcmLogWriter> log_;
  std::shared_ptr<const CommandAuthenticator> auth_;
  std::vector<uint8_t> buffer_;
  int64_t published_ = 0;
  int64_t publish_errors_ = 0;
  int64_t log_errors_ = 0;
};

template <typename Msg>
void LcmPublisher::Publish(const std::string& channel, const Msg& msg) {
  buffer_.resize(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(buffer_.data(), 0, static_cast<int>(buffer_.size()));
  PublishRaw(channel, msg.utime, buffer_);
}

}  // namespace sedbridge::display
