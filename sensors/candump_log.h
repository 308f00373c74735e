#pragma once
// candump `-l` text logs (can-utils), read and written in the format canplayer replays:
//
//   (1699999999.123456) can0 123#DEADBEEF          classic, 11-bit id (3 hex digits)
//   (1699999999.123456) can0 1F334455#0011         classic, 29-bit id (8 hex digits)
//   (1699999999.123456) can0 123#R   123#R5        remote frame (optional length digit)
//   (1699999999.123456) can0 123##1DEADBEEF        CAN FD; the nibble after ## is the flags
//                                                  (1 = BRS, 2 = ESI)
//   (1699999999.123456) can0 20000004#0004000000000000   error frame (CAN_ERR_FLAG set)
//
// Time stamps have 6 (microseconds) or 9 (nanoseconds, truncated to us) fraction digits.
// Classic frames may carry can-utils' "_D" raw-DLC suffix (accepted, ignored). A trailing
// direction token (" R" / " T", written by newer candump) is accepted. Empty lines and lines
// starting with '#' are skipped; every other line that is not a frame is a bad line: it is
// counted with its line number and reading goes on.

#include <cstdint>
#include <istream>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "sensors/can_frame.h"
#include "sensors/frame_source.h"

namespace sedbridge::sensors {

enum class LineKind {
  kFrame,  ///< the line held a frame
  kSkip,   ///< empty line or '#' comment
  kBad,    ///< not a frame; `error` says why
};

struct LineResult {
  LineKind kind = LineKind::kBad;
  const char* error = nullptr;  ///< static string, set for kBad
};

/// Parses one log line (without its newline; a trailing '\r' is tolerated) into `frame`.
/// Never throws, never reads outside `line`.
LineResult ParseCandumpLine(std::string_view line, Frame* frame);

/// Appends one log line for `frame` (with '\n') to `out`. Seconds are zero-padded to 10
/// digits and microseconds to 6, as candump writes them.
void AppendCandumpLine(const Frame& frame, std::string* out);
/// Same, as a string without the newline.
std::string FormatCandumpLine(const Frame& frame);

/// A line the reader could not use.
struct BadLine {
  int64_t line_number = 0;  ///< 1-based
  std::string reason;
  std::string text;  ///< the line, cut to 120 characters
};

/// Reads frames from a candump log stream line by line; bad lines are counted and the
/// first `max_kept_bad_lines` of them kept for reporting.
/// Longest candump line read [bytes]; longer lines are bad lines, skipped without storing.
constexpr size_t kMaxLineBytes = 4096;
/// Bad lines a reader keeps for its report by default: enough to see a pattern, bounded so a
/// log of garbage cannot fill memory (the count goes on).
constexpr size_t kDefaultKeptBadLines = 1000;

class CandumpLogReader {
 public:
  /// `name` is used in messages (usually the file name). The stream must outlive the reader.
  explicit CandumpLogReader(std::istream& in, std::string name = "log",
                            size_t max_kept_bad_lines = kDefaultKeptBadLines);

  /// Next frame; false at the end of the stream.
  bool Next(Frame* frame);

  int64_t lines_read() const { return line_number_; }
  int64_t frames_read() const { return frames_; }
  int64_t bad_line_count() const { return bad_lines_; }
  const std::vector<BadLine>& bad_lines() const { return kept_bad_lines_; }
  const std::string& name() const { return name_; }

 private:
  std::istream& in_;
  std::string name_;
  size_t max_kept_;
  std::string line_;
  int64_t line_number_ = 0, frames_ = 0, bad_lines_ = 0;
  std::vector<BadLine> kept_bad_lines_;
};

/// Writes frames as candump -l lines.
class CandumpLogWriter {
 public:
  explicit CandumpLogWriter(std::ostream& out) : out_(out) {}
  void Write(const Frame& frame);
  void Flush();
  int64_t frames_written() const { return frames_; }

 private:
  std::ostream& out_;
  std::string buffer_;
  int64_t frames_ = 0;
};

/// How a log is played back.
struct PlaybackOptions {
  /// 0 = as fast as possible; 1 = recorded timing; 2 = twice as fast; 0.5 = half speed.
  double speed = 0;
  /// Replace each frame's utime by the wall-clock time it is handed out (for feeding a
  /// live bridge); false keeps the recorded time stamps.
  bool restamp = false;
};

/// A candump log as a FrameSource.
class CandumpLogSource final : public FrameSource {
 public:
  /// Opens `path`; throws config::ConfigError if it cannot be opened.
  CandumpLogSource(const std::string& path, PlaybackOptions options = {});
  /// Reads from an already open stream (tests, stdin); `name` is used in messages; the first
  /// `max_kept_bad_lines` bad lines are kept (reader().bad_lines()).
  CandumpLogSource(std::unique_ptr<std::istream> in, std::string name,
                   PlaybackOptions options = {}, size_t max_kept_bad_lines = kDefaultKeptBadLines);
  ~CandumpLogSource() override;

  std::optional<Frame> Next(int64_t timeout_us) override;
  bool Done() const override { return done_; }
  void Close() override { done_ = true; }
  FrameSourceStats Stats() const override;
  std::string Describe() const override;

  const CandumpLogReader& reader() const { return *reader_; }

 private:
  std::unique_ptr<std::istream> in_;
  std::unique_ptr<CandumpLogReader> reader_;
  PlaybackOptions options_;
  bool done_ = false;
  bool have_pending_ = false;
  Frame pending_;
  // Playback clock: wall time (steady, us) that corresponds to log time `log_origin_utime_`.
  bool clock_started_ = false;
  int64_t wall_origin_us_ = 0, log_origin_utime_ = 0;
  FrameSourceStats stats_;
};

}  // namespace sedbridge::sensors
