#pragma once
// Writes LCM event logs (the lcm-logger format) that lcm-logplayer replays and lcm-spy shows.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace lcm {
class LogFile;
}

namespace sedbridge::lcm_io {

class LcmLogWriter {
 public:
  /// Creates/truncates `path`. Throws std::runtime_error if it cannot be opened.
  explicit LcmLogWriter(const std::string& path);
  ~LcmLogWriter();
  LcmLogWriter(const LcmLogWriter&) = delete;
  LcmLogWriter& operator=(const LcmLogWriter&) = delete;

  /// Appends one event. `timestamp_utime` [us] is what lcm-logplayer paces replay by.
  /// Throws std::runtime_error on a write error (disk full).
  void WriteRaw(const std::string& channel, int64_t timestamp_utime, const void* data,
                int32_t size);

  /// Encodes an lcm-gen message and appends it, stamped with the message's own utime.
  template <typename Msg>
  void Write(const std::string& channel, const Msg& msg) {
    std::vector<uint8_t> buf(msg.getEncodedSize());
    msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
    WriteRaw(channel, msg.utime, buf.data(), static_cast<int32_t>(buf.size()));
  }

  /// Flushes buffered events to the file (e.g. after each second of a run).
  void Flush();

  int64_t events_written() const { return events_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t events_ = 0;
};

}  // namespace sedbridge::lcm_io
