#include "sensors/merged_frame_source.h"

#include <stdexcept>

namespace sedbridge::sensors {

MergedFrameSource::MergedFrameSource(std::vector<std::unique_ptr<FrameSource>> sources)
    : sources_(std::move(sources)), waiting_(sources_.size()) {
  if (sources_.empty()) throw std::invalid_argument("merged frame source: no source");
  for (const auto& s : sources_)
    if (!s) throw std::invalid_argument("merged frame source: a null source");
}

std::optional<Frame> MergedFrameSource::Next(int64_t timeout_us) {
  if (closed_) return std::nullopt;
  size_t earliest = waiting_.size();
  for (size_t i = 0; i < sources_.size(); ++i) {
    if (!waiting_[i] && !sources_[i]->Done()) waiting_[i] = sources_[i]->Next(timeout_us);
    if (waiting_[i] && (earliest == waiting_.size() || waiting_[i]->utime < waiting_[earliest]->utime)) earliest = i;
  }
  if (earliest == waiting_.size()) return std::nullopt;
  std::optional<Frame> f = std::move(waiting_[earliest]);
  waiting_[earliest].reset();
  return f;
}

bool MergedFrameSource::Done() const {
  if (closed_) return true;
  for (size_t i = 0; i < sources_.size(); ++i)
    if (waiting_[i] || !sources_[i]->Done()) return false;
  return true;
}

void MergedFrameSource::Close() {
  closed_ = true;
  for (auto& s : sources_) s->Close();
}

FrameSourceStats MergedFrameSource::Stats() const {
  FrameSourceStats sum;
  for (const auto& s : sources_) {
    const FrameSourceStats t = s->Stats();
    sum.frames += t.frames, sum.error_frames += t.error_frames, sum.bus_off += t.bus_off;
    sum.error_passive += t.error_passive, sum.error_warning += t.error_warning;
    sum.controller_overflow += t.controller_overflow, sum.restarted += t.restarted;
    sum.other_errors += t.other_errors, sum.kernel_drops += t.kernel_drops, sum.bad_lines += t.bad_lines;
    sum.read_errors += t.read_errors;
  }
  return sum;
}

std::string MergedFrameSource::Describe() const {
  std::string d = "merged:";
  for (size_t i = 0; i < sources_.size(); ++i) d += (i ? "; " : " ") + sources_[i]->Describe();
  return d;
}

}  // namespace sedbridge::sensors
