#pragma once
// The one generic LCM publisher: any lcm-gen message on any channel, on the bus and,
// optionally, into an LCM event log. Converters (one per message) make the messages:
// display_command_message.h, merkel_sed_message.h, tactile_scan_message.h.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "display/command_authenticator.h"
#include "lcm/lcm_channels.h"
#include "lcm/lcm_log_writer.h"

namespace sedbridge::lcm_io {

/// One LCM connection plus channel names. Publishing never throws in the real-time path: a
/// failed send is counted (publish_errors()) and the run goes on; the next command follows
/// within one period anyway. Not thread-safe.
///
///   LcmPublisher out(settings.url, settings.channels);     // "memq://" in tests
///   out.OpenLog("out/run.lcmlog");                          // optional
///   out.Publish(out.channels().command, ToLcm(controller.OnSedField(field, now)));
class LcmPublisher {
 public:
  /// @param[in] url       LCM provider URL, e.g. kDefaultLcmUrl, "memq://", "udpm://...?ttl=1"
  /// @param[in] channels  validated (UPPER_SNAKE); throws std::invalid_argument otherwise
  /// Throws std::runtime_error when LCM cannot be initialised with `url`.
  explicit LcmPublisher(const std::string& url = kDefaultLcmUrl, LcmChannels channels = {});

  /// Also writes every later published message to an LCM event log at `path`
  /// (replay: `lcm-logplayer path`). Throws std::runtime_error if it cannot be created.
  void OpenLog(const std::string& path);

  /// Signs every later message on channels().command (DISPLAY_COMMAND) on the bus with `auth`
  /// (payload || HMAC tag); the log still gets the plain message. nullptr = unsigned.
  void SetAuthenticator(std::shared_ptr<const display::CommandAuthenticator> auth) { auth_ = std::move(auth); }

  /// Any lcm-gen message on any channel; the log timestamp is msg.utime. Never throws: a
  /// failed send (or signature) counts in publish_errors(), a failed log write in log_errors().
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
  void PublishSigned(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes);
  void LogRaw(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes);

  std::string url_;
  LcmChannels channels_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<LcmLogWriter> log_;
  std::shared_ptr<const display::CommandAuthenticator> auth_;
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

}  // namespace sedbridge::lcm_io
