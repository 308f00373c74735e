#include "display/display_controller.h"

namespace sedbridge::display {

DisplayController::DisplayController(DisplayProfile profile, CommandRequestSource requests)
    : profile_(std::move(profile)),
      mapping_(profile_),
      requests_(std::move(requests)),
      limiter_(SafetyLimits::FromProfile(profile_)) {}

DisplayCommand DisplayController::OnSedField(const SedField& field, int64_t now_utime) {
  last_mapping_ = mapping_.Map(field);
  ++stats_.fields;
  const SedFieldCheck& check = last_mapping_.check;
  const bool rejected = !check.consistent || check.non_finite_sed > 0 || check.non_finite_position > 0;
  if (rejected) ++stats_.fields_rejected;
  if (check.negative_sed > 0) ++stats_.fields_negative;
  // The curve's sampled SED per site stays (SA1 rates read it); the requests are the
  // source's. A rejected field keeps the curve's NaN: the limiter faults it either way.
  if (requests_ && !rejected) requests_(field, &last_mapping_.requested);
  const LimitedOutput& out = limiter_.Apply(now_utime, field.utime, last_mapping_.requested);
  // Provenance follows the newest field the limiter could have taken.
  if (!limiter_.is_shut_down() && field.utime > source_sed_utime_) {
    source_sed_utime_ = field.utime;
    source_scan_utime_ = field.source_scan_utime;
  }
  return Make(out, now_utime);
}

DisplayCommand DisplayController::Tick(int64_t now_utime) {
  return Make(limiter_.Tick(now_utime), now_utime);
}

DisplayCommand DisplayController::Shutdown(int64_t now_utime) {
  return Make(limiter_.Shutdown(now_utime), now_utime);
}

DisplayCommand DisplayController::Make(const LimitedOutput& out, int64_t now_utime) {
  DisplayCommand c;
  c.utime = now_utime;
  c.sequence = sequence_++;
  c.source_scan_utime = source_scan_utime_;
  c.source_sed_utime = source_sed_utime_;
  c.display_id = profile_.name;
  c.unit = profile_.unit;
  c.value = out.value;
  c.clamped = out.clamped;
  c.stale = out.stale;
  c.fault = out.fault;
  c.shutdown = out.shutdown;
  ++stats_.commands;
  stats_.commands_clamped += c.clamped;
  stats_.commands_stale += c.stale;
  stats_.commands_fault += c.fault;
  return c;
}

}  // namespace sedbridge::display
