#include "view/view_state.h"

#include "display/command_authenticator.h"
#include "lcm/lcm_safe_decode.h"

namespace sedbridge::view {
namespace {

// A live timeline keeps at most this many points: the oldest half goes when it is full.
constexpr std::size_t kMaxSeriesPoints = 20000;

}  // namespace

void Series::Add(double t, double v) {
  if (t_s.size() >= kMaxSeriesPoints) {
    t_s.erase(t_s.begin(), t_s.begin() + kMaxSeriesPoints / 2);
    value.erase(value.begin(), value.begin() + kMaxSeriesPoints / 2);
  }
  t_s.push_back(t);
  value.push_back(v);
}

void ViewState::Reset() {
  // The messages stay as they are, hidden behind have_*: nothing reads them until replaced.
  have_scan = have_contact = have_sed = have_command = have_sa1 = have_status = false;
  force_N = peak_sed_Pa = latency_ms = Series{};
  events = rejected = first_utime = last_utime = 0;
  ++version;
}

bool ViewState::OnEvent(const std::string& channel, const void* data, std::size_t size, int64_t utime) {
  using lcm_io::SafeDecode;
  bool ok = true;
  if (channel == channels_.tactile_scan) {
    ok = SafeDecode(data, size, &scan);
    if (ok) have_scan = true;
  } else if (channel == channels_.contact) {
    ok = SafeDecode(data, size, &contact);
    if (ok) {
      have_contact = true;
      if (first_utime == 0) first_utime = utime;
      force_N.Add(SinceStart_s(utime), double(contact.normal_force_N) + double(contact.normal_force2_N));
    }
  } else if (channel == channels_.sed) {
    ok = SafeDecode(data, size, &sed);
    if (ok) {
      have_sed = true;
      if (first_utime == 0) first_utime = utime;
      peak_sed_Pa.Add(SinceStart_s(utime), sed.max_sed_Pa);
    }
  } else if (channel == channels_.command) {
    // A signed command is payload || HMAC tag; the view checks nothing, it only shows.
    ok = SafeDecode(data, size, &command) ||
         (size > display::CommandAuthenticator::kTagBytes &&
          SafeDecode(data, size - display::CommandAuthenticator::kTagBytes, &command));
    if (ok) {
      have_command = true;
      if (first_utime == 0) first_utime = utime;
      if (command.source_scan_utime > 0 && !command.shutdown)
        latency_ms.Add(SinceStart_s(utime), (command.utime - command.source_scan_utime) * 1e-3);
    }
  } else if (channel == channels_.sa1_rate) {
    ok = SafeDecode(data, size, &sa1);
    if (ok) have_sa1 = true;
  } else if (channel == channels_.status) {
    ok = SafeDecode(data, size, &status);
    if (ok) have_status = true;
  } else {
    return true;
  }
  if (!ok) {
    ++rejected;
    return false;
  }
  if (first_utime == 0) first_utime = utime;
  last_utime = utime;
  ++events;
  ++version;
  return true;
}

}  // namespace sedbridge::view
