#include "sensors/candump_log.h"

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "common/config_error.h"
#include "common/wall_clock.h"

namespace sedbridge::sensors {

namespace {

constexpr uint32_t kErrFlag = 0x20000000u;  // CAN_ERR_FLAG as candump prints it

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool IsSpace(char c) { return c == ' ' || c == '\t'; }

LineResult Bad(const char* why) { return {LineKind::kBad, why}; }

/// Parses "(sec.frac)" at the start of `s`; advances `s` past it.
bool ParseTimestamp(std::string_view& s, int64_t* utime, const char** error) {
  if (s.empty() || s[0] != '(') return *error = "line does not start with '(' time stamp", false;
  size_t i = 1;
  int64_t sec = 0;
  int sec_digits = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (++sec_digits > 12) return *error = "time stamp seconds too large", false;
    sec = sec * 10 + (s[i] - '0');
    ++i;
  }
  if (sec_digits == 0 || i >= s.size() || s[i] != '.')
    return *error = "time stamp must be (seconds.fraction)", false;
  ++i;
  int64_t frac = 0;
  int frac_digits = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
    if (frac_digits < 6) frac = frac * 10 + (s[i] - '0');
    ++frac_digits;
    ++i;
  }
  if (frac_digits != 6 && frac_digits != 9)
    return *error = "time stamp needs 6 or 9 fraction digits", false;
  if (i >= s.size() || s[i] != ')') return *error = "time stamp not closed by ')'", false;
  *utime = sec * 1000000 + frac;
  s.remove_prefix(i + 1);
  return true;
}

/// Parses hex byte pairs (optionally '.'-separated) from `s` into data; stops at the end or
/// at '_' (raw DLC suffix). Returns byte count or -1.
int ParseHexBytes(std::string_view s, size_t* consumed, uint8_t* data, int max_len,
                  const char** error) {
  size_t i = 0;
  int n = 0;
  while (i < s.size() && s[i] != '_') {
    if (s[i] == '.') {
      ++i;
      continue;
    }
    if (i + 1 >= s.size()) return *error = "odd number of hex digits in data", -1;
    const int hi = HexValue(s[i]), lo = HexValue(s[i + 1]);
    if (hi < 0 || lo < 0) return *error = "data is not hexadecimal", -1;
    if (n >= max_len) return *error = "too many data bytes for the frame type", -1;
    data[n++] = static_cast<uint8_t>(hi << 4 | lo);
    i += 2;
  }
  *consumed = i;
  return n;
}

const char kHexUpper[] = "0123456789ABCDEF";

void AppendHex(uint32_t v, int digits, std::string* out) {
  for (int d = digits - 1; d >= 0; --d) out->push_back(kHexUpper[(v >> (4 * d)) & 0xF]);
}

void AppendDecimal(int64_t v, int min_digits, std::string* out) {
  char buf[24];
  int n = 0;
  uint64_t u = v < 0 ? 0 : static_cast<uint64_t>(v);
  do {
    buf[n++] = static_cast<char>('0' + u % 10);
    u /= 10;
  } while (u);
  while (n < min_digits) buf[n++] = '0';
  while (n) out->push_back(buf[--n]);
}

}  // namespace

