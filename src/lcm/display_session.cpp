#include "lcm/display_session.h"

#include "lcm/display_command_message.h"
#include "lcm/lcm_float.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"

namespace sedbridge::lcm_io {

DisplaySession::DisplaySession(display::DisplayProfile profile, const LcmSettings& settings,
                               DisplaySessionOptions options)
    : controller_(std::move(profile), options.requests),
      publisher_(settings.url, settings.channels),
      options_(options) {
  if (!settings.log_path.empty()) publisher_.OpenLog(settings.log_path);
  if (!settings.auth_key_file.empty())
    publisher_.SetAuthenticator(
        std::make_shared<display::CommandAuthenticator>(display::CommandAuthenticator::FromKeyFile(settings.auth_key_file)));
}

DisplaySession::~DisplaySession() {
  if (shut_down_) return;
  try {
    Shutdown(WallClockUtime());
  } catch (...) {
    // Destructors must not throw; the display's own watchdog takes over from here.
  }
}

const display::DisplayCommand& DisplaySession::OnSedField(const display::SedField& field, int64_t now_utime) {
  stage_ms_ = StageTimes{};
  StageTimer publish_sed_timer(stage_ms_, Stage::kPublish);
  if (options_.publish_sed) {
    const bool due = !sed_published_ || options_.sed_max_rate_Hz <= 0 ||
                     now_utime - last_sed_publish_utime_ >= 1e6 / options_.sed_max_rate_Hz ||
                     now_utime < last_sed_publish_utime_;
    if (due) {
      publisher_.Publish(publisher_.channels().sed, ToLcm(field));
      sed_published_ = true;
      last_sed_publish_utime_ = now_utime;
    }
  }
  publish_sed_timer.Stop();
  StageTimer limiter_timer(stage_ms_, Stage::kLimiter);
  last_ = controller_.OnSedField(field, now_utime);
  limiter_timer.Stop();
  const StageTimer publish_timer(stage_ms_, Stage::kPublish);
  publisher_.Publish(publisher_.channels().command, ToLcm(last_));
  if (options_.publish_sa1_rate) {
    const auto& sed = controller_.last_mapping().sed_at_site_Pa;
    const std::vector<double> rate = display::EstimateSa1Rates(sed, options_.sa1);
    lcmt_sa1_rate_estimate m;
    m.utime = field.utime;
    m.display_id = controller_.profile().name;
    m.num_sites = static_cast<int32_t>(sed.size());
    for (std::size_t i = 0; i < sed.size(); ++i) {
      m.sed_Pa.push_back(ToLcmFloat(sed[i]));
      m.rate_Hz.push_back(ToLcmFloat(rate[i]));
    }
    publisher_.Publish(publisher_.channels().sa1_rate, m);
  }
  return last_;
}

const display::DisplayCommand& DisplaySession::Tick(int64_t now_utime) {
  last_ = controller_.Tick(now_utime);
  publisher_.Publish(publisher_.channels().command, ToLcm(last_));
  return last_;
}

const display::DisplayCommand& DisplaySession::Shutdown(int64_t now_utime) {
  shut_down_ = true;
  // Sent kShutdownRepeats times: UDP multicast may drop one datagram, and this is the one
  // message the display must not miss (its own watchdog is the last line of defence).
  for (int i = 0; i < kShutdownRepeats; ++i) {
    last_ = controller_.Shutdown(now_utime);
    publisher_.Publish(publisher_.channels().command, ToLcm(last_));
  }
  if (publisher_.log()) publisher_.log()->Flush();
  return last_;
}

}  // namespace sedbridge::lcm_io