LineResult ParseCandumpLine(std::string_view s, Frame* f) {
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || IsSpace(s.back()))) s.remove_suffix(1);
  while (!s.empty() && IsSpace(s.front())) s.remove_prefix(1);
  if (s.empty() || s[0] == '#') return {LineKind::kSkip, nullptr};

  const char* error = nullptr;
  *f = Frame{};
  if (!ParseTimestamp(s, &f->utime, &error)) return Bad(error);

  // Interface name.
  if (s.empty() || !IsSpace(s[0])) return Bad("expected a space after the time stamp");
  while (!s.empty() && IsSpace(s[0])) s.remove_prefix(1);
  size_t n = 0;
  while (n < s.size() && !IsSpace(s[n])) ++n;
  if (n == 0) return Bad("missing interface name");
  if (n >= kInterfaceNameMax) return Bad("interface name longer than 15 characters");
  for (size_t i = 0; i < n; ++i) {
    if (s[i] == '#') return Bad("missing interface name before the frame");
    if (s[i] < 0x21 || s[i] > 0x7E) return Bad("interface name has non-printable characters");
  }
  std::copy(s.begin(), s.begin() + n, f->interface.begin());
  s.remove_prefix(n);

  // Frame token, then an optional direction flag.
  while (!s.empty() && IsSpace(s[0])) s.remove_prefix(1);
  if (s.empty()) return Bad("missing frame after the interface name");
  size_t tok = 0;
  while (tok < s.size() && !IsSpace(s[tok])) ++tok;
  std::string_view trailer = s.substr(tok);
  while (!trailer.empty() && IsSpace(trailer[0])) trailer.remove_prefix(1);
  if (!trailer.empty() && !(trailer.size() == 1 && (trailer[0] == 'R' || trailer[0] == 'T')))
    return Bad("unexpected text after the frame");
  s = s.substr(0, tok);

  // Identifier.
  size_t id_digits = 0;
  uint32_t id = 0;
  while (id_digits < s.size() && s[id_digits] != '#') {
    const int h = HexValue(s[id_digits]);
    if (h < 0) return Bad("identifier is not hexadecimal");
    if (++id_digits > 8) return Bad("identifier longer than 8 hex digits");
    id = id << 4 | static_cast<uint32_t>(h);
  }
  if (id_digits == s.size()) return Bad("missing '#' between identifier and data");
  if (id_digits == 3) {
    if (id > kCanStdIdMask) return Bad("11-bit identifier above 0x7FF");
    f->id = id;
  } else if (id_digits == 8) {
    if (id & kErrFlag) {
      f->error = true;
      f->id = id & kCanExtIdMask & ~kErrFlag;
    } else {
      if (id > kCanExtIdMask) return Bad("29-bit identifier above 0x1FFFFFFF");
      f->extended = true;
      f->id = id;
    }
  } else {
    return Bad("identifier must have 3 (11-bit) or 8 (29-bit) hex digits");
  }
  s.remove_prefix(id_digits + 1);  // past '#'

  if (!s.empty() && s[0] == '#') {  // CAN FD
    s.remove_prefix(1);
    if (!s.empty() && s[0] == '#') return Bad("CAN XL frames are not supported");
    if (f->error) return Bad("error frames cannot be CAN FD");
    if (s.empty()) return Bad("CAN FD frame lacks its flags nibble");
    const int flags = HexValue(s[0]);
    if (flags < 0) return Bad("CAN FD flags nibble is not hexadecimal");
    s.remove_prefix(1);
    f->fd = true;
    f->fd_flags = static_cast<uint8_t>(flags);
    size_t used = 0;
    const int len = ParseHexBytes(s, &used, f->data.data(), kCanFdMaxLen, &error);
    if (len < 0) return Bad(error);
    if (used != s.size()) return Bad("unexpected '_' in CAN FD data");
    if (!IsValidFdLength(len)) return Bad("CAN FD data length is not 0-8,12,16,20,24,32,48,64");
    f->len = static_cast<uint8_t>(len);
    return {LineKind::kFrame, nullptr};
  }

  size_t used = 0;
  if (!s.empty() && (s[0] == 'R' || s[0] == 'r')) {
    if (f->error) return Bad("error frames cannot be remote frames");
    f->remote = true;
    s.remove_prefix(1);
    if (!s.empty() && s[0] >= '0' && s[0] <= '8') {
      f->len = static_cast<uint8_t>(s[0] - '0');
      s.remove_prefix(1);
    }
  } else {
    const int len = ParseHexBytes(s, &used, f->data.data(), kCanMaxLen, &error);
    if (len < 0) return Bad(error);
    f->len = static_cast<uint8_t>(len);
    s.remove_prefix(used);
  }
  if (!s.empty()) {  // "_D": raw DLC 9..F of an 8-byte classic frame
    if (s.size() != 2 || s[0] != '_' || HexValue(s[1]) < 9 || f->len != 8)
      return Bad("unexpected characters after the data");
  }
  return {LineKind::kFrame, nullptr};
}

void AppendCandumpLine(const Frame& f, std::string* out) {
  out->push_back('(');
  AppendDecimal(f.utime / 1000000, 10, out);
  out->push_back('.');
  AppendDecimal(f.utime % 1000000, 6, out);
  out->append(") ");
  out->append(f.interface[0] ? f.interface.data() : "can0");
  out->push_back(' ');
  if (f.error) {
    AppendHex(kErrFlag | (f.id & kCanExtIdMask), 8, out);
  } else if (f.extended) {
    AppendHex(f.id & kCanExtIdMask, 8, out);
  } else {
    AppendHex(f.id & kCanStdIdMask, 3, out);
  }
  out->push_back('#');
  if (f.fd) {
    out->push_back('#');
    out->push_back(kHexUpper[f.fd_flags & 0xF]);
  } else if (f.remote) {
    out->push_back('R');
    if (f.len > 0 && f.len <= kCanMaxLen) out->push_back(kHexUpper[f.len]);
    out->push_back('\n');
    return;
  }
  const int len = std::min<int>(f.len, f.fd ? kCanFdMaxLen : kCanMaxLen);
  for (int i = 0; i < len; ++i) {
    out->push_back(kHexUpper[f.data[i] >> 4]);
    out->push_back(kHexUpper[f.data[i] & 0xF]);
  }
  out->push_back('\n');
}

std::string FormatCandumpLine(const Frame& f) {
  std::string s;
  AppendCandumpLine(f, &s);
  s.pop_back();
  return s;
}

// ---- reader ----

CandumpLogReader::CandumpLogReader(std::istream& in, std::string name, size_t max_kept)
    : in_(in), name_(std::move(name)), max_kept_(max_kept) {}

bool CandumpLogReader::Next(Frame* frame) {
  // Lines are read with a cap: a valid line is under 200 bytes, and one 400 MB line once
  // cost 467 MB of memory. A longer line is a bad line; the rest of it is skipped unread.
  char buffer[kMaxLineBytes + 1];
  for (;;) {
    in_.getline(buffer, sizeof buffer);
    const std::streamsize got = in_.gcount();
    if (in_.eof() && got == 0) return false;
    if (in_.bad()) return false;
    if (in_.fail() && !in_.eof()) {  // no '\n' within the cap
      in_.clear();
      in_.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
      ++line_number_;
      ++bad_lines_;
      if (kept_bad_lines_.size() < max_kept_)
        kept_bad_lines_.push_back(
            {line_number_, "line longer than " + std::to_string(kMaxLineBytes) + " bytes (skipped)",
             std::string(buffer, 120)});
      continue;
    }
    line_.assign(buffer, static_cast<size_t>(std::strlen(buffer)));
    ++line_number_;
    const LineResult r = ParseCandumpLine(line_, frame);
    if (r.kind == LineKind::kFrame) {
      ++frames_;
      return true;
    }
    if (r.kind == LineKind::kBad) {
      ++bad_lines_;
      if (kept_bad_lines_.size() < max_kept_)
        kept_bad_lines_.push_back({line_number_, r.error, line_.substr(0, 120)});
    }
    if (in_.eof()) return false;
  }
}

// ---- writer ----

void CandumpLogWriter::Write(const Frame& frame) {
  AppendCandumpLine(frame, &buffer_);
  ++frames_;
  if (buffer_.size() > 1 << 16) Flush();
}

void CandumpLogWriter::Flush() {
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
  out_.flush();
}

// ---- playback source ----

namespace {
int64_t SteadyNowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

CandumpLogSource::CandumpLogSource(const std::string& path, PlaybackOptions options)
    : options_(options) {
  if (std::filesystem::is_directory(path)) throw config::ConfigError({path, 0, 0}, "is a directory, not a candump log");
  auto file = std::make_unique<std::ifstream>(path);
  if (!*file) throw config::ConfigError({path, 0, 0}, "cannot open candump log");
  in_ = std::move(file);
  reader_ = std::make_unique<CandumpLogReader>(*in_, path);
}

CandumpLogSource::CandumpLogSource(std::unique_ptr<std::istream> in, std::string name,
                                   PlaybackOptions options, size_t max_kept_bad_lines)
    : in_(std::move(in)), options_(options) {
  reader_ = std::make_unique<CandumpLogReader>(*in_, std::move(name), max_kept_bad_lines);
}

CandumpLogSource::~CandumpLogSource() = default;

std::optional<Frame> CandumpLogSource::Next(int64_t timeout_us) {
  if (done_) return std::nullopt;
  if (!have_pending_) {
    if (!reader_->Next(&pending_)) {
      done_ = true;
      return std::nullopt;
    }
    have_pending_ = true;
  }
  if (options_.speed > 0) {
    const int64_t now = SteadyNowUs();
    if (!clock_started_) {
      clock_started_ = true;
      wall_origin_us_ = now;
      log_origin_utime_ = pending_.utime;
    }
    // Frames earlier than the first one (time going backwards) are due at once.
    const double offset_us =
        static_cast<double>(pending_.utime - log_origin_utime_) / options_.speed;
    const int64_t due = wall_origin_us_ + static_cast<int64_t>(std::max(0.0, offset_us));
    if (due > now) {
      const int64_t wait = due - now;
      if (timeout_us >= 0 && wait > timeout_us) {
        std::this_thread::sleep_for(std::chrono::microseconds(timeout_us));
        return std::nullopt;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(wait));
    }
  }
  have_pending_ = false;
  Frame f = pending_;
  if (options_.restamp) f.utime = WallClockUtime();
  ++stats_.frames;
  if (f.error) CountErrorFrame(f, &stats_);
  return f;
}

FrameSourceStats CandumpLogSource::Stats() const {
  FrameSourceStats s = stats_;
  s.bad_lines = reader_->bad_line_count();
  return s;
}

std::string CandumpLogSource::Describe() const { return "candump log " + reader_->name(); }

}  // namespace sedbridge::sensors
